// AFF import (docs/aff.md): the two BART scenes of the shared MANIFEST.md load with the published
// triangle counts, their keyframed objects and camera move, BART's Kochanek-Bartels splines give
// hand-computed values, small hand-written files check static transforms, a two-key translation,
// includes relative to the including file, textures, lights and the camera, and one test per
// class of bad input checks that it is refused with one error naming the file and line.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <glm/gtc/quaternion.hpp>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/aff_loader.h"
#include "host/scene.h"

namespace saarcor::host {
namespace {

namespace fs = std::filesystem;

const std::string kScenes = SAARCOR_SHARED_SCENES;
const std::string kKitchen = kScenes + "/BART/kitchen/aff/kitchen.aff";
const std::string kRobot = kScenes + "/BART/robot/aff/Robot.aff";

// The two BART scenes are loaded once per test program (through load_scene: the dispatch).
const Scene& kitchen() {
  static const Scene s = load_scene(kKitchen);
  return s;
}
const Scene& robot() {
  static const Scene s = load_scene(kRobot);
  return s;
}

int node_named(const Scene& s, const std::string& name) {
  for (std::size_t i = 0; i < s.nodes.size(); ++i)
    if (s.nodes[i].name == name) return static_cast<int>(i);
  return -1;
}

// Instances placed by node n or a node below it.
std::vector<std::size_t> instances_below(const Scene& s, int n) {
  std::set<int> below{n};
  for (bool grew = true; grew;) {
    grew = false;
    for (std::size_t i = 0; i < s.nodes.size(); ++i)
      if (s.nodes[i].parent >= 0 && below.count(s.nodes[i].parent) &&
          below.insert(static_cast<int>(i)).second)
        grew = true;
  }
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < s.instances.size(); ++i)
    if (below.count(static_cast<int>(s.instances[i].id))) out.push_back(i);
  return out;
}

glm::dvec3 apply(const glm::dmat4& m, const glm::dvec3& p) {
  return glm::dvec3(m * glm::dvec4(p, 1.0));
}

void expect_near3(const glm::dvec3& a, const glm::dvec3& b, double tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// ---------------------------------------------------------------------------------------------
// The BART scenes.

TEST(AffBart, KitchenHasTheManifestCounts) {
  const Scene& s = kitchen();
  EXPECT_EQ(s.instanced_triangles(), 110561u);  // MANIFEST.md / the published BART figure
  EXPECT_LT(s.unique_triangles(), s.instanced_triangles());  // the 4 stools are instances
  EXPECT_EQ(s.lights.size(), 6u);
  EXPECT_FALSE(s.light_defaulted);
  EXPECT_FLOAT_EQ(s.lights[0].position.x, 2.15f);
  EXPECT_FLOAT_EQ(s.lights[4].color.r, 0.4f);
  EXPECT_EQ(s.textures.size(), 8u);  // the 8 PPM files of TextureFiles/
  for (const Texture& t : s.textures) {
    EXPECT_GT(t.width, 0);
    EXPECT_EQ(t.rgba.size(),
              static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height));
  }
  ASSERT_EQ(s.cameras.size(), 1u);
  EXPECT_NEAR(s.cameras[0].yfov, glm::radians(40.0f), 1e-6);
  EXPECT_DOUBLE_EQ(s.animation_seconds, 20.0);  // `a 0.0 20.0 800`
  EXPECT_EQ(s.skipped_primitives, 0u);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  // The glasses, the bowl and the dragon are glass (param_glass.aff: T 0.85, index 1.55).
  int glass = 0;
  for (const Material& m : s.materials)
    glass += m.refraction == 0.85f && m.ior == 1.55f ? 1 : 0;
  EXPECT_GT(glass, 0);
}

TEST(AffBart, KitchenStoolsAreOneSetOfObjectsInstancedFourTimes) {
  const Scene& s = kitchen();
  std::vector<std::vector<std::uint32_t>> stools;
  std::set<std::pair<double, double>> where;
  std::uint64_t stool_triangles = 0;
  for (std::size_t n = 0; n < s.nodes.size(); ++n) {
    if (s.nodes[n].name != "bar_stool.aff") continue;
    std::vector<std::uint32_t> objects;
    stool_triangles = 0;
    for (std::size_t i : instances_below(s, static_cast<int>(n))) {
      objects.push_back(s.instances[i].object);
      stool_triangles += s.objects[s.instances[i].object].triangles.size();
    }
    stools.push_back(objects);
    // bar_stools.aff places them with `xs` at x 1.56 / 2.93, z 1.45 / 0.65.
    const Node& xs = s.nodes[static_cast<std::size_t>(s.nodes[n].parent)];
    where.emplace(xs.translation.x, xs.translation.z);
  }
  ASSERT_EQ(stools.size(), 4u);
  EXPECT_GT(stools[0].size(), 5u);
  for (const auto& o : stools)
    EXPECT_EQ(o, stools[0]);  // the same objects, stored once
  EXPECT_GT(stool_triangles, 10000u);
  // Three of the four stools are instances (other repeated includes share objects too).
  EXPECT_GE(s.instanced_triangles() - s.unique_triangles(), 3 * stool_triangles);
  EXPECT_EQ(where, (std::set<std::pair<double, double>>{
                       {1.56, 0.65}, {1.56, 1.45}, {2.93, 0.65}, {2.93, 1.45}}));
}

TEST(AffBart, RobotHasTheManifestCounts) {
  const Scene& s = robot();
  EXPECT_EQ(s.instanced_triangles(), 71708u);
  EXPECT_LT(s.unique_triangles(), s.instanced_triangles());  // 10 robots share their parts
  EXPECT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.textures.size(), 44u);
  ASSERT_EQ(s.cameras.size(), 1u);
  EXPECT_NEAR(s.cameras[0].yfov, glm::radians(36.869890479389504), 1e-6);
  EXPECT_DOUBLE_EQ(s.animation_seconds, 50.0);  // `a 0 50 800`
  // Facts of the data: `k old_camera` animates nothing, five `x` blocks have no `k`, and
  // gun_rot1's key times restart at 42 s after 48 s.
  const std::string all = [&] {
    std::string j;
    for (const std::string& w : s.warnings)
      j += w + "\n";
    return j;
  }();
  EXPECT_EQ(s.warnings.size(), 7u) << all;
  for (const char* w : {"'old_camera' animate nothing", "'grip_lift1' has no keyframes",
                        "'head_rot2' has no keyframes", "Robot1.aff:364: key times of 'gun_rot1'"})
    EXPECT_NE(all.find(w), std::string::npos) << w;
}

