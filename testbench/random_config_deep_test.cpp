// Random-configuration stress, full size (label deep; testbench/random_config_testing.h): 500
// seeded configurations of every cycle key (and kd.* keys, shadow and secondary rays, both host
// thread modes) over nine scenes (four built-ins, four glTF models, BART's kitchen) at 32x24,
// each bit-identical to the functional fp24 model with every ray returned exactly once. Ten ctest
// cases of 50 seeds each, so `ctest --preset deep` spreads them over the cores. docs/fuzzing.md
// gives the figures of a run.
#include <gtest/gtest.h>

#include <cstdio>

#include "testbench/random_config_testing.h"

namespace saarcor {
namespace {

constexpr std::uint64_t kConfigs = 500;
constexpr int kChunks = 10;

class RandomConfigDeep : public ::testing::TestWithParam<int> {};

TEST_P(RandomConfigDeep, FiftyConfigurationsEqualTheFunctionalModel) {
  const auto per = kConfigs / kChunks;
  const std::uint64_t first = 1 + static_cast<std::uint64_t>(GetParam()) * per;
  stress::StressRunner runner(stress::deep_scenes());
  runner.run(first, first + per - 1);
  const stress::StressTotals& t = runner.totals();
  EXPECT_EQ(t.configs, per);
  std::printf("random configurations %llu..%llu: %llu run, %llu rays, %llu cycles, %.1f s\n",
              static_cast<unsigned long long>(first),
              static_cast<unsigned long long>(first + per - 1),
              static_cast<unsigned long long>(t.configs), static_cast<unsigned long long>(t.rays),
              static_cast<unsigned long long>(t.cycles), t.seconds);
}

INSTANTIATE_TEST_SUITE_P(Seeds, RandomConfigDeep, ::testing::Range(0, kChunks));

}  // namespace
}  // namespace saarcor
