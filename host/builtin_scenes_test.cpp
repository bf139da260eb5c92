// Built-in scenes (decision D42): the triangle and object counts of the paper's Table 3
// stand-ins, determinism, animation of the dynamic scene, and glTF export -> re-load.
#include "host/builtin_scenes.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <memory>

#include "host/gltf_export.h"
#include "host/scene.h"

namespace saarcor::host {
namespace {

struct Expected {
  const char* name;
  std::uint64_t unique;
  std::uint64_t instanced;
  std::size_t objects;
  std::size_t instances;
  std::size_t dynamic;
  std::size_t lights;
  std::size_t cameras;
};
const Expected kBuiltins[] = {
    {"triangle", 1, 1, 1, 1, 0, 1, 1},
    {"cube", 12, 12, 1, 1, 0, 1, 1},
    {"room", 806, 806, 1, 1, 0, 2, 1},                                        // Scene6
    {"suncor", 33288, 187145136, 1, 5622, 0, 1, 3},                           // SunCOR
    {"terrain", 1000000 + 36006 + 36008 + 36010, 10469866, 4, 264, 0, 1, 1},  // Terrain
    {"dynamic", 39414 + 832 + 840, 52790, 3, 17, 16, 3, 1},                   // Quake3-p
    {"glass", 32 + 10 + 2 + 40 + 960 + 12, 1056, 2, 2, 0, 1, 1},              // refraction
    {"suncor-wind", 33288, 187145136, 1, 5622, 5622, 1, 3},                   // SunCOR, all moving
};

const Scene& cached(const std::string& name) {
  static std::map<std::string, std::unique_ptr<Scene>> cache;
  auto& slot = cache[name];
  if (!slot) slot = std::make_unique<Scene>(load_scene("builtin:" + name));
  return *slot;
}

std::size_t dynamic_count(const Scene& s) {
  std::size_t n = 0;
  for (const Instance& i : s.instances)
    n += i.dynamic ? 1 : 0;
  return n;
}

TEST(BuiltinScenes, CountsMatchThePapersScenes) {
  for (const Expected& e : kBuiltins) {
    SCOPED_TRACE(e.name);
    const Scene& s = cached(e.name);
    EXPECT_EQ(s.unique_triangles(), e.unique);
    EXPECT_EQ(s.instanced_triangles(), e.instanced);
    EXPECT_EQ(s.objects.size(), e.objects);
    EXPECT_EQ(s.instances.size(), e.instances);
    EXPECT_EQ(dynamic_count(s), e.dynamic);
    EXPECT_EQ(s.lights.size(), e.lights);
    EXPECT_FALSE(s.light_defaulted);
    EXPECT_EQ(s.cameras.size(), e.cameras);
    EXPECT_EQ(s.dropped_triangles(), 0u);
    EXPECT_TRUE(s.warnings.empty());
    for (std::size_t i = 0; i < s.instances.size(); ++i)
      EXPECT_EQ(s.instances[i].id, i);
    for (const Object& o : s.objects) {
      ASSERT_EQ(o.normals.size(), o.positions.size());
      ASSERT_EQ(o.texcoords.size(), o.positions.size());
      for (const glm::uvec3& t : o.triangles)
        for (int k = 0; k < 3; ++k)
          ASSERT_LT(t[k], o.positions.size());
      for (std::uint32_t m : o.material)
        ASSERT_LT(m, s.materials.size());
    }
  }
}

TEST(BuiltinScenes, SameNameSameScene) {
  for (const char* name : {"room", "suncor", "dynamic", "glass"}) {
    SCOPED_TRACE(name);
    const Scene a = make_builtin_scene(name);
    const Scene& b = cached(name);
    ASSERT_EQ(a.objects.size(), b.objects.size());
    for (std::size_t o = 0; o < a.objects.size(); ++o) {
      EXPECT_EQ(a.objects[o].positions, b.objects[o].positions);
      EXPECT_EQ(a.objects[o].triangles, b.objects[o].triangles);
      EXPECT_EQ(a.objects[o].texcoords, b.objects[o].texcoords);
    }
    ASSERT_EQ(a.instances.size(), b.instances.size());
    for (std::size_t i = 0; i < a.instances.size(); ++i)
      EXPECT_EQ(a.instances[i].object_to_world, b.instances[i].object_to_world);
    ASSERT_EQ(a.textures.size(), b.textures.size());
    for (std::size_t t = 0; t < a.textures.size(); ++t)
      EXPECT_EQ(a.textures[t].rgba, b.textures[t].rgba);
  }
}

TEST(BuiltinScenes, DynamicMoversFollowTheirAnimation) {
  Scene s = cached("dynamic");
  EXPECT_DOUBLE_EQ(s.animation_seconds, 10.0);
  const glm::dmat4 level = s.instances[0].object_to_world;
  std::vector<glm::dmat4> at0;
  for (const Instance& i : s.instances)
    at0.push_back(i.object_to_world);
  s.set_time(2.5);
  EXPECT_EQ(s.instances[0].object_to_world, level);
  EXPECT_FALSE(s.instances[0].dynamic);
  for (std::size_t i = 1; i < s.instances.size(); ++i) {
    EXPECT_TRUE(s.instances[i].dynamic);
    const glm::dvec3 moved = glm::dvec3(s.instances[i].object_to_world[3]) - glm::dvec3(at0[i][3]);
    EXPECT_GT(glm::length(moved), 1.0) << "mover " << i;
    EXPECT_DOUBLE_EQ(s.instances[i].object_to_world[3].y, 0.0);  // on the floor
  }
  s.set_time(10.0);  // one lap: back where they started
  for (std::size_t i = 1; i < s.instances.size(); ++i)
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        EXPECT_NEAR(s.instances[i].object_to_world[c][r], at0[i][c][r], 1e-9);
}

// builtin:glass: a glass sphere (ior 1.5) and a crystal block (ior 1.7) whose refraction weights
// come from their transmission as a glTF asset's would (docs/scenes.md "Materials").
TEST(BuiltinScenes, GlassHasTwoRefractiveMaterials) {
  const Scene& s = cached("glass");
  std::map<std::string, const Material*> by_name;
  for (const Material& m : s.materials)
    by_name[m.name] = &m;
  ASSERT_TRUE(by_name.count("glass") && by_name.count("crystal"));
  EXPECT_FLOAT_EQ(by_name["glass"]->refraction, 0.9f);
  EXPECT_FLOAT_EQ(by_name["glass"]->ior, 1.5f);
  EXPECT_FLOAT_EQ(by_name["crystal"]->refraction, 0.85f);
  EXPECT_FLOAT_EQ(by_name["crystal"]->ior, 1.7f);
  int refractive = 0;
  for (const Material& m : s.materials)
    refractive += m.refraction > 0.0f ? 1 : 0;
  EXPECT_EQ(refractive, 2);
  EXPECT_FLOAT_EQ(by_name["mirror"]->reflectivity, 0.95f);
  EXPECT_EQ(s.textures.size(), 2u);
}

// Every sunflower sways about its own base, where SunCOR has it, by at most 0.12 rad.
TEST(BuiltinScenes, SuncorWindMovesEveryInstanceAboutItsBase) {
  const Scene& still = cached("suncor");
  Scene s = cached("suncor-wind");
  EXPECT_DOUBLE_EQ(s.animation_seconds, 4.0);
  const auto up = [](const glm::dmat4& m) { return glm::normalize(glm::dvec3(m[1])); };
  std::vector<glm::dmat4> at0;
  for (const Instance& i : s.instances)
    at0.push_back(i.object_to_world);
  s.set_time(1.0);
  double largest = 0.0;
  for (std::size_t i = 0; i < s.instances.size(); ++i) {
    const glm::dmat4& m = s.instances[i].object_to_world;
    EXPECT_NE(m, at0[i]) << "sunflower " << i;
    for (int r = 0; r < 3; ++r)
      EXPECT_NEAR(m[3][r], still.instances[i].object_to_world[3][r], 1e-12);
    const double tilt = std::acos(std::clamp(glm::dot(up(m), glm::dvec3(0, 1, 0)), -1.0, 1.0));
    EXPECT_LE(tilt, 0.12 + 1e-6);
    largest = std::max(largest, tilt);
    EXPECT_NEAR(glm::length(glm::dvec3(m[1])),
                glm::length(glm::dvec3(still.instances[i].object_to_world[1])), 1e-6);
  }
  EXPECT_GT(largest, 0.11);
}

class BuiltinExport : public ::testing::TestWithParam<const char*> {};

TEST_P(BuiltinExport, ExportThenReloadGivesTheSameScene) {
  const Scene& a = cached(GetParam());
  const auto path = std::filesystem::temp_directory_path() /
                    (std::string("saarcor_builtin_") + GetParam() + "_" +
                     std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + ".glb");
  export_gltf(a, path.string());
  const Scene b = load_scene(path.string());
  std::filesystem::remove(path);
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".partial"));
  EXPECT_EQ(b.unique_triangles(), a.unique_triangles());
  EXPECT_EQ(b.instanced_triangles(), a.instanced_triangles());
  ASSERT_EQ(b.objects.size(), a.objects.size());
  ASSERT_EQ(b.instances.size(), a.instances.size());
  EXPECT_EQ(b.lights.size(), a.lights.size());
  EXPECT_FALSE(b.light_defaulted);
  ASSERT_EQ(b.cameras.size(), a.cameras.size());
  EXPECT_EQ(b.textures.size(), a.textures.size());
  EXPECT_DOUBLE_EQ(b.animation_seconds, a.animation_seconds);
  EXPECT_TRUE(b.warnings.empty());
  // Materials, glass included (KHR_materials_transmission, KHR_materials_ior).
  ASSERT_EQ(b.materials.size(), a.materials.size());
  for (std::size_t m = 0; m < a.materials.size(); ++m) {
    EXPECT_EQ(b.materials[m].transmission, a.materials[m].transmission) << a.materials[m].name;
    EXPECT_EQ(b.materials[m].ior, a.materials[m].ior) << a.materials[m].name;
    EXPECT_EQ(b.materials[m].refraction, a.materials[m].refraction) << a.materials[m].name;
    EXPECT_EQ(b.materials[m].reflectivity, a.materials[m].reflectivity) << a.materials[m].name;
  }
  for (std::size_t o = 0; o < a.objects.size(); ++o) {
    EXPECT_EQ(b.objects[o].positions, a.objects[o].positions);
    EXPECT_EQ(b.objects[o].triangles, a.objects[o].triangles);
    EXPECT_EQ(b.objects[o].texcoords, a.objects[o].texcoords);
  }
  for (std::size_t i = 0; i < a.instances.size(); ++i) {
    EXPECT_EQ(b.instances[i].id, a.instances[i].id);
    EXPECT_EQ(b.instances[i].object, a.instances[i].object);
    EXPECT_EQ(b.instances[i].dynamic, a.instances[i].dynamic);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        ASSERT_NEAR(b.instances[i].object_to_world[c][r], a.instances[i].object_to_world[c][r],
                    1e-12);
  }
  for (std::size_t c = 0; c < a.cameras.size(); ++c) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(b.cameras[c].position[k], a.cameras[c].position[k], 1e-5f);
      EXPECT_NEAR(b.cameras[c].forward[k], a.cameras[c].forward[k], 1e-6f);
      EXPECT_NEAR(b.cameras[c].up[k], a.cameras[c].up[k], 1e-6f);
    }
  }
  for (std::size_t t = 0; t < a.textures.size(); ++t)
    EXPECT_EQ(b.textures[t].rgba, a.textures[t].rgba);
  if (a.animation_seconds > 0.0) {  // the animation survives: same transforms at another time
    Scene a2 = a;
    Scene b2 = b;
    a2.set_time(3.3);
    b2.set_time(3.3);
    for (std::size_t i = 0; i < a2.instances.size(); ++i)
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
          ASSERT_NEAR(b2.instances[i].object_to_world[c][r], a2.instances[i].object_to_world[c][r],
                      1e-6);
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, BuiltinExport,
                         ::testing::Values("triangle", "cube", "room", "suncor", "dynamic",
                                           "glass"));

TEST(BuiltinScenes, SuncorExportStaysSmall) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("saarcor_suncor_size_" +
                     std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + ".glb");
  export_gltf(cached("suncor"), path.string());
  const auto bytes = std::filesystem::file_size(path);
  std::filesystem::remove(path);
  // One mesh of 33,288 triangles plus 5,622 nodes, not 187M triangles.
  EXPECT_LT(bytes, 8u << 20);
}

}  // namespace
}  // namespace saarcor::host
