// glTF import (docs/scenes.md): every glTF model of the shared MANIFEST.md loads with the
// triangle counts the manifest lists, instancing, cameras, textures, node animations sampled at
// chosen times, and one test per class of bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/gltf_export.h"
#include "host/gltf_loader.h"
#include "host/scene.h"

namespace saarcor::host {
namespace {

const std::string kScenes = SAARCOR_SHARED_SCENES;

// The glTF table of $SAARCOR_SHARED_SCENES/MANIFEST.md: triangles unique / instanced, meshes,
// mesh nodes (instances).
struct ManifestRow {
  const char* file;
  std::uint64_t unique;
  std::uint64_t instanced;
  std::size_t meshes;
  std::size_t mesh_nodes;
};
const ManifestRow kManifest[] = {
    {"Triangle/Triangle.gltf", 1, 1, 1, 1},
    {"TriangleWithoutIndices/TriangleWithoutIndices.gltf", 1, 1, 1, 1},
    {"Box/Box.gltf", 12, 12, 1, 1},
    {"Box/Box.glb", 12, 12, 1, 1},
    {"SimpleMeshes/SimpleMeshes.gltf", 1, 2, 1, 2},
    {"Cameras/Cameras.gltf", 2, 2, 1, 1},
    {"BoxTextured/BoxTextured.gltf", 12, 12, 1, 1},
    {"Duck/Duck.gltf", 4212, 4212, 1, 1},
    {"AnimatedTriangle/AnimatedTriangle.gltf", 1, 1, 1, 1},
    {"BoxAnimated/BoxAnimated.gltf", 254, 254, 2, 2},
    {"BoxAnimated/BoxAnimated.glb", 254, 254, 2, 2},
    {"AnimatedCube/AnimatedCube.gltf", 12, 12, 1, 1},
    {"InterpolationTest/InterpolationTest.gltf", 110, 110, 10, 10},
    {"CesiumMilkTruck/CesiumMilkTruck.gltf", 2856, 3624, 2, 3},
    {"SpheresScaledInstances/spheres_scaled_instances.gltf", 224, 672, 1, 3},
    {"RiggedSimple/RiggedSimple.gltf", 188, 188, 1, 1},
    {"CesiumMan/CesiumMan.gltf", 4672, 4672, 1, 1},
    {"AnimatedMorphCube/AnimatedMorphCube.gltf", 12, 12, 1, 1},
    {"DamagedHelmet/DamagedHelmet.gltf", 15452, 15452, 1, 1},
    {"VC/VC.gltf", 8383, 8383, 135, 135},
    {"2CylinderEngine/2CylinderEngine.gltf", 75730, 121496, 29, 67},
    {"ReciprocatingSaw/ReciprocatingSaw.gltf", 139594, 198470, 65, 113},
};

// The two big models are loaded once per test program.
const Scene& cached(const std::string& file) {
  static std::map<std::string, std::unique_ptr<Scene>> cache;
  auto& slot = cache[file];
  if (!slot) slot = std::make_unique<Scene>(load_scene(kScenes + "/" + file));
  return *slot;
}

bool has_warning(const Scene& s, const std::string& part) {
  for (const std::string& w : s.warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

std::string error_of(const std::string& spec) {
  try {
    (void)load_scene(spec);
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    return msg;
  }
  ADD_FAILURE() << spec << " loaded without error";
  return {};
}

void expect_mat_near(const glm::dmat4& a, const glm::dmat4& b, double tol = 1e-5) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      EXPECT_NEAR(a[c][r], b[c][r], tol) << "column " << c << " row " << r;
}

const Instance& instance_of_node(const Scene& s, std::uint32_t node) {
  for (const Instance& i : s.instances)
    if (i.id == node) return i;
  throw std::runtime_error("no instance for node " + std::to_string(node));
}

TEST(GltfManifest, EveryModelHasTheListedTriangleCounts) {
  for (const ManifestRow& row : kManifest) {
    SCOPED_TRACE(row.file);
    const Scene& s = cached(row.file);
    EXPECT_EQ(s.unique_triangles(), row.unique);
    EXPECT_EQ(s.instanced_triangles(), row.instanced);
    EXPECT_EQ(s.objects.size(), row.meshes);
    EXPECT_EQ(s.instances.size(), row.mesh_nodes);
    EXPECT_EQ(s.skipped_primitives, 0u);
    for (const Object& o : s.objects) {
      EXPECT_EQ(o.material.size(), o.triangles.size());
      EXPECT_EQ(o.degenerate.size(), o.triangles.size());
      for (const glm::uvec3& t : o.triangles)
        for (int k = 0; k < 3; ++k)
          ASSERT_LT(t[k], o.positions.size());
      for (std::uint32_t m : o.material)
        ASSERT_LT(m, s.materials.size());
    }
    // Only 2CylinderEngine holds degenerate triangles: 10,419 of exactly zero area.
    EXPECT_EQ(s.dropped_triangles(),
              std::string(row.file).find("2CylinderEngine") == 0 ? 10419u : 0u);
    // No file has lights (MANIFEST.md), so each gets the default one.
    EXPECT_TRUE(s.light_defaulted);
    EXPECT_EQ(s.lights.size(), 1u);
  }
}

TEST(GltfManifest, SkinnedAndMorphModelsLoadInBindPoseWithAWarning) {
  EXPECT_TRUE(has_warning(cached("RiggedSimple/RiggedSimple.gltf"),
                          "is skinned: rendered in its bind pose"));
  EXPECT_TRUE(
      has_warning(cached("CesiumMan/CesiumMan.gltf"), "is skinned: rendered in its bind pose"));
  const Scene& morph = cached("AnimatedMorphCube/AnimatedMorphCube.gltf");
  EXPECT_TRUE(has_warning(morph, "has morph targets: rendered with its base shape"));
  EXPECT_TRUE(has_warning(morph, "morph weights"));
  // Models without such features warn about nothing.
  EXPECT_TRUE(cached("Duck/Duck.gltf").warnings.empty());
  EXPECT_TRUE(cached("2CylinderEngine/2CylinderEngine.gltf").warnings.empty());
}

TEST(GltfInstancing, MeshesUsedByManyNodesAreStoredOnce) {
  const Scene& simple = cached("SimpleMeshes/SimpleMeshes.gltf");
  ASSERT_EQ(simple.instances.size(), 2u);
  EXPECT_EQ(simple.instances[0].object, simple.instances[1].object);
  EXPECT_NE(simple.instances[0].object_to_world, simple.instances[1].object_to_world);

  const Scene& spheres = cached("SpheresScaledInstances/spheres_scaled_instances.gltf");
  ASSERT_EQ(spheres.instances.size(), 3u);
  std::vector<double> scales;
  for (const Instance& i : spheres.instances) {
    EXPECT_EQ(i.object, 0u);
    scales.push_back(glm::length(glm::dvec3(i.object_to_world[0])));
  }
  std::sort(scales.begin(), scales.end());
  EXPECT_NEAR(scales[0], 0.1, 1e-6);
  EXPECT_NEAR(scales[1], 1.0, 1e-6);
  EXPECT_NEAR(scales[2], 3.0, 1e-6);

  const Scene& truck = cached("CesiumMilkTruck/CesiumMilkTruck.gltf");
  std::map<std::uint32_t, int> uses;
  for (const Instance& i : truck.instances)
    ++uses[i.object];
  int shared = 0;
  for (const auto& [o, n] : uses)
    shared += n > 1 ? 1 : 0;
  EXPECT_EQ(shared, 1);  // the wheels

  const Scene& engine = cached("2CylinderEngine/2CylinderEngine.gltf");
  std::vector<int> engine_uses(engine.objects.size(), 0);
  for (const Instance& i : engine.instances)
    ++engine_uses[i.object];
  EXPECT_EQ(std::count_if(engine_uses.begin(), engine_uses.end(), [](int n) { return n > 1; }), 14);
}

TEST(GltfHierarchy, MatrixNodesComposeWithTheirParents) {
  // Box: the root node's matrix turns Y-up into Z-up (a rotation of -90 degrees about X).
  const Scene& box = cached("Box/Box.gltf");
  ASSERT_EQ(box.instances.size(), 1u);
  const glm::dmat4& m = box.instances[0].object_to_world;
  const glm::dvec4 y = m * glm::dvec4(0, 1, 0, 0);
  EXPECT_NEAR(std::abs(y.z), 1.0, 1e-9);
  EXPECT_EQ(box.instances[0].id, 1u);  // the mesh sits on node 1
  EXPECT_FALSE(box.instances[0].dynamic);
  // The .glb holds the same model.
  const Scene& glb = cached("Box/Box.glb");
  expect_mat_near(glb.instances[0].object_to_world, m, 0.0);
  EXPECT_EQ(glb.objects[0].positions, box.objects[0].positions);
}

TEST(GltfCameras, ThePerspectiveCameraWithItsNodeTransform) {
  const Scene& s = cached("Cameras/Cameras.gltf");
  ASSERT_EQ(s.cameras.size(), 1u);  // the orthographic one is skipped with a warning
  EXPECT_TRUE(has_warning(s, "orthographic"));
  const Camera& c = s.cameras[0];
  EXPECT_FLOAT_EQ(c.yfov, 0.7f);
  EXPECT_EQ(c.node, 1);
  EXPECT_NEAR(c.position.x, 0.5f, 1e-6f);
  EXPECT_NEAR(c.position.y, 0.5f, 1e-6f);
  EXPECT_NEAR(c.position.z, 3.0f, 1e-6f);
  EXPECT_NEAR(c.forward.z, -1.0f, 1e-6f);
  EXPECT_NEAR(c.up.y, 1.0f, 1e-6f);
  EXPECT_EQ(scene_camera(s).position, c.position);
  // Duck: its camera sits under a matrix node; forward and up stay unit and orthogonal.
  const Scene& duck = cached("Duck/Duck.gltf");
  ASSERT_EQ(duck.cameras.size(), 1u);
  EXPECT_NEAR(glm::length(duck.cameras[0].forward), 1.0f, 1e-5f);
  EXPECT_NEAR(glm::dot(duck.cameras[0].forward, duck.cameras[0].up), 0.0f, 1e-5f);
}

TEST(GltfTextures, BaseColourImagesAreDecoded) {
  const Scene& box = cached("BoxTextured/BoxTextured.gltf");
  ASSERT_EQ(box.textures.size(), 1u);
  EXPECT_EQ(box.textures[0].name, "CesiumLogoFlat.png");
  EXPECT_EQ(box.textures[0].width, 256);
  EXPECT_EQ(box.textures[0].height, 256);
  ASSERT_EQ(box.materials[0].texture, 0);
  ASSERT_FALSE(box.objects[0].texcoords.empty());
  // Not a constant image, fully opaque.
  std::uint32_t first = box.textures[0].rgba[0];
  bool varies = false;
  for (std::uint32_t px : box.textures[0].rgba) {
    varies = varies || px != first;
    ASSERT_EQ(px >> 24, 255u);
  }
  EXPECT_TRUE(varies);

  const Scene& duck = cached("Duck/Duck.gltf");
  ASSERT_EQ(duck.textures.size(), 1u);
  EXPECT_EQ(duck.textures[0].width, 512);
  EXPECT_EQ(duck.textures[0].height, 512);
  // DuckCM.png is mostly yellow: red and green well above blue on average.
  double r = 0, g = 0, b = 0;
  for (std::uint32_t px : duck.textures[0].rgba) {
    r += px & 0xFF;
    g += (px >> 8) & 0xFF;
    b += (px >> 16) & 0xFF;
  }
  EXPECT_GT(r, 1.5 * b);
  EXPECT_GT(g, 1.2 * b);
  // DamagedHelmet: five images, only the base colour is decoded.
  EXPECT_EQ(cached("DamagedHelmet/DamagedHelmet.gltf").textures.size(), 1u);
}

TEST(GltfMaterials, MetallicRoughnessMapsToTheFixedFunctionTerms) {
  Material m;
  m.base_color = {0.8f, 0.2f, 0.1f, 1.0f};
  m.metallic = 1.0f;
  m.roughness = 0.0f;
  derive_fixed_function_terms(m, false);
  EXPECT_FLOAT_EQ(m.specular.r, 0.8f);
  EXPECT_FLOAT_EQ(m.reflectivity, 1.0f);
  EXPECT_FLOAT_EQ(m.shininess, 256.0f);
  m.metallic = 0.0f;
  m.roughness = 1.0f;
  derive_fixed_function_terms(m, false);
  EXPECT_FLOAT_EQ(m.specular.r, 0.0f);
  EXPECT_FLOAT_EQ(m.reflectivity, 0.0f);
  EXPECT_FLOAT_EQ(m.shininess, 1.0f);
  m.roughness = 0.5f;  // alpha = 0.25: n = 2 / 0.0625 - 2 = 30
  derive_fixed_function_terms(m, false);
  EXPECT_FLOAT_EQ(m.shininess, 30.0f);
  EXPECT_NEAR(m.specular.g, 0.02f, 1e-7f);
  m.base_color.a = 0.25f;
  derive_fixed_function_terms(m, true);
  EXPECT_FLOAT_EQ(m.transparency, 0.75f);
  EXPECT_FLOAT_EQ(m.refraction, 0.0f);
  m.transmission = 0.9f;  // glass: the dielectric share transmits
  m.metallic = 0.5f;
  derive_fixed_function_terms(m, false);
  EXPECT_FLOAT_EQ(m.refraction, 0.45f);
}

TEST(GltfAnimation, AnimatedTriangleRotatesAboutZ) {
  Scene s = cached("AnimatedTriangle/AnimatedTriangle.gltf");
  EXPECT_DOUBLE_EQ(s.animation_seconds, 1.0);
  ASSERT_EQ(s.instances.size(), 1u);
  EXPECT_TRUE(s.instances[0].dynamic);
  const std::pair<double, double> cases[] = {
      {0.0, 0.0}, {0.125, 45.0}, {0.25, 90.0}, {0.375, 135.0}, {0.5, 180.0}};
  for (const auto& [t, degrees] : cases) {
    SCOPED_TRACE(t);
    s.set_time(t);
    expect_mat_near(s.instances[0].object_to_world,
                    glm::rotate(glm::dmat4(1.0), glm::radians(degrees), glm::dvec3(0, 0, 1)));
  }
  s.set_time(7.0);  // clamped to the end: back to the start pose
  EXPECT_DOUBLE_EQ(s.time, 1.0);
  expect_mat_near(s.instances[0].object_to_world, glm::dmat4(1.0));
}

TEST(GltfAnimation, BoxAnimatedMovesInItsHierarchy) {
  Scene s = cached("BoxAnimated/BoxAnimated.gltf");
  EXPECT_NEAR(s.animation_seconds, 3.70833, 1e-5);
  const Instance& still = instance_of_node(s, 3);
  EXPECT_FALSE(still.dynamic);
  EXPECT_TRUE(instance_of_node(s, 2).dynamic);  // under the translated node 0
  // Node 0 translates (0, 2.52, 0) at 1.25 s .. 2.5 s; node 2 turns about X from 1.25 s to 2.5 s.
  s.set_time(0.625);
  expect_mat_near(instance_of_node(s, 2).object_to_world,
                  glm::translate(glm::dmat4(1.0), {0, 1.26, 0}));
  s.set_time(1.875);
  expect_mat_near(instance_of_node(s, 2).object_to_world,
                  glm::translate(glm::dmat4(1.0), {0, 2.52, 0}) *
                      glm::rotate(glm::dmat4(1.0), glm::radians(90.0), glm::dvec3(1, 0, 0)),
                  1e-4);
  s.set_time(3.0);
  const double y = 2.52 * (1.0 - 0.5 / (3.708329916000366 - 2.5));
  EXPECT_NEAR(instance_of_node(s, 2).object_to_world[3].y, y, 1e-6);
  const glm::dmat4 before = still.object_to_world;
  s.set_time(1.0);
  EXPECT_EQ(instance_of_node(s, 3).object_to_world, before);
}

TEST(GltfAnimation, InterpolationTestStepLinearAndCubicSpline) {
  Scene s = cached("InterpolationTest/InterpolationTest.gltf");
  EXPECT_NEAR(s.animation_seconds, 1.7083333730697632, 1e-9);
  EXPECT_TRUE(has_warning(s, "CUBICSPLINE"));
  const double k0 = 0.0416666679084301, k1 = 0.4166666567325592;
  const auto scale_of = [&](std::uint32_t node) {
    return glm::length(glm::dvec3(instance_of_node(s, node).object_to_world[0]));
  };
  // Scale: STEP (node 0), LINEAR (node 3), CUBICSPLINE read as linear (node 4), 1 -> 0.5.
  s.set_time(0.5 * (k0 + k1));
  EXPECT_NEAR(scale_of(0), 1.0, 1e-6);
  EXPECT_NEAR(scale_of(3), 0.75, 1e-6);
  EXPECT_NEAR(scale_of(4), 0.75, 1e-6);
  s.set_time(0.5);
  EXPECT_NEAR(scale_of(0), 0.5, 1e-6);
  // Translation: STEP (node 8) 6.665 -> 10 at 0.458 s; LINEAR (node 10) 10 -> 6 over 0.417..0.833
  // s.
  s.set_time(0.5);
  EXPECT_NEAR(instance_of_node(s, 8).object_to_world[3].y, 10.0, 1e-6);
  s.set_time(0.625);
  EXPECT_NEAR(instance_of_node(s, 10).object_to_world[3].y, 8.0, 1e-5);
  EXPECT_NEAR(instance_of_node(s, 10).object_to_world[3].x, -3.2975807189941406, 1e-6);
  // Rotation: LINEAR (node 7) halfway to -45 degrees about Z; STEP (node 5) holds -90 degrees.
  s.set_time(0.5 * k1);
  const glm::dmat4 r7 = instance_of_node(s, 7).object_to_world;
  EXPECT_NEAR(std::atan2(r7[0].y, r7[0].x), glm::radians(-22.5), 1e-5);
  s.set_time(1.0);
  const glm::dmat4 r5 = instance_of_node(s, 5).object_to_world;
  EXPECT_NEAR(std::atan2(r5[0].y, r5[0].x), glm::radians(-90.0), 1e-5);
  // Static nodes are not dynamic.
  EXPECT_FALSE(instance_of_node(s, 11).dynamic);
  EXPECT_TRUE(instance_of_node(s, 7).dynamic);
}

TEST(SceneDefaults, CameraFramesTheBoundsAndTheLightSitsAboveIt) {
  const Scene& s = cached("Box/Box.gltf");  // a unit cube: bounds [-0.5, 0.5]^3
  EXPECT_TRUE(s.cameras.empty());
  const Aabb b = world_bounds(s);
  EXPECT_NEAR(b.lo.x, -0.5f, 1e-6f);
  EXPECT_NEAR(b.hi.z, 0.5f, 1e-6f);
  const Camera c = default_camera(s);
  const double radius = std::sqrt(3.0) * 0.5;
  EXPECT_NEAR(c.position.z, radius / std::sin(glm::radians(22.5)), 1e-5);
  EXPECT_NEAR(c.position.x, 0.0f, 1e-6f);
  EXPECT_EQ(c.forward, glm::vec3(0, 0, -1));
  EXPECT_NEAR(c.yfov, glm::radians(45.0f), 1e-6f);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_NEAR(s.lights[0].position.y, radius * 0.5, 1e-5);
  EXPECT_NEAR(s.lights[0].position.z, c.position.z, 1e-5);
}

TEST(SceneDegenerate, ZeroAreaAndRelativelyTinyTrianglesAreMarked) {
  Object o;
  o.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {1e6f, 0, 0}, {0, 1e-4f, 0}};
  o.triangles = {{0, 1, 2}, {0, 1, 3}, {0, 0, 2}, {0, 4, 5}};
  o.material.assign(4, 0);
  mark_degenerate_triangles(o);
  // Kept, collinear, repeated vertex, and a sliver with |cross| / longest^2 = 1e2 / 1e12 (kept).
  EXPECT_EQ(o.degenerate, (std::vector<std::uint8_t>{0, 1, 1, 0}));
  o.positions[5] = {0, 1e-7f, 0};  // 1e-1 / 1e12 = 1e-13: below the threshold
  mark_degenerate_triangles(o);
  EXPECT_EQ(o.degenerate[3], 1);
  EXPECT_EQ(o.dropped_triangles(), 3u);
}

// ---- bad input: small glTF files written into a temporary directory ---------------------------

std::string base64_encode(const std::vector<unsigned char>& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (in[i] << 16) | (in[i + 1] << 8) | in[i + 2];
    out += {t[(v >> 18) & 63], t[(v >> 12) & 63], t[(v >> 6) & 63], t[v & 63]};
  }
  if (i + 1 == in.size()) {
    const unsigned v = in[i] << 16;
    out += {t[(v >> 18) & 63], t[(v >> 12) & 63], '=', '='};
  } else if (i + 2 == in.size()) {
    const unsigned v = (in[i] << 16) | (in[i + 1] << 8);
    out += {t[(v >> 18) & 63], t[(v >> 12) & 63], t[(v >> 6) & 63], '='};
  }
  return out;
}

class BadGltf : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        std::filesystem::temp_directory_path() /
        ("saarcor_scene_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) {
    const std::string p = (dir_ / name).string();
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }

