// The independent bit-exact check of the functional model's fast paths: the reference
// instantiation of the thread program (units/reference_model.h: ReferenceDatapath, every datapath
// step on encodings in the paper's op order, built in a target that cannot see units/fast_paths.h)
// against the fast one (run_functional: FastDatapath, whose traversal, clip, transformation and
// RGS dot and cosine steps run on binary64 values where those decide). The two are computed
// independently (encodings through fixedfloat's round-and-pack; binary64 values rounded once),
// so a fast path that rounds differently on any step of any of these scenes fails here: step by
// step (every traversal lane, transformation and intersection a tap sees, in order) and frame by
// frame (hit records, image, counters, op counts). Scenes with shadow, reflection and
// transparency rays included.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "testbench/render_cmd.h"
#include "units/functional_model.h"
#include "units/reference_model.h"

namespace saarcor {
namespace {

using F = ff::fp24;

// Every transaction as the words a tap sees, in order (one vector of words per transaction).
class RecordingTap final : public units::UnitTap<F> {
 public:
  std::vector<std::vector<std::uint32_t>> steps;
  void traversal(int /*lane*/, F split, F o_axis, F d_axis, F tn, F tf, bool go_near, bool go_far,
                 F near_tf, F far_tn) override {
    steps.push_back({0u, split.bits, o_axis.bits, d_axis.bits, tn.bits, tf.bits,
                     std::uint32_t{go_near}, std::uint32_t{go_far}, near_tf.bits, far_tn.bits});
  }
  void transformation(int /*lane*/, const units::Mat34<F>& m, const units::Vec3<F>& in,
                      bool translate, const units::Vec3<F>& out) override {
    std::vector<std::uint32_t> w = {1u, std::uint32_t{translate}};
    for (const auto& row : m)
      for (const F x : row)
        w.push_back(x.bits);
    for (int k = 0; k < 3; ++k) {
      w.push_back(in[k].bits);
      w.push_back(out[k].bits);
    }
    steps.push_back(std::move(w));
  }
  void intersection(int /*lane*/, const units::Ray<F>& r, const units::Candidate<F>& c) override {
    std::vector<std::uint32_t> w = {2u};
    for (int k = 0; k < 3; ++k) {
      w.push_back(r.o[k].bits);
      w.push_back(r.d[k].bits);
    }
    w.insert(w.end(), {c.t.bits, c.u.bits, c.v.bits, c.c.bits, std::uint32_t{c.inside}});
    steps.push_back(std::move(w));
  }
};

void expect_same_ops(const ff::OpCounts& a, const ff::OpCounts& b, const std::string& what) {
  EXPECT_EQ(a.add, b.add) << what;
  EXPECT_EQ(a.mul, b.mul) << what;
  EXPECT_EQ(a.div, b.div) << what;
  EXPECT_EQ(a.sqrt, b.sqrt) << what;
  EXPECT_EQ(a.cmp, b.cmp) << what;
}

struct Case {
  const char* spec;  // builtin:NAME, or a path under the shared scenes
  bool shadows;
  int depth;
};

class ReferenceDatapath : public ::testing::TestWithParam<Case> {};

TEST_P(ReferenceDatapath, FastPathsEqualTheReferenceStepByStep) {
  const Case& c = GetParam();
  const std::string spec = std::string(c.spec).rfind("builtin:", 0) == 0
                               ? std::string(c.spec)
                               : std::string(SAARCOR_SHARED_SCENES) + "/" + c.spec;
#ifdef SAARCOR_SANITIZED
  const std::string res = "24x18";  // the reference path is slow under the sanitizers
#else
  const std::string res = "64x48";
#endif
  const RenderSettings s = frame_settings(res, 0.0, c.shadows, c.depth, 32.0);
  const PreparedScene prep = prepare_scene(spec, s);
  const units::FunctionalParams params = functional_params(s);
  RecordingTap fast_tap, ref_tap;
  const units::FunctionalFrame a =
      units::run_functional<F>(prep.built.image, params, {}, &fast_tap);
  const units::FunctionalFrame b = units::run_reference(prep.built.image, params, &ref_tap);
  // Step by step: the first differing transaction names itself.
  ASSERT_EQ(fast_tap.steps.size(), ref_tap.steps.size()) << spec;
  EXPECT_GT(fast_tap.steps.size(), 1000u) << spec;
  for (std::size_t i = 0; i < fast_tap.steps.size(); ++i)
    ASSERT_EQ(fast_tap.steps[i], ref_tap.steps[i])
        << spec << ": transaction " << i << " (kind " << ref_tap.steps[i][0] << ")";
  // Frame by frame.
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    const auto& p = a.pixels[i];
    const auto& q = b.pixels[i];
    ASSERT_TRUE(p.t == q.t && p.u == q.u && p.v == q.v && p.cos == q.cos &&
                p.instance == q.instance && p.triangle == q.triangle && p.o == q.o && p.d == q.d &&
                p.counters == q.counters)
        << spec << ": pixel " << i;
  }
  EXPECT_EQ(a.rgb, b.rgb) << spec;
  EXPECT_EQ(a.by_kind, b.by_kind) << spec;
  EXPECT_EQ(a.rays_issued, b.rays_issued) << spec;
  expect_same_ops(a.units.traversal_ops, b.units.traversal_ops, spec + " traversal ops");
  expect_same_ops(a.units.transformation_ops, b.units.transformation_ops, spec + " xfrm ops");
  expect_same_ops(a.units.intersection_ops, b.units.intersection_ops, spec + " int ops");
  expect_same_ops(a.units.rgs_ops, b.units.rgs_ops, spec + " rgs ops");
  EXPECT_EQ(a.units.traversal_steps, b.units.traversal_steps) << spec;
  EXPECT_EQ(a.units.clip_steps, b.units.clip_steps) << spec;
  if (c.shadows) {
    EXPECT_GT(a.rays_issued[1], 0u) << spec << ": no shadow rays";
  }
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, ReferenceDatapath,
    ::testing::Values(Case{"builtin:room", true, 2}, Case{"builtin:dynamic", true, 2},
                      Case{"builtin:cube", false, 3}, Case{"Duck/Duck.gltf", true, 1},
                      Case{"DamagedHelmet/DamagedHelmet.gltf", false, 2},
                      Case{"2CylinderEngine/2CylinderEngine.gltf", true, 0},
                      Case{"SpheresScaledInstances/spheres_scaled_instances.gltf", true, 2},
                      Case{"builtin:suncor", false, 0}),
    [](const auto& info) {
      std::string n = info.param.spec;
      n = n.substr(0, n.find('/'));
      for (char& ch : n)
        if (ch == ':' || ch == '.') ch = '_';
      return n;
    });

}  // namespace
}  // namespace saarcor
