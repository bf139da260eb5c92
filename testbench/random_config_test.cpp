// Random-configuration stress, CI size (testbench/random_config_testing.h; the 500-configuration
// run is random_config_deep_test.cpp, label deep): ten seeded configurations of every cycle key on
// the small scenes, each bit-identical to the functional fp24 model with every ray returned once.
#include <gtest/gtest.h>

#include <cstdio>

#include "testbench/random_config_testing.h"

namespace saarcor {
namespace {

using stress::random_config;
using stress::small_scenes;

// The same seed gives the same configuration, and its replay command names every key drawn.
TEST(RandomConfig, SeedNamesOneReplayableConfiguration) {
  const stress::RandomConfig a = random_config(17, small_scenes());
  const stress::RandomConfig b = random_config(17, small_scenes());
  EXPECT_EQ(a.command(), b.command());
  EXPECT_EQ(a.scene.spec, small_scenes()[17 % small_scenes().size()].spec);
  for (const std::string& kv : a.set)
    EXPECT_NE(a.command().find(" --set " + kv), std::string::npos) << kv;
  EXPECT_EQ(a.command().rfind("saarcor render " + a.scene.spec + " --model cycle --res 32x24", 0),
            0u)
      << a.command();
  EXPECT_NE(random_config(18, small_scenes()).command(), a.command());
  // Every draw is a configuration the parser accepts.
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    CycleRenderOptions o;
    o.set = random_config(seed, small_scenes()).set;
    EXPECT_NO_THROW(resolve_cycle_params(o)) << random_config(seed, small_scenes()).command();
  }
}

TEST(RandomConfig, TenConfigurationsEqualTheFunctionalModel) {
  // The sanitizer build: five configurations at 16x12.
  const bool small = units::testing::kSanitized;
  stress::StressRunner runner(small_scenes(), small ? 2 : 1);
  runner.run(1, small ? 5 : 10);
  const stress::StressTotals& t = runner.totals();
  EXPECT_EQ(t.configs, small ? 5u : 10u);
  std::printf("random configurations: %llu, %llu rays, %llu cycles, %.1f s\n",
              static_cast<unsigned long long>(t.configs), static_cast<unsigned long long>(t.rays),
              static_cast<unsigned long long>(t.cycles), t.seconds);
}

}  // namespace
}  // namespace saarcor
