// Deep (ctest label "deep"): the cycle model against the functional fp24 model on the full cross
// product of scenes and configurations of testbench/dynrtc_testing.h at 64x48, and the
// thread-scaling curve of the room at 256x192.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>

#include "testbench/dynrtc_testing.h"

namespace saarcor::units {
namespace {

class BitExactDeep : public ::testing::TestWithParam<int> {};

TEST_P(BitExactDeep, EveryConfigurationOnEveryScene) {
  const auto cases = testing::scene_cases();
  const testing::SceneCase& sc = cases[static_cast<std::size_t>(GetParam())];
  const host::BuiltImage b = testing::build(sc.spec, 64, 48, sc.bank_mb);
  for (const testing::Config& c : testing::configs())
    testing::expect_bit_exact(b, c, sc.spec + " [" + c.name + "]");
}

INSTANTIATE_TEST_SUITE_P(Scenes, BitExactDeep, ::testing::Range(0, 28));

TEST(DynRtcDeep, ThreadScalingOnTheRoom256) {
  const host::BuiltImage b = testing::build("builtin:room", 256, 192);
  std::map<int, std::uint64_t> cycles;
  for (int t : {1, 2, 4, 8, 16, 32, 64, 128}) {
    CycleParams p = prototype_params();
    p.threads = t;
    const CycleFrame c = run_cycle(b.image, p);
    cycles[t] = c.cycles;
    std::printf("threads %3d: %9llu cycles, %.1f per packet, speed-up %.2f\n", t,
                static_cast<unsigned long long>(c.cycles),
                static_cast<double>(c.cycles) / static_cast<double>(c.packets),
                static_cast<double>(cycles[1]) / static_cast<double>(c.cycles));
  }
  EXPECT_GE(static_cast<double>(cycles[1]) / static_cast<double>(cycles[32]), 8.0);
}

}  // namespace
}  // namespace saarcor::units