TEST(AffBart, KitchenToyCarAndCameraMove) {
  Scene s = kitchen();
  const int car = node_named(s, "toycar");
  ASSERT_GE(car, 0);
  EXPECT_TRUE(s.nodes[static_cast<std::size_t>(car)].animated);
  const std::vector<std::size_t> parts = instances_below(s, car);
  ASSERT_FALSE(parts.empty());
  for (std::size_t i : parts)
    EXPECT_TRUE(s.instances[i].dynamic);
  // `k toycar`: transl key (4.45, 0, 2.75) at t=3 (held before it), (3.75, 0, 2.75) at t=5.
  expect_near3(s.nodes[static_cast<std::size_t>(car)].translation, {4.45, 0.0, 2.75}, 1e-12);
  const glm::dmat4 body0 = s.instances[parts[0]].object_to_world;
  const Aabb bounds0 = world_bounds(s);
  const Camera cam0 = scene_camera(s);
  // `k camera`: transl (3.75, 2.3, 3.6) at t=0; rot -31.77348 degrees about (0.77895, -0.61838,
  // -0.10410).
  expect_near3(glm::dvec3(cam0.position), {3.75, 2.3, 3.6}, 1e-6);
  const glm::dquat q0 = glm::angleAxis(glm::radians(-31.77348),
                                       glm::normalize(glm::dvec3(0.77895, -0.61838, -0.10410)));
  expect_near3(glm::dvec3(cam0.forward), q0 * glm::dvec3(0.0, 0.0, -1.0), 1e-6);
  expect_near3(glm::dvec3(cam0.up), q0 * glm::dvec3(0.0, 1.0, 0.0), 1e-6);

  s.set_time(5.0);
  expect_near3(s.nodes[static_cast<std::size_t>(car)].translation, {3.75, 0.0, 2.75}, 1e-12);
  const Camera cam5 = scene_camera(s);
  expect_near3(glm::dvec3(cam5.position), {3.5, 0.2, 0.1}, 1e-6);
  // -180 degrees about -Y: looks along +Z.
  expect_near3(glm::dvec3(cam5.forward), {0.0, 0.0, 1.0}, 1e-6);
  expect_near3(glm::dvec3(cam5.up), {0.0, 1.0, 0.0}, 1e-6);

  s.set_time(10.0);
  const glm::dmat4 body10 = s.instances[parts[0]].object_to_world;
  EXPECT_GT(glm::length(glm::dvec3(body10[3]) - glm::dvec3(body0[3])), 0.5);
  // Static objects stay where they are, so the scene's bounds are unchanged (the car is inside).
  const Aabb bounds10 = world_bounds(s);
  EXPECT_FLOAT_EQ(bounds10.lo.x, bounds0.lo.x);
  EXPECT_FLOAT_EQ(bounds10.hi.y, bounds0.hi.y);
  // Past the end the clock clamps to 20 s.
  s.set_time(100.0);
  EXPECT_DOUBLE_EQ(s.time, 20.0);
}

TEST(AffBart, RobotsWalk) {
  Scene s = robot();
  const int r1 = node_named(s, "robot_transl1");
  ASSERT_GE(r1, 0);
  const std::vector<std::size_t> parts = instances_below(s, r1);
  ASSERT_GT(parts.size(), 10u);
  Aabb a;
  const auto robot_bounds = [&](const Scene& sc) {
    Aabb b;
    for (std::size_t i : parts)
      b.grow(glm::vec3(sc.instances[i].object_to_world[3]));
    return b;
  };
  a = robot_bounds(s);
  const glm::dvec3 cam_a(scene_camera(s).position);
  s.set_time(20.0);
  const Aabb b = robot_bounds(s);
  const glm::dvec3 cam_b(scene_camera(s).position);
  EXPECT_GT(glm::length(glm::dvec3(b.lo) - glm::dvec3(a.lo)), 1.0);
  // Robot.aff `k camera` transl: (-3.5, 2, -203) at t=0.
  expect_near3(cam_a, {-3.5, 2.0, -203.0}, 1e-6);
  EXPECT_GT(glm::length(cam_b - cam_a), 10.0);
}