  static std::string base64(const std::vector<unsigned char>& in) { return base64_encode(in); }

  // A one-mesh glTF whose buffer holds `positions` (float xyz), drawn non-indexed with `mode`;
  // `extra` is spliced into the top-level object.
  static std::string gltf(const std::vector<float>& positions, int mode = 4,
                          const std::string& buffer_uri = "", const std::string& extra = "") {
    std::vector<unsigned char> bytes(positions.size() * 4);
    std::memcpy(bytes.data(), positions.data(), bytes.size());
    const std::string uri =
        buffer_uri.empty() ? "data:application/octet-stream;base64," + base64(bytes) : buffer_uri;
    const std::string n = std::to_string(positions.size() / 3);
    return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
           R"("meshes":[{"name":"probe","primitives":[{"attributes":{"POSITION":0},"mode":)" +
           std::to_string(mode) +
           R"(}]}],"accessors":[{"bufferView":0,"componentType":5126,"count":)" + n +
           R"(,"type":"VEC3"}],"bufferViews":[{"buffer":0,"byteLength":)" +
           std::to_string(bytes.size()) + R"(}],"buffers":[{"byteLength":)" +
           std::to_string(bytes.size()) + R"(,"uri":")" + uri + "\"}]" + extra + "}";
  }

  std::filesystem::path dir_;
};

