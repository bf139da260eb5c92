// The RTL traversal unit (rtl/traversal_ctrl.sv) against the model's traversal semantics
// (units/traversal_step.h) on real frames, request by request (rtl/traversal_ctrl_testing.h):
// every node step, clip chain and pop, the next request it names, the lanes' segments, and the
// cycle the thread leaves as issue + (faces - 1) + depth (+ one per dropped stack entry). The
// test-only faults of the traversal unit are caught in lockstep with the cycle model
// (rtl/lockstep_test.cpp).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "Vtraversal_ctrl.h"
#include "rtl/builds_testing.h"
#if SAARCOR_RTL_VARIANT_BUILDS
#include "Vtraversal_ctrl_p1.h"
#include "Vtraversal_ctrl_p16.h"
#endif
#include "host/image_builder.h"
#include "host/scene.h"
#include "rtl/traversal_ctrl_testing.h"
#include "units/cycle_params.h"

namespace saarcor::rtl::testing {
namespace {

// `packets` primary packets (square tiles of P pixels) spread evenly over the frame, one after
// another on threads 0, 1, 2, ... (mod 64), through the RTL and the model.
// D: the model's datapath policy the harness's neighbours and reference steps run on.
template <class V, int kL = kLanes, class D = units::FastDatapath>
TravRun run_scene(const std::string& spec, int packets, int depth, int p = kLanes,
                  bool shadows = false) {
  const host::BuiltImage built = host::build_image(host::load_scene(spec));
  const memif::MemoryImage& image = built.image;
  units::FunctionalParams fp;
  fp.packet = p;
  fp.shadows = shadows;
  units::PipelineUnits<F> pu(fp.mode);
  units::FrameSink sink;
  const auto w = static_cast<int>(image.registers().width);
  const auto h = static_cast<int>(image.registers().height);
  sink.reset(w, h);
  TravHarness<V, kL, D> rtl(image, {depth});
  const int side = p == 16 ? 4 : p == 4 ? 2 : 1;  // square tiles of P pixels
  const int tiles = (w / side) * (h / side);
  for (int k = 0; k < packets; ++k) {
    const int tile = static_cast<int>(static_cast<long>(k) * tiles / packets);
    const auto x = static_cast<std::uint32_t>((tile % (w / side)) * side);
    const auto y = static_cast<std::uint32_t>((tile / (w / side)) * side);
    const auto uw = static_cast<std::uint32_t>(w);
    std::vector<std::uint32_t> px;
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i)
        px.push_back((y + static_cast<std::uint32_t>(j)) * uw + x + static_cast<std::uint32_t>(i));
    auto s = std::make_unique<typename TravHarness<V, kL, D>::S>(image, fp, pu, sink);
    s->rgs.start_primary(*s, px);
    s->transformation.generate(*s);
    if (!rtl.packet(*s, static_cast<std::uint32_t>(k % 64), shadows)) break;
  }
  return rtl.run();
}

std::string describe(const TravRun& r) {
  return "packets " + std::to_string(r.packets) + ", requests " + std::to_string(r.requests) +
         " (node steps " + std::to_string(r.node_steps) + ", clips " + std::to_string(r.clips) +
         ", pops " + std::to_string(r.pops) + ", leaves " + std::to_string(r.leaves) + ", drops " +
         std::to_string(r.drops) + "), " + std::to_string(r.cycles) + " cycles" +
         (r.first.found
              ? "; first divergence at request " + std::to_string(r.first.request) + " (cycle " +
                    std::to_string(r.first.cycle) + ", " + r.first.kind + "): " + r.first.what
              : "");
}

int depth() {
  return units::prototype_params().traversal_depth();
}

TEST(RtlTraversal, RoomMatchesTheModelRequestByRequest) {
  const TravRun r = run_scene<Vtraversal_ctrl>("builtin:room", 300, depth());
  EXPECT_FALSE(r.first.found) << describe(r);
  EXPECT_EQ(r.packets, 300u) << describe(r);
  EXPECT_GT(r.node_steps, 5000u) << describe(r);
  EXPECT_GT(r.leaves, 500u) << describe(r);
  EXPECT_GT(r.drops, 0u) << describe(r);  // pops behind a hit, one cycle per dropped entry
  std::printf("RtlTraversal room: %s\n", describe(r).c_str());
}

// The model's reference datapath (every step on encodings) gives the same requests.
TEST(RtlTraversal, RoomOnTheReferenceDatapath) {
  const TravRun r =
      run_scene<Vtraversal_ctrl, kLanes, units::ReferenceDatapath>("builtin:room", 60, depth());
  EXPECT_FALSE(r.first.found) << describe(r);
  EXPECT_EQ(r.packets, 60u) << describe(r);
}

// Two levels with many instances: object boxes, bottom-level trees, the top level resumed.
TEST(RtlTraversal, DynamicSceneTwoLevels) {
  const TravRun r = run_scene<Vtraversal_ctrl>("builtin:dynamic", 200, depth());
  EXPECT_FALSE(r.first.found) << describe(r);
  EXPECT_EQ(r.packets, 200u) << describe(r);
  EXPECT_GT(r.clips, 200u) << describe(r);  // bottom-level clips beside the 200 top-level ones
  std::printf("RtlTraversal dynamic: %s\n", describe(r).c_str());
}

// Other packet widths: the Verilated builds with P = 16 and P = 1.
#if SAARCOR_RTL_VARIANT_BUILDS
TEST(RtlTraversal, RoomWithSixteenRayPackets) {
  const TravRun r = run_scene<Vtraversal_ctrl_p16, 16>("builtin:room", 80, depth(), 16);
  EXPECT_FALSE(r.first.found) << describe(r);
  EXPECT_EQ(r.packets, 80u) << describe(r);
  std::printf("RtlTraversal room P=16: %s\n", describe(r).c_str());
}

TEST(RtlTraversal, DynamicSceneWithSingleRayPackets) {
  const TravRun r = run_scene<Vtraversal_ctrl_p1, 2>("builtin:dynamic", 200, depth(), 1);
  EXPECT_FALSE(r.first.found) << describe(r);
  EXPECT_EQ(r.packets, 200u) << describe(r);
  std::printf("RtlTraversal dynamic P=1: %s\n", describe(r).c_str());
}
#endif

// Shadow packets (docs/shading.md 6.4): the RGS hands them to the traversal unit directly, their
// rays finish at any hit (done), and entries whose rays are all done are dropped at a pop.
TEST(RtlTraversal, DynamicSceneWithShadowRays) {
  const TravRun r = run_scene<Vtraversal_ctrl>("builtin:dynamic", 60, depth(), kLanes, true);
  EXPECT_FALSE(r.first.found) << describe(r);
  EXPECT_GT(r.packets, 60u) << describe(r);  // the shadow packets count too
  std::printf("RtlTraversal dynamic with shadows: %s\n", describe(r).c_str());
}

class RtlTraversalOnModels : public ::testing::TestWithParam<const char*> {};

TEST_P(RtlTraversalOnModels, MatchesTheModel) {
  const std::string scene = std::string(SAARCOR_SHARED_SCENES) + "/" + GetParam();
  if (!std::filesystem::exists(scene)) GTEST_SKIP() << scene << " not present";
  const TravRun r = run_scene<Vtraversal_ctrl>(scene, 150, depth());
  EXPECT_FALSE(r.first.found) << GetParam() << ": " << describe(r);
  EXPECT_EQ(r.packets, 150u) << describe(r);
}

INSTANTIATE_TEST_SUITE_P(Scenes, RtlTraversalOnModels,
                         ::testing::Values("Duck/Duck.gltf",
                                           "SpheresScaledInstances/spheres_scaled_instances.gltf"),
                         [](const ::testing::TestParamInfo<const char*>& i) {
                           std::string n = i.param;
                           return n.substr(0, n.find('/'));
                         });

}  // namespace
}  // namespace saarcor::rtl::testing