// ---------------------------------------------------------------------------------------------
// BART's splines.

std::vector<AffKey> keys1d(std::initializer_list<std::pair<double, double>> tv, double tension) {
  std::vector<AffKey> k;
  for (const auto& [t, v] : tv) {
    AffKey key;
    key.time = t;
    key.value = {v, 0.0, 0.0, 0.0};
    key.tension = tension;
    k.push_back(key);
  }
  return k;
}

TEST(AffSpline, CatmullRomWithZeroTcb) {
  // Keys 0 -> 1 between t=0 and t=1, tangent keys at -1 (0) and 2 (1): Catmull-Rom with tangents
  // 0.5 at both ends, x(u) = 0.5u + 1.5u^2 - u^3.
  const auto k = keys1d({{-1, 0}, {0, 0}, {1, 1}, {2, 1}}, 0.0);
  EXPECT_DOUBLE_EQ(aff_position_spline(k, 0.25).x, 0.203125);
  EXPECT_DOUBLE_EQ(aff_position_spline(k, 0.5).x, 0.5);
  EXPECT_DOUBLE_EQ(aff_position_spline(k, -3.0).x, 0.0);  // clamped to the first real key
  EXPECT_DOUBLE_EQ(aff_position_spline(k, 9.0).x, 1.0);   // and to the last
}

TEST(AffSpline, TensionOneEasesInAndOut) {
  // Collinear, evenly spaced keys: linear with tension 0, 3u^2 - 2u^3 with tension 1.
  const auto lin = keys1d({{-1, -1}, {0, 0}, {1, 1}, {2, 2}}, 0.0);
  const auto ease = keys1d({{-1, -1}, {0, 0}, {1, 1}, {2, 2}}, 1.0);
  EXPECT_DOUBLE_EQ(aff_position_spline(lin, 0.25).x, 0.25);
  EXPECT_DOUBLE_EQ(aff_position_spline(ease, 0.25).x, 0.15625);
}

TEST(AffSpline, ContinuityAndBiasFollowKochanekBartels) {
  // Keys 0, 0, 1, 1 at t = -1..2. Bias +1 at key 1 gives the incoming chord P1 - P0 (= 0) weight
  // 1 and the outgoing chord weight 0: Tout = 0, Tin = 0.5, so c2 = 3 - 0 - 0.5 = 2.5 and
  // c3 = -2 + 0 + 0.5 = -1.5 in x(u) = c1 u + c2 u^2 + c3 u^3.
  auto k = keys1d({{-1, 0}, {0, 0}, {1, 1}, {2, 1}}, 0.0);
  k[1].bias = 1.0;
  EXPECT_DOUBLE_EQ(aff_position_spline(k, 0.5).x, 0.25 * 2.5 - 0.125 * 1.5);
  // Continuity -1 at key 2: Tin = in1 (P3 - P2) + in0 (P2 - P1) with in1 = 0, in0 = 1: Tin = 1.
  auto c = keys1d({{-1, 0}, {0, 0}, {1, 1}, {2, 1}}, 0.0);
  c[2].continuity = -1.0;
  // Tout = 0.5, Tin = 1: c2 = 3 - 1 - 1 = 1, c3 = -2 + 0.5 + 1 = -0.5.
  EXPECT_DOUBLE_EQ(aff_position_spline(c, 0.5).x, 0.25 + 0.25 - 0.0625);
}

TEST(AffSpline, RotationAboutOneAxisIsLinearInAngle) {
  std::vector<AffKey> k(4);
  const double deg[] = {-90, 0, 90, 180};
  for (int i = 0; i < 4; ++i) {
    k[static_cast<std::size_t>(i)].time = i - 1;
    k[static_cast<std::size_t>(i)].value = {0.0, 1.0, 0.0, glm::radians(deg[i])};
  }
  for (double t : {0.0, 0.25, 0.5, 1.0}) {
    const glm::dquat q = aff_rotation_spline(k, t);
    const glm::dquat want = glm::angleAxis(glm::radians(90.0 * t), glm::dvec3(0, 1, 0));
    EXPECT_NEAR(std::abs(glm::dot(q, want)), 1.0, 1e-12) << t;
  }
}

TEST(AffSpline, RotationPassesThroughItsKeys) {
  std::vector<AffKey> k(5);
  const glm::dvec4 v[] = {
      {1, 0, 0, 0.3}, {0, 1, 0, 0.5}, {0, 0, 1, 1.2}, {1, 1, 0, -0.7}, {0, 1, 1, 2.0}};
  for (int i = 0; i < 5; ++i) {
    k[static_cast<std::size_t>(i)].time = 0.5 * i;
    k[static_cast<std::size_t>(i)].value = v[i];
    k[static_cast<std::size_t>(i)].tension = 0.3;
  }
  for (int i = 1; i <= 3; ++i) {
    const glm::dquat q = aff_rotation_spline(k, 0.5 * i);
    const glm::dquat want = glm::angleAxis(v[i].w, glm::normalize(glm::dvec3(v[i])));
    EXPECT_NEAR(std::abs(glm::dot(q, want)), 1.0, 1e-12) << i;
  }
}