const std::vector<float> kTri = {0, 0, 0, 1, 0, 0, 0, 1, 0};

TEST_F(BadGltf, GoodProbeLoads) {
  const Scene s = load_scene(write("ok.gltf", gltf(kTri)));
  EXPECT_EQ(s.unique_triangles(), 1u);
  EXPECT_EQ(s.dropped_triangles(), 0u);
}

TEST_F(BadGltf, MalformedJsonGivesTinygltfsErrorInOneLine) {
  const std::string p = write("bad.gltf", "{ \"asset\": {\"version\": \"2.0\" ");
  const std::string e = error_of(p);
  EXPECT_NE(e.find(p + ": cannot load glTF: "), std::string::npos) << e;
  EXPECT_NE(e.find("parse error"), std::string::npos) << e;
}

TEST_F(BadGltf, MissingFile) {
  const std::string p = (dir_ / "nothing.gltf").string();
  EXPECT_EQ(error_of(p), p + ": no such file");
}

TEST_F(BadGltf, MissingBufferNamesTheFile) {
  const std::string e = error_of(write("nobuf.gltf", gltf(kTri, 4, "missing_buffer.bin")));
  EXPECT_NE(e.find("missing_buffer.bin"), std::string::npos) << e;
  EXPECT_NE(e.find("cannot load glTF"), std::string::npos) << e;
}

