// Unit transaction vectors: captured from real frames, every one equals the reference datapath's
// answer (so the functional model's fast paths agree with the plain datapath on that traffic),
// the sample is seeded and spread over the frame, the reference answers hand-checked cases, and
// malformed vectors are one-line errors.
#include "units/unit_vectors.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "testbench/dynrtc_testing.h"

namespace saarcor::units {
namespace {

using testing::build;
using testing::kSanitized;

constexpr std::uint32_t kOne = 0x3F0000;      // 1.0 in fp24 (bias 63)
constexpr std::uint32_t kQuarter = 0x3D0000;  // 0.25
constexpr std::uint32_t kTwo = 0x400000;      // 2.0
constexpr std::uint32_t kMinusOne = 0xBF0000;

TEST(UnitVectors, CapturedVectorsAreTheDatapathsAnswers) {
  // The room (triangles in one object) and the dynamic scene (instances: object transformations).
  for (const char* scene : {"builtin:room", "builtin:dynamic"}) {
    const host::BuiltImage b = build(scene, 48, 36);
    for (int u = 0; u < kVectorUnits; ++u) {
      const auto unit = static_cast<VectorUnit>(u);
      const VectorCapture cap = capture_unit_vectors(b.image, {}, unit, 400, 1);
      const std::string what = std::string(scene) + " " + vector_unit_name(unit);
      ASSERT_EQ(cap.vectors.size(), 400u) << what;
      EXPECT_GT(cap.transactions, 400u) << what;
      int outside = 0;
      for (const UnitVector& v : cap.vectors) {
        ASSERT_EQ(v.in.size(), vector_inputs(unit).size()) << what;
        ASSERT_EQ(v.out.size(), vector_outputs(unit).size()) << what;
        EXPECT_EQ(expected_outputs(unit, v.in), v.out) << what << ", transaction " << v.index;
        if (unit == VectorUnit::kIntersection) outside += v.out[4] == 0 ? 1 : 0;
      }
      // Real traffic: most triangle tests of a ray miss the triangle, some hit it.
      if (unit == VectorUnit::kIntersection) {
        EXPECT_GT(outside, 0) << what;
        EXPECT_LT(outside, 400) << what;
      }
    }
  }
}

// Every scene of the covering design (testbench/dynrtc_testing.h): 2,000 vectors per unit, each
// recomputed on encodings, so the functional model's binary64 fast paths and the datapath the
// vectors document agree on every scene's traffic (4.5 s in all in the release build).
class UnitVectorsOnScenes : public ::testing::TestWithParam<int> {};

TEST_P(UnitVectorsOnScenes, EveryVectorIsTheDatapathsAnswer) {
  const auto cases = testing::scene_cases();
  const testing::SceneCase& sc = cases[static_cast<std::size_t>(GetParam())];
  if (kSanitized && sc.bank_mb > 4) GTEST_SKIP() << "large scene: release build only";
  const host::BuiltImage b =
      kSanitized ? build(sc.spec, 16, 12, sc.bank_mb) : build(sc.spec, 64, 48, sc.bank_mb);
  for (int u = 0; u < kVectorUnits; ++u) {
    const auto unit = static_cast<VectorUnit>(u);
    const VectorCapture cap = capture_unit_vectors(b.image, {}, unit, kSanitized ? 200 : 2000, 3);
    int bad = 0;
    for (const UnitVector& v : cap.vectors)
      if (expected_outputs(unit, v.in) != v.out && ++bad <= 3)
        ADD_FAILURE() << sc.spec << " " << vector_unit_name(unit) << ": transaction " << v.index;
    EXPECT_EQ(bad, 0) << sc.spec << " " << vector_unit_name(unit);
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, UnitVectorsOnScenes, ::testing::Range(0, 28));

// With shadow and secondary rays the transformation unit also generates shadow, reflection and
// transparency rays (the RGS's T, docs/shading.md): those steps are vectors too.
TEST(UnitVectors, ShadowAndSecondaryRaysToo) {
  const host::BuiltImage b = build("builtin:dynamic", 32, 24);
  FunctionalParams shaded;
  shaded.shadows = true;
  shaded.secondary = true;
  shaded.max_depth = 2;
  const VectorCapture primary =
      capture_unit_vectors(b.image, {}, VectorUnit::kTransformation, 1, 1);
  for (int u = 0; u < kVectorUnits; ++u) {
    const auto unit = static_cast<VectorUnit>(u);
    const VectorCapture cap = capture_unit_vectors(b.image, shaded, unit, 1000, 5);
    for (const UnitVector& v : cap.vectors)
      EXPECT_EQ(expected_outputs(unit, v.in), v.out) << vector_unit_name(unit) << " " << v.index;
    if (unit == VectorUnit::kTransformation) {
      EXPECT_GT(cap.transactions, primary.transactions);
    }
  }
}

TEST(UnitVectors, TheSampleIsSeededAndSpreadOverTheFrame) {
  const host::BuiltImage b = build("builtin:room", 32, 24);
  const FunctionalParams p;
  const VectorCapture a = capture_unit_vectors(b.image, p, VectorUnit::kTraversal, 300, 7);
  const VectorCapture again = capture_unit_vectors(b.image, p, VectorUnit::kTraversal, 300, 7);
  const VectorCapture other = capture_unit_vectors(b.image, p, VectorUnit::kTraversal, 300, 8);
  ASSERT_EQ(a.vectors.size(), 300u);
  EXPECT_EQ(a.transactions, other.transactions);
  bool same = true, differ = false;
  for (std::size_t i = 0; i < a.vectors.size(); ++i) {
    same &= a.vectors[i].index == again.vectors[i].index && a.vectors[i].in == again.vectors[i].in;
    differ |= a.vectors[i].index != other.vectors[i].index;
    if (i > 0) {
      EXPECT_LT(a.vectors[i - 1].index, a.vectors[i].index);  // frame order
    }
  }
  EXPECT_TRUE(same);
  EXPECT_TRUE(differ);
  // Uniform over the frame: the sample's first and last lie near the frame's ends.
  EXPECT_LT(a.vectors.front().index, a.transactions / 20);
  EXPECT_GT(a.vectors.back().index, a.transactions - a.transactions / 20);
  // A frame with fewer transactions than asked for gives all of them, numbered 0, 1, ...
  const host::BuiltImage tiny = build("builtin:triangle", 2, 2);
  const VectorCapture all = capture_unit_vectors(tiny.image, p, VectorUnit::kIntersection, 1000, 1);
  ASSERT_EQ(all.vectors.size(), all.transactions);
  for (std::size_t i = 0; i < all.vectors.size(); ++i)
    EXPECT_EQ(all.vectors[i].index, i);
}

TEST(UnitVectors, ReferenceAnswersByHand) {
  // A ray from (0.25, 0.25, 1) straight down hits the unit triangle at t = 1, (u, v) = (0.25,
  // 0.25), cosine -1.
  EXPECT_EQ(
      expected_outputs(VectorUnit::kIntersection, {kQuarter, kQuarter, kOne, 0, 0, kMinusOne}),
      (std::vector<std::uint32_t>{kOne, kQuarter, kQuarter, kMinusOne, 1}));
  // Pointing away: t = -1, outside.
  EXPECT_EQ(expected_outputs(VectorUnit::kIntersection, {kQuarter, kQuarter, kOne, 0, 0, kOne})[4],
            0u);
  // Split plane at 1, origin 0, direction 1, segment [0, 2]: both children, split at d = 1.
  EXPECT_EQ(expected_outputs(VectorUnit::kTraversal, {kOne, 0, kOne, 0, kTwo}),
            (std::vector<std::uint32_t>{1, 1, kOne, kOne}));
  // Segment [0, 0.25] ends before the plane: near child only, its interval unchanged (far_tn is
  // d = 1 all the same: the multiplexer selects on go_near, the far side is dropped).
  EXPECT_EQ(expected_outputs(VectorUnit::kTraversal, {kOne, 0, kOne, 0, kQuarter}),
            (std::vector<std::uint32_t>{1, 0, kQuarter, kOne}));
  // Identity plus translation (2, 0, 0): a point moves, a direction does not.
  std::vector<std::uint32_t> in = {kOne, 0, 0,    kTwo, 0,    kOne, 0,    0,
                                   0,    0, kOne, 0,    kOne, kOne, kOne, 1};
  EXPECT_EQ(expected_outputs(VectorUnit::kTransformation, in),
            (std::vector<std::uint32_t>{0x408000, kOne, kOne}));  // (3, 1, 1)
  in.back() = 0;
  EXPECT_EQ(expected_outputs(VectorUnit::kTransformation, in),
            (std::vector<std::uint32_t>{kOne, kOne, kOne}));
}

TEST(UnitVectors, MalformedVectorsAreErrors) {
  auto error = [](VectorUnit u, const std::vector<std::uint32_t>& in) {
    try {
      expected_outputs(u, in);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(error(VectorUnit::kIntersection, {1, 2, 3}),
            "unit vector: intersection takes 6 inputs, not 3");
  EXPECT_EQ(error(VectorUnit::kTraversal, {0x1000000, 0, 0, 0, 0}),
            "unit vector: 16777216 is not a 24-bit fp24 encoding");
  std::vector<std::uint32_t> in(16, 0);
  in.back() = 2;
  EXPECT_EQ(error(VectorUnit::kTransformation, in), "unit vector: a flag is 0 or 1, not 2");
  EXPECT_EQ(parse_vector_unit("transformation"), VectorUnit::kTransformation);
  EXPECT_THROW(parse_vector_unit("shading"), std::runtime_error);
  // The vectors are the fp24 hardware's: another image format is refused.
  host::ImageParams ip;
  ip.width = 4;
  ip.height = 4;
  ip.format = ff::Format{7, 20};
  const host::BuiltImage e7m20 = host::build_image(host::load_scene("builtin:cube"), ip);
  EXPECT_THROW(capture_unit_vectors(e7m20.image, {}, VectorUnit::kTraversal, 10, 1),
               std::runtime_error);
}

}  // namespace
}  // namespace saarcor::units