// ---------------------------------------------------------------------------------------------
// Hand-written files.

class AffFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("saarcor_aff_" + std::to_string(getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& rel, const std::string& text) {
    const fs::path p = dir_ / rel;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }

  // Refused with one std::runtime_error whose message starts "FILE:LINE: " and contains `what`.
  void expect_refused(const std::string& root, const std::string& file, int line,
                      const std::string& what) {
    try {
      load_scene(root);
      ADD_FAILURE() << "no error for " << root;
    } catch (const std::runtime_error& e) {
      const std::string msg = e.what();
      const std::string where = (dir_ / file).string() + ":" + std::to_string(line) + ": ";
      EXPECT_EQ(msg.rfind(where, 0), 0u) << msg;
      EXPECT_NE(msg.find(what), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }

  fs::path dir_;
};

const char* kTriangle =
    "m\n"
    " vertices 3\n"
    "  1 0 0\n"
    "  0 1 0\n"
    "  0 0 1\n"
    " triangles 1\n"
    "  0 1 2\n";

TEST_F(AffFiles, StaticTransformIsTranslateRotateScale) {
  const std::string root = write("static.aff",
                                 "fm 0.1 0.1 0.1  0.8 0.2 0.1  0.5 0.5 0.5  30 0.25 1.5\n"
                                 "xs 2 2 2\n"
                                 "   0 0 1 90\n"
                                 "   1 2 3\n"
                                 "{\n" +
                                     std::string(kTriangle) + "}\n");
  const Scene s = load_scene(root);
  ASSERT_EQ(s.instances.size(), 1u);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.instanced_triangles(), 1u);
  EXPECT_FALSE(s.instances[0].dynamic);
  // T * R * S: (1,0,0) -> scale (2,0,0) -> 90 degrees about Z (0,2,0) -> translate (1,4,3).
  const glm::dmat4& m = s.instances[0].object_to_world;
  expect_near3(apply(m, {1, 0, 0}), {1, 4, 3}, 1e-12);
  expect_near3(apply(m, {0, 1, 0}), {-1, 2, 3}, 1e-12);
  expect_near3(apply(m, {0, 0, 1}), {1, 2, 5}, 1e-12);
  const Aabb b = world_bounds(s);
  EXPECT_FLOAT_EQ(b.lo.x, -1.0f);
  EXPECT_FLOAT_EQ(b.hi.y, 4.0f);
  // fm: diffuse, specular, Shine, T, ior; reflectivity = mean specular; T refracts with ior.
  ASSERT_EQ(s.materials.size(), 1u);
  const Material& mat = s.materials[0];
  EXPECT_FLOAT_EQ(mat.base_color.r, 0.8f);
  EXPECT_FLOAT_EQ(mat.base_color.b, 0.1f);
  EXPECT_FLOAT_EQ(mat.specular.g, 0.5f);
  EXPECT_FLOAT_EQ(mat.shininess, 30.0f);
  EXPECT_FLOAT_EQ(mat.transparency, 0.0f);
  EXPECT_FLOAT_EQ(mat.refraction, 0.25f);
  EXPECT_FLOAT_EQ(mat.ior, 1.5f);
  EXPECT_FLOAT_EQ(mat.reflectivity, 0.5f);
  EXPECT_TRUE(s.objects[0].normals.empty());
  EXPECT_TRUE(s.cameras.empty());
  EXPECT_TRUE(s.light_defaulted);  // no `l`: load_scene adds the default light
}

TEST_F(AffFiles, TwoKeyTranslationIsLinear) {
  // Two real keys (t=0 at x=0, t=1 at x=1) plus BART's two tangent keys on the same line: the
  // KB spline is exactly linear.
  const std::string root = write("move.aff",
                                 "a 0 1 25\n"
                                 "x mover\n"
                                 "{\n" +
                                     std::string(kTriangle) +
                                     "}\n"
                                     "k mover\n"
                                     "{\n"
                                     "  transl 4\n"
                                     "   -1  -1 0 0  0 0 0\n"
                                     "    0   0 0 0  0 0 0\n"
                                     "    1   1 0 0  0 0 0\n"
                                     "    2   2 0 0  0 0 0\n"
                                     "}\n");
  Scene s = load_scene(root);
  ASSERT_EQ(s.instances.size(), 1u);
  EXPECT_TRUE(s.instances[0].dynamic);
  EXPECT_DOUBLE_EQ(s.animation_seconds, 1.0);
  ASSERT_EQ(s.animations.size(), 1u);
  EXPECT_EQ(s.animations[0].path, AnimPath::kTranslation);
  EXPECT_EQ(s.animations[0].times.size(), 61u);  // 60 samples per second, both ends
  for (double t : {0.0, 0.1, 0.25, 0.5, 0.7, 1.0}) {
    s.set_time(t);
    expect_near3(glm::dvec3(s.instances[0].object_to_world[3]), {t, 0, 0}, 1e-12);
  }
}

TEST_F(AffFiles, KeysAtTheSameTimeMakeAJump) {
  // Keys at t=1 with x=1 and x=5: BART's spline jumps there (the segment that starts at t=1 is
  // used from t=1 on). The channel holds both one-sided values at t=1.
  const std::string root = write("jump.aff", "x j {\n" + std::string(kTriangle) +
                                                 "}\n"
                                                 "k j { transl 6\n"
                                                 "  -1 0 0 0 0 0 0\n"
                                                 "   0 0 0 0 0 0 0\n"
                                                 "   1 1 0 0 0 0 0\n"
                                                 "   1 5 0 0 0 0 0\n"
                                                 "   2 6 0 0 0 0 0\n"
                                                 "   3 7 0 0 0 0 0 }\n");
  Scene s = load_scene(root);
  EXPECT_DOUBLE_EQ(s.animation_seconds, 2.0);
  ASSERT_EQ(s.animations.size(), 1u);
  const auto& times = s.animations[0].times;
  EXPECT_EQ(std::count(times.begin(), times.end(), 1.0), 2);
  std::vector<AffKey> keys(6);
  const double kt[] = {-1, 0, 1, 1, 2, 3}, kx[] = {0, 0, 1, 5, 6, 7};
  for (std::size_t i = 0; i < 6; ++i) {
    keys[i].time = kt[i];
    keys[i].value.x = kx[i];
  }
  EXPECT_DOUBLE_EQ(aff_position_spline(keys, 1.0).x, 5.0);
  s.set_time(1.0);
  EXPECT_NEAR(s.instances[0].object_to_world[3].x, 5.0, 1e-12);
  s.set_time(1.0 - 1e-7);
  EXPECT_NEAR(s.instances[0].object_to_world[3].x, 1.0, 1e-6);
  for (double t : {0.3, 0.77, 1.5}) {
    s.set_time(t);
    EXPECT_NEAR(s.instances[0].object_to_world[3].x, aff_position_spline(keys, t).x, 1e-3) << t;
  }
}

TEST_F(AffFiles, KeyframedRotationAndScaleUnderAStaticParent) {
  const std::string root = write("spin.aff",
                                 "xs 1 1 1  0 1 0 0  5 0 0\n"
                                 "{\n"
                                 "  x spin\n"
                                 "  {\n" +
                                     std::string(kTriangle) +
                                     "  }\n"
                                     "}\n"
                                     "k spin\n"
                                     "{\n"
                                     "  rot 4\n"
                                     "   -2  0 0 1 -180  0 0 0\n"
                                     "    0  0 0 1    0  0 0 0\n"
                                     "    2  0 0 1  180  0 0 0\n"
                                     "    4  0 0 1  360  0 0 0\n"
                                     "  scale 4\n"
                                     "   -2  -1 -1 -1  0 0 0\n"
                                     "    0   1  1  1  0 0 0\n"
                                     "    2   3  3  3  0 0 0\n"
                                     "    4   5  5  5  0 0 0\n"
                                     "}\n");
  Scene s = load_scene(root);
  EXPECT_DOUBLE_EQ(s.animation_seconds, 2.0);  // no `a`: the end of the splines
  s.set_time(1.0);                             // 90 degrees about Z, scale 2
  expect_near3(apply(s.instances[0].object_to_world, {1, 0, 0}), {5, 2, 0}, 1e-9);
  s.set_time(2.0);  // 180 degrees, scale 3
  expect_near3(apply(s.instances[0].object_to_world, {1, 0, 0}), {2, 0, 0}, 1e-9);
}

TEST_F(AffFiles, IncludesAreRelativeToTheIncludingFile) {
  // root.aff includes parts/arm.aff, which includes leaf.aff from parts/ (there is no leaf.aff
  // next to root.aff) twice, under two static transforms.
  write("parts/leaf.aff", kTriangle);
  write("parts/arm.aff",
        "xs 1 1 1  1 0 0 0  0 0 0 { i 0 leaf.aff }\n"
        "xs 1 1 1  1 0 0 0  0 5 0 { i 0 leaf.aff }\n"
        "p 4\n"
        "  0 0 0\n"
        "  1 0 0\n"
        "  1 1 0\n"
        "  0 1 0\n");
  const std::string root = write("root.aff", "i 0 parts/arm.aff\n");
  const Scene s = load_scene(root);
  // Two leaf triangles (one object, instanced twice) and the quad of arm.aff as a 2-triangle fan.
  EXPECT_EQ(s.instanced_triangles(), 4u);
  EXPECT_EQ(s.unique_triangles(), 3u);
  ASSERT_EQ(s.instances.size(), 3u);
  std::vector<double> leaf_y;
  for (const Instance& i : s.instances)
    if (s.nodes[i.id].name == "leaf.aff") leaf_y.push_back(i.object_to_world[3].y);
  EXPECT_EQ(leaf_y, (std::vector<double>{0.0, 5.0}));
}

// NFF's `f ... T index_of_refraction` (docs/aff.md, docs/scenes.md "Materials"): T is the weight
// of the refraction ray, the index that of the material's inside; BART's 0 ("none") and indices
// outside 1/64..64 refract with index 1 (a straight ray); materials differing only in the index
// stay apart.
TEST_F(AffFiles, TransmittanceRefractsWithTheIndexOfRefraction) {
  const std::string root =
      write("glass.aff", "f 1 1 1  0.1 0.2 40 0.7 1.33\n" + std::string(kTriangle) +
                             "f 1 1 1  0.1 0.2 40 0.7 1.7\n" + kTriangle +
                             "f 1 1 1  0.1 0.2 40 0.04 0\n" + kTriangle +
                             "f 1 1 1  0.1 0.2 40 0 0\n" + kTriangle);
  const Scene s = load_scene(root);
  ASSERT_EQ(s.materials.size(), 4u);
  EXPECT_FLOAT_EQ(s.materials[0].refraction, 0.7f);
  EXPECT_FLOAT_EQ(s.materials[0].transmission, 0.7f);
  EXPECT_FLOAT_EQ(s.materials[0].ior, 1.33f);
  EXPECT_FLOAT_EQ(s.materials[0].transparency, 0.0f);
  EXPECT_FLOAT_EQ(s.materials[0].reflectivity, 0.2f);  // Ks
  EXPECT_FLOAT_EQ(s.materials[1].ior, 1.7f);
  EXPECT_FLOAT_EQ(s.materials[2].refraction, 0.04f);
  EXPECT_FLOAT_EQ(s.materials[2].ior, 1.0f);
  EXPECT_FLOAT_EQ(s.materials[3].refraction, 0.0f);
}

TEST_F(AffFiles, MaterialStateDecidesWhetherAnIncludeIsShared) {
  // part.aff has no material of its own: included under two different materials it needs two
  // objects; tinted.aff sets its own material first, so it is shared.
  write("part.aff", kTriangle);
  write("tinted.aff", std::string("f 1 0 0  1 0 0 0 1\n") + kTriangle);
  const std::string root = write("mat.aff",
                                 "f 0 1 0  1 0 0 0 1\n"
                                 "xs 1 1 1 1 0 0 0 0 0 0 { i 0 part.aff }\n"
                                 "xs 1 1 1 1 0 0 0 0 0 0 { i 0 tinted.aff }\n"
                                 "f 0 0 1  1 0 0 0 1\n"
                                 "xs 1 1 1 1 0 0 0 0 0 0 { i 0 part.aff }\n"
                                 "xs 1 1 1 1 0 0 0 0 0 0 { i 0 tinted.aff }\n");
  const Scene s = load_scene(root);
  EXPECT_EQ(s.instances.size(), 4u);
  EXPECT_EQ(s.objects.size(), 3u);
  std::set<std::pair<float, float>> colours;  // (green, blue) of each part.aff instance
  for (const Instance& i : s.instances) {
    const Material& m = s.materials[s.objects[i.object].material[0]];
    if (s.nodes[i.id].name == "part.aff")
      colours.emplace(m.base_color.g, m.base_color.b);
    else
      EXPECT_FLOAT_EQ(m.base_color.r, 1.0f);
  }
  EXPECT_EQ(colours, (std::set<std::pair<float, float>>{{1.0f, 0.0f}, {0.0f, 1.0f}}));
}

// The view and lights of MeshWithNormalsTextureCameraAndLights' file.
void expect_view_and_lights(const Scene& s) {
  ASSERT_EQ(s.cameras.size(), 1u);
  const Camera& c = s.cameras[0];
  expect_near3(glm::dvec3(c.position), {0, 0, 10}, 0.0);
  expect_near3(glm::dvec3(c.forward), {0, 0, -1}, 1e-7);
  expect_near3(glm::dvec3(c.up), {0, 1, 0}, 1e-7);  // orthogonalised
  EXPECT_NEAR(c.yfov, glm::radians(30.0f), 1e-7);
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].color, glm::vec3(1.0f));               // colour optional, white
  EXPECT_EQ(s.lights[1].color, glm::vec3(0.5f, 0.25f, 1.0f));  // clamped to 1
  EXPECT_EQ(s.lights[1].position, glm::vec3(4, 5, 6));
}