TEST_F(BadGltf, MissingImageNamesTheFile) {
  const std::string extra = R"(,"images":[{"uri":"missing_image.png"}])";
  const std::string e = error_of(write("noimg.gltf", gltf(kTri, 4, "", extra)));
  EXPECT_NE(e.find("image file missing or unreadable"), std::string::npos) << e;
  EXPECT_NE(e.find("missing_image.png"), std::string::npos) << e;
}

TEST_F(BadGltf, UndecodableImageNamesTheFile) {
  write("garbage.png", "this is not a PNG file at all");
  const std::string extra =
      R"(,"images":[{"uri":"garbage.png"}],"textures":[{"source":0}],)"
      R"("materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}])";
  const std::string e = error_of(write("badimg.gltf", gltf(kTri, 4, "", extra)));
  EXPECT_NE(e.find("garbage.png: cannot decode image"), std::string::npos) << e;
}

TEST_F(BadGltf, NanVertexNamesMeshAndAccessor) {
  std::vector<float> p = kTri;
  p[4] = std::nanf("");
  const std::string e = error_of(write("nan.gltf", gltf(p)));
  EXPECT_NE(e.find("mesh 0 'probe': accessor 0 (POSITION) has a non-finite value at vertex 1"),
            std::string::npos)
      << e;
  p[4] = INFINITY;
  EXPECT_NE(error_of(write("inf.gltf", gltf(p))).find("non-finite"), std::string::npos);
}

TEST_F(BadGltf, PointsPrimitiveIsSkippedAndCounted) {
  const Scene s = load_scene(write("points.gltf", gltf(kTri, 0)));
  EXPECT_EQ(s.skipped_primitives, 1u);
  EXPECT_EQ(s.unique_triangles(), 0u);
  EXPECT_TRUE(has_warning(s, "primitive 0 has mode 0 (points or lines): skipped"));
}

TEST_F(BadGltf, DegenerateTriangleKeepsItsSlotAndIsCounted) {
  std::vector<float> p = kTri;
  const std::vector<float> line = {0, 0, 0, 1, 1, 1, 2, 2, 2};
  p.insert(p.end(), line.begin(), line.end());
  const Scene s = load_scene(write("degenerate.gltf", gltf(p)));
  EXPECT_EQ(s.unique_triangles(), 2u);
  EXPECT_EQ(s.dropped_triangles(), 1u);
  EXPECT_EQ(s.objects[0].degenerate, (std::vector<std::uint8_t>{0, 1}));
}

TEST_F(BadGltf, AccessorPastTheBufferIsRefused) {
  std::string text = gltf(kTri);
  const std::string from = "\"count\":3,";
  text.replace(text.find(from), from.size(), "\"count\":4,");
  const std::string e = error_of(write("short.gltf", text));
  EXPECT_NE(e.find("reads past the end of its buffer view"), std::string::npos) << e;
}