TEST_F(AffFiles, MeshWithNormalsTextureCameraAndLights) {
  // A 2x1 binary PPM: red, green. BART keeps textures in ../TextureFiles.
  write("TextureFiles/rg.ppm",
        std::string("P6\n2 1\n255\n") + std::string("\xff\x00\x00\x00\xff\x00", 6));
  const std::string root = write("aff/scene.aff",
                                 "b 0.1 0.2 0.3\n"
                                 "v\n"
                                 "from 0 0 10\n"
                                 "at 0 0 0\n"
                                 "up 0 2 0.5\n"
                                 "angle 30\n"
                                 "hither 0.01\n"
                                 "resolution 640 480\n"
                                 "am 0.5 0.5 0.5\n"
                                 "l 1 2 3\n"
                                 "l 4 5 6  0.5 0.25 2\n"
                                 "fm 0 0 0  0 0 0  0 0 0  0 0 0\n"
                                 "m\n"
                                 " vertices 4\n"
                                 "  0 0 0\n"
                                 "  1 0 0\n"
                                 "  1 1 0\n"
                                 "  0 1 0\n"
                                 " normals 1\n"
                                 "  0 0 2\n"
                                 " texturecoords 4 rg.ppm\n"
                                 "  0 0\n"
                                 "  1 0\n"
                                 "  1 1\n"
                                 "  0 1\n"
                                 " triangles 2\n"
                                 "  0 1 2  0 0 0  0 1 2\n"
                                 "  0 2 3  0 0 0  0 2 3\n");
  const Scene s = load_scene(root);
  ASSERT_EQ(s.objects.size(), 1u);
  const Object& o = s.objects[0];
  EXPECT_EQ(o.positions.size(), 4u);  // (vertex, normal, uv) triples 0,1,2,3 are shared
  ASSERT_EQ(o.normals.size(), 4u);
  EXPECT_FLOAT_EQ(o.normals[2].z, 1.0f);  // normalised
  ASSERT_EQ(o.texcoords.size(), 4u);
  EXPECT_FLOAT_EQ(o.texcoords[2].x, 1.0f);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].name, "rg.ppm");
  EXPECT_EQ(s.textures[0].width, 2);
  EXPECT_EQ(s.textures[0].height, 1);
  EXPECT_EQ(s.textures[0].rgba[0], 0xFF0000FFu);  // red, alpha 255
  EXPECT_EQ(s.textures[0].rgba[1], 0xFF00FF00u);  // green
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].texture, 0);
  EXPECT_FLOAT_EQ(s.materials[0].base_color.r, 1.0f);  // the texture replaces the diffuse colour
  expect_view_and_lights(s);
}