// Found by fuzzing (docs/fuzzing.md): counts are only numbers in the JSON. An accessor without a
// buffer view (zeros) of a billion VEC3s, and one of two billion MAT4s over a 36-byte view, were
// allocated (24 GB, 256 GB) before any check; they are refused in one line first.
TEST_F(BadGltf, HugeAccessorCountsAreRefusedBeforeAllocating) {
  const std::string zeros =
      write("zeros.gltf",
            R"({"asset":{"version":"2.0"},"accessors":[{"componentType":5126,"count":1000000000,)"
            R"("type":"VEC3"}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
            R"("nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]})");
  std::string e = error_of(zeros);
  EXPECT_NE(e.find("accessor 0): the scene is too large: its accessors hold more than 33554432 "
                   "values in all"),
            std::string::npos)
      << e;
  std::string text = gltf(kTri);
  const std::string from = R"("count":3,"type":"VEC3")";
  text.replace(text.find(from), from.size(), R"("count":2000000000,"type":"MAT4")");
  e = error_of(write("mat4.gltf", text));
  EXPECT_NE(e.find("the scene is too large"), std::string::npos) << e;
}

// The limit counts every read: meshes that share one accessor read it again each.
TEST_F(BadGltf, MeshesSharingAnAccessorCountAgainstTheLimitEachTime) {
  const std::string mesh = R"({"primitives":[{"attributes":{"POSITION":0}}]})";
  const std::string e = error_of(write(
      "shared.gltf",
      R"({"asset":{"version":"2.0"},"accessors":[{"componentType":5126,"count":5600000,)"
      R"("type":"VEC3"}],"meshes":[)" +
          mesh + "," + mesh + R"(],"nodes":[{"mesh":0},{"mesh":1}],"scenes":[{"nodes":[0,1]}]})"));
  EXPECT_NE(e.find("mesh 1 primitive 0 POSITION (accessor 0): the scene is too large"),
            std::string::npos)
      << e;
}

// Found by fuzzing: a buffer view offset near 2^64 wrapped the end check (offset + length) and
// the accessor read before the buffer (UBSan: pointer overflow).
TEST_F(BadGltf, BufferViewOffsetThatWrapsIsRefused) {
  std::string text = gltf(kTri);
  const std::string from = R"("bufferViews":[{"buffer":0,)";
  text.replace(text.find(from), from.size(),
               R"("bufferViews":[{"buffer":0,"byteOffset":18446744073709551600,)");
  const std::string e = error_of(write("wrap.gltf", text));
  EXPECT_NE(e.find("buffer view 0 reaches past the end of buffer 0"), std::string::npos) << e;
}

// ---- features the manifest models do not exercise ---------------------------------------------

// Positions (float xyz) followed by an index block of the given component type, all in one
// embedded buffer; one primitive with `mode`.
std::string indexed_gltf(const std::vector<float>& positions,
                         const std::vector<std::uint32_t>& indices, int component_type, int mode,
                         const std::string& accessor_extra = "") {
  std::vector<unsigned char> bytes(positions.size() * 4);
  std::memcpy(bytes.data(), positions.data(), bytes.size());
  const std::size_t index_offset = bytes.size();
  for (std::uint32_t i : indices) {
    const int size = component_type == 5121 ? 1 : component_type == 5123 ? 2 : 4;
    for (int b = 0; b < size; ++b)
      bytes.push_back(static_cast<unsigned char>(i >> (8 * b)));
  }
  while (bytes.size() % 4 != 0)
    bytes.push_back(0);
  const std::string n = std::to_string(positions.size() / 3);
  return R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
         R"("meshes":[{"name":"probe","primitives":[{"attributes":{"POSITION":0},"indices":1,"mode":)" +
         std::to_string(mode) +
         R"(}]}],"accessors":[{"bufferView":0,"componentType":5126,"count":)" + n +
         R"(,"type":"VEC3")" + accessor_extra + R"(},{"bufferView":1,"componentType":)" +
         std::to_string(component_type) + R"(,"count":)" + std::to_string(indices.size()) +
         R"(,"type":"SCALAR"}],"bufferViews":[{"buffer":0,"byteLength":)" +
         std::to_string(index_offset) + R"(},{"buffer":0,"byteOffset":)" +
         std::to_string(index_offset) + R"(,"byteLength":)" +
         std::to_string(bytes.size() - index_offset) + R"(}],"buffers":[{"byteLength":)" +
         std::to_string(bytes.size()) + R"(,"uri":"data:application/octet-stream;base64,)" +
         base64_encode(bytes) + "\"}]}";
}

const std::vector<float> kQuad = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};

TEST_F(BadGltf, IndicesOfEightSixteenAndThirtyTwoBits) {
  const std::vector<std::uint32_t> idx = {0, 1, 2, 0, 2, 3};
  for (int type : {5121, 5123, 5125}) {
    SCOPED_TRACE(type);
    const Scene s = load_scene(
        write("idx" + std::to_string(type) + ".gltf", indexed_gltf(kQuad, idx, type, 4)));
    ASSERT_EQ(s.objects[0].triangles.size(), 2u);
    EXPECT_EQ(s.objects[0].triangles[1], glm::uvec3(0, 2, 3));
  }
  const std::string e = error_of(write("oob.gltf", indexed_gltf(kQuad, {0, 1, 4}, 5123, 4)));
  EXPECT_NE(e.find("accessor 1 (indices) entry 2 = 4 is not below the 4 vertices"),
            std::string::npos)
      << e;
}

TEST_F(BadGltf, StripsAndFansBecomeTriangles) {
  const Scene strip = load_scene(write("strip.gltf", indexed_gltf(kQuad, {0, 1, 3, 2}, 5123, 5)));
  EXPECT_EQ(strip.objects[0].triangles,
            (std::vector<glm::uvec3>{{0, 1, 3}, {1, 2, 3}}));  // glTF's order
  const Scene fan = load_scene(write("fan.gltf", indexed_gltf(kQuad, {0, 1, 2, 3}, 5123, 6)));
  EXPECT_EQ(fan.objects[0].triangles, (std::vector<glm::uvec3>{{1, 2, 0}, {2, 3, 0}}));
}

TEST_F(BadGltf, SparseAccessorReplacesVertices) {
  // Vertex 3 of kQuad moved to (5, 5, 5) by a one-entry sparse block stored after the indices:
  // sparse index (u16 3, padded to 4 bytes), then the value (3 floats).
  std::vector<unsigned char> bytes(kQuad.size() * 4);
  std::memcpy(bytes.data(), kQuad.data(), bytes.size());
  for (std::uint16_t i : {0, 1, 2, 0, 2, 3}) {
    bytes.push_back(static_cast<unsigned char>(i));
    bytes.push_back(static_cast<unsigned char>(i >> 8));
  }
  const std::size_t sparse_idx = bytes.size();
  bytes.push_back(3);
  bytes.push_back(0);
  bytes.push_back(0);
  bytes.push_back(0);
  const std::size_t sparse_val = bytes.size();
  const float v[3] = {5, 5, 5};
  bytes.insert(bytes.end(), reinterpret_cast<const unsigned char*>(v),
               reinterpret_cast<const unsigned char*>(v) + 12);
  const std::string text =
      R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
      R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3",)"
      R"("sparse":{"count":1,"indices":{"bufferView":2,"componentType":5123},"values":{"bufferView":3}}},)"
      R"({"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}],)"
      R"("bufferViews":[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":12},)"
      R"({"buffer":0,"byteOffset":)" +
      std::to_string(sparse_idx) + R"(,"byteLength":2},{"buffer":0,"byteOffset":)" +
      std::to_string(sparse_val) + R"(,"byteLength":12}],"buffers":[{"byteLength":)" +
      std::to_string(bytes.size()) + R"(,"uri":"data:application/octet-stream;base64,)" +
      base64_encode(bytes) + "\"}]}";
  const Scene s = load_scene(write("sparse.gltf", text));
  ASSERT_EQ(s.objects[0].positions.size(), 4u);
  EXPECT_EQ(s.objects[0].positions[3], glm::vec3(5, 5, 5));
  EXPECT_EQ(s.objects[0].positions[2], glm::vec3(1, 1, 0));
}

// Found by fuzzing (docs/fuzzing.md): sparse indices of a float component type were read as
// doubles and cast to an index (1e30: undefined behaviour, UBSan float-cast-overflow; 1.5: vertex
// 1). glTF allows unsigned integers only.
TEST_F(BadGltf, FloatSparseIndicesAreRefused) {
  std::vector<unsigned char> bytes(kTri.size() * 4);
  std::memcpy(bytes.data(), kTri.data(), bytes.size());
  const float index_and_value[4] = {1e30f, 0, 0, 1};
  bytes.insert(bytes.end(), reinterpret_cast<const unsigned char*>(index_and_value),
               reinterpret_cast<const unsigned char*>(index_and_value) + 16);
  const std::string text =
      R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
      R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",)"
      R"("sparse":{"count":1,"indices":{"bufferView":1,"componentType":5126},)"
      R"("values":{"bufferView":2}}}],)"
      R"("bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":4},)"
      R"({"buffer":0,"byteOffset":40,"byteLength":12}],"buffers":[{"byteLength":52,)"
      R"("uri":"data:application/octet-stream;base64,)" +
      base64_encode(bytes) + "\"}]}";
  const std::string e = error_of(write("sparse_float.gltf", text));
  EXPECT_NE(e.find("POSITION (accessor 0): sparse indices must be unsigned integers, not "
                   "component type 5126"),
            std::string::npos)
      << e;
}