TEST_F(AffFiles, AnimatedLightAndCameraKeys) {
  const std::string root = write("la.aff",
                                 "v from 0 0 5 at 0 0 0 up 0 1 0 angle 45 hither 1 resolution 4 4\n"
                                 "la lamp 0 9 0\n"
                                 "k lamp { transl 4  -1 -1 9 0 0 0 0  0 0 9 0 0 0 0  "
                                 "4 4 9 0 0 0 0  5 5 9 0 0 0 0 }\n"
                                 "k camera { transl 4  -1 0 0 6 0 0 0  0 0 0 5 0 0 0  "
                                 "4 0 0 1 0 0 0  5 0 0 0 0 0 0 }\n" +
                                     std::string(kTriangle));
  Scene s = load_scene(root);
  EXPECT_DOUBLE_EQ(s.animation_seconds, 4.0);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_GE(s.lights[0].node, 0);
  s.set_time(2.0);
  EXPECT_NEAR(s.lights[0].position.x, 2.0f, 1e-6);
  EXPECT_NEAR(s.lights[0].position.y, 9.0f, 1e-6);
  const Camera c = scene_camera(s);
  EXPECT_NEAR(c.position.z, 3.0f, 1e-6);
  expect_near3(glm::dvec3(c.forward), {0, 0, -1}, 1e-7);  // no rot keys: the `v` direction
}