TEST_F(BadGltf, DataUriImageAndPointLight) {
  Texture t;
  t.name = "probe";
  t.width = 4;
  t.height = 2;
  for (std::uint32_t i = 0; i < 8; ++i)
    t.rgba.push_back(0xFF000000u | (i * 30u) | ((255u - i * 30u) << 8));
  const std::vector<unsigned char> png = encode_png(t);
  const std::string extra =
      R"(,"images":[{"uri":"data:image/png;base64,)" + base64_encode(png) +
      R"("}],"textures":[{"source":0}],"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],)"
      R"("extensionsUsed":["KHR_lights_punctual"],"extensions":{"KHR_lights_punctual":{"lights":[)"
      R"({"type":"point","color":[1,0.5,0.25],"intensity":0.5}]}})";
  std::string text = gltf(kTri, 4, "", extra);
  // A second root node carries the light, 2 units up.
  text.replace(text.find(R"("scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}])"),
               std::strlen(R"("scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}])"),
               R"("scenes":[{"nodes":[0,1]}],"nodes":[{"mesh":0},)"
               R"({"translation":[0,2,0],"extensions":{"KHR_lights_punctual":{"light":0}}}])");
  const Scene s = load_scene(write("datauri.gltf", text));
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].name, "embedded:0");
  EXPECT_EQ(s.textures[0].rgba, t.rgba);
  EXPECT_EQ(s.materials.at(0).texture, 0);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_FALSE(s.light_defaulted);
  EXPECT_EQ(s.lights[0].position, glm::vec3(0, 2, 0));
  EXPECT_EQ(s.lights[0].color, glm::vec3(0.5f, 0.25f, 0.125f));
}

TEST_F(BadGltf, UnsupportedRequiredExtensionIsRefused) {
  const std::string extra =
      R"(,"extensionsUsed":["KHR_draco_mesh_compression"],"extensionsRequired":["KHR_draco_mesh_compression"])";
  const std::string e = error_of(write("draco.gltf", gltf(kTri, 4, "", extra)));
  EXPECT_NE(e.find("requires extension KHR_draco_mesh_compression, which is not supported"),
            std::string::npos)
      << e;
  // Only used (not required), or cosmetic: a warning.
  const Scene s = load_scene(write(
      "cosmetic.gltf",
      gltf(
          kTri, 4, "",
          R"(,"extensionsUsed":["KHR_materials_unlit"],"extensionsRequired":["KHR_materials_unlit"])")));
  EXPECT_TRUE(has_warning(s, "extension KHR_materials_unlit is not supported: ignored"));
}

// KHR_materials_transmission and KHR_materials_ior (docs/scenes.md "Materials"): the transmission
// factor times (1 - metallic) is the refraction weight, ior the index of the material's inside
// (1.5 when absent); both extensions are supported (no warning, may be required); a transmission
// texture and an ior below 1 are reduced with a warning.
TEST_F(BadGltf, TransmissionAndIorMapToRefraction) {
  const std::string extra =
      R"(,"materials":[)"
      R"({"name":"water","pbrMetallicRoughness":{"metallicFactor":0.25},"extensions":{)"
      R"("KHR_materials_transmission":{"transmissionFactor":0.8},"KHR_materials_ior":{"ior":1.33}}},)"
      R"({"name":"glass","extensions":{"KHR_materials_transmission":{"transmissionFactor":1.0}}},)"
      R"({"name":"odd","extensions":{"KHR_materials_transmission":{"transmissionFactor":2.0,)"
      R"("transmissionTexture":{"index":0}},"KHR_materials_ior":{"ior":0.5}}},)"
      R"({"name":"opaque"}],)"
      R"("extensionsUsed":["KHR_materials_transmission","KHR_materials_ior"],)"
      R"("extensionsRequired":["KHR_materials_transmission"])";
  const Scene s = load_scene(write("glass.gltf", gltf(kTri, 4, "", extra)));
  ASSERT_GE(s.materials.size(), 4u);
  const Material& water = s.materials[0];
  EXPECT_FLOAT_EQ(water.transmission, 0.8f);
  EXPECT_FLOAT_EQ(water.refraction, 0.6f);  // 0.8 * (1 - 0.25): metals do not transmit
  EXPECT_FLOAT_EQ(water.ior, 1.33f);
  EXPECT_FLOAT_EQ(water.transparency, 0.0f);
  EXPECT_FLOAT_EQ(s.materials[1].refraction, 0.0f);  // glTF's default metallic is 1
  EXPECT_FLOAT_EQ(s.materials[1].transmission, 1.0f);
  EXPECT_FLOAT_EQ(s.materials[1].ior, 1.5f);           // glTF's default
  EXPECT_FLOAT_EQ(s.materials[2].transmission, 1.0f);  // clamped
  EXPECT_FLOAT_EQ(s.materials[2].ior, 1.5f);
  EXPECT_FLOAT_EQ(s.materials[3].transmission, 0.0f);
  EXPECT_FLOAT_EQ(s.materials[3].refraction, 0.0f);
  EXPECT_TRUE(has_warning(s, "material 'odd': ior 0.500000 is outside 1..64: 1.5 is used"));
  EXPECT_TRUE(has_warning(
      s, "material 'odd': transmissionTexture is not supported: transmissionFactor alone is used"));
  for (const std::string& w : s.warnings)
    EXPECT_EQ(w.find("is not supported: ignored"), std::string::npos) << w;
}

TEST_F(BadGltf, UnknownBuiltinListsTheKnownOnes) {
  const std::string e = error_of("builtin:nope");
  EXPECT_NE(e.find("unknown built-in scene 'builtin:nope'"), std::string::npos) << e;
  EXPECT_NE(e.find("suncor"), std::string::npos) << e;
}

}  // namespace
}  // namespace saarcor::host