TEST_F(AffFiles, RelativeRootFindsIncludesAndTexturesAndSkipsSpheres) {
  // BART's layout, loaded as a bare relative name from inside aff/: includes next to it,
  // textures in ../TextureFiles. Spheres and cones are skipped with one warning per kind.
  write("TextureFiles/g.ppm", std::string("P6\n1 1\n255\n") + std::string("\x10\x20\x30", 3));
  write("aff/part.aff",
        "tt g.ppm\n"
        "  0 0 0  0 0\n"
        "  1 0 0  1 0\n"
        "  0 1 0  0 1\n");
  write("aff/main.aff",
        "s 0 0 0 1\n"
        "s 1 0 0 1\n"
        "c 0 0 0 1  0 1 0 0.5\n"
        "i 0 part.aff\n");
  const fs::path cwd = fs::current_path();
  fs::current_path(dir_ / "aff");
  Scene s;
  try {
    s = load_scene("main.aff");
  } catch (...) {
    fs::current_path(cwd);
    throw;
  }
  fs::current_path(cwd);
  EXPECT_EQ(s.instanced_triangles(), 1u);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].rgba[0], 0xFF302010u);
  EXPECT_EQ(s.skipped_primitives, 3u);
  EXPECT_EQ(s.warnings.size(), 2u);  // sphere, cone
}

TEST_F(AffFiles, DetailLevelSelectsIncludesAndPatchesKeepNormals) {
  // `i 1 ...` is skipped at detail level 0 (so a missing file there is no error); `d 1` admits it.
  write("patch.aff",
        "pp 4\n"
        "  0 0 0  0 0 3\n"
        "  1 0 0  0 0 3\n"
        "  1 1 0  0 0 3\n"
        "  0 1 0  0 0 3\n");
  const std::string root = write("detail.aff",
                                 "i 1 not_there.aff\n"
                                 "d 1\n"
                                 "i 1 patch.aff\n"
                                 "i 2 not_there_either.aff\n");
  const Scene s = load_scene(root);
  EXPECT_EQ(s.instanced_triangles(), 2u);  // the quad patch as a fan
  ASSERT_EQ(s.objects.size(), 1u);
  ASSERT_EQ(s.objects[0].normals.size(), 4u);
  EXPECT_FLOAT_EQ(s.objects[0].normals[3].z, 1.0f);
  EXPECT_EQ(s.objects[0].triangles[1], glm::uvec3(0, 2, 3));
}

// ---------------------------------------------------------------------------------------------
// Bad input: one error, naming the file and line.

TEST_F(AffFiles, RefusesATruncatedFile) {
  const std::string root = write("cut.aff",
                                 "m\n"
                                 " vertices 3\n"
                                 "  1 0 0\n"
                                 "  0 1 0\n"
                                 "  0 0 1\n"
                                 " triangles 2\n"
                                 "  0 1 2\n"
                                 "  0 2\n");
  expect_refused(root, "cut.aff", 8, "unexpected end of file");
  const std::string open =
      write("open.aff", "xs 1 1 1 1 0 0 0 0 0 0\n{\n" + std::string(kTriangle));
  expect_refused(open, "open.aff", 9, "line 1 is not closed");
}

TEST_F(AffFiles, RefusesAnUnknownKeyword) {
  const std::string root = write("kw.aff", std::string(kTriangle) + "\n# fine\nsphere 0 0 0 1\n");
  expect_refused(root, "kw.aff", 10, "unknown keyword 'sphere'");
}

TEST_F(AffFiles, RefusesAMissingInclude) {
  write("sub/a.aff", "\n\ni 0 nothere.aff\n");
  const std::string root = write("inc.aff", "i 0 sub/a.aff\n");
  expect_refused(root, "sub/a.aff", 3,
                 "include file not found: " + (dir_ / "sub/nothere.aff").string());
}

TEST_F(AffFiles, RefusesAMissingTexture) {
  const std::string root = write("tex.aff",
                                 "m\n"
                                 " vertices 3\n"
                                 "  1 0 0\n"
                                 "  0 1 0\n"
                                 "  0 0 1\n"
                                 " texturecoords 3 nosuch.ppm\n"
                                 "  0 0\n"
                                 "  1 0\n"
                                 "  0 1\n"
                                 " triangles 1\n"
                                 "  0 1 2 0 1 2\n");
  expect_refused(root, "tex.aff", 6, "texture file not found: nosuch.ppm");
}

TEST_F(AffFiles, RefusesANaN) {
  const std::string root = write("nan.aff",
                                 "xs 1 1 1\n"
                                 "   0 1 0 nan\n"
                                 "   0 0 0\n"
                                 "{\n}\n");
  expect_refused(root, "nan.aff", 2, "'nan' is not a finite number");
  const std::string inf = write("inf.aff", "m vertices 3 1 0 0 0 1 0 0 0 -inf triangles 1 0 1 2\n");
  expect_refused(inf, "inf.aff", 1, "'-inf' is not a finite number");
}

TEST_F(AffFiles, RefusesAnIncludeCycle) {
  write("a.aff", "i 0 b.aff\n");
  write("b.aff", "\ni 0 c.aff\n");
  write("c.aff", std::string(kTriangle) + "i 0 a.aff\n");
  const std::string root = write("top.aff", "i 0 a.aff\n");
  expect_refused(root, "c.aff", 8, "include cycle: a.aff -> b.aff -> c.aff -> a.aff");
}

TEST_F(AffFiles, RefusesTooFewKeys) {
  const std::string root =
      write("k.aff", "k x\n{\n  rot 2\n 0 0 1 0 0 0 0 0\n 1 0 1 0 5 0 0 0\n}\n");
  expect_refused(root, "k.aff", 3, "rot needs at least 4 keys");
}

// Found by fuzzing (docs/fuzzing.md): keyframes 10^7 s apart were sampled 60 times a second,
// 600 million samples (gigabytes) before anything was checked. The scene's channels may take
// 2^24 samples in all; more is refused in one line naming the file and the animated node.
TEST_F(AffFiles, RefusesKeyframesThatWouldTakeMillionsOfSamples) {
  const std::string root = write("days.aff",
                                 "x mover {\n"
                                 "p 3 0 0 0 1 0 0 0 1 0\n"
                                 "}\n"
                                 "k mover {\n"
                                 "transl 4\n"
                                 "0 0 0 0 0 0 0\n"
                                 "0 0 0 0 0 0 0\n"
                                 "1e7 1 0 0 0 0 0\n"
                                 "1e7 1 0 0 0 0 0\n"
                                 "}\n");
  try {
    load_scene(root);
    ADD_FAILURE() << "no error for " << root;
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(root + ": the keyframes of 'mover' span 10000000", 0), 0u) << msg;
    EXPECT_NE(msg.find("exceed the loader's limit of 16777216 samples"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

// BART's scenes stay far below that limit (the robots take 442,327 samples).
TEST(AffBart, AnimationSamplesStayFarBelowTheLoadersLimit) {
  for (const Scene* s : {&kitchen(), &robot()}) {
    std::size_t samples = 0;
    for (const AnimChannel& ch : s->animations)
      samples += ch.times.size();
    std::printf("%s: %zu channels, %zu samples\n", s->source.c_str(), s->animations.size(),
                samples);
    EXPECT_GT(samples, 0u);
    EXPECT_LT(samples, (std::size_t{1} << 24) / 30);
  }
}

}  // namespace
}  // namespace saarcor::host
