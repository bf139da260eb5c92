// Random-configuration stress, full size (label deep; testbench/random_config_testing.h): 500
// seeded configurations of every cycle key (and kd.* keys, shadow and secondary rays, both host
// thread modes) over nine scenes (four built-ins, four glTF models, BART's kitchen) at 32x24,
// each bit-identical to the functional fp24 model with every ray returned exactly once. Ten ctest
// cases of 50 seeds each, so `ctest --preset deep` spreads them over the cores. A longer campaign
// over other seeds: SAARCOR_STRESS_SEEDS=FIRST-LAST splits those seeds over the ten cases instead.
// docs/fuzzing.md gives the figures of runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <utility>

#include "testbench/random_config_testing.h"

namespace saarcor {
namespace {

constexpr std::uint64_t kConfigs = 500;
constexpr int kChunks = 10;

// The seeds of the campaign: 1..500, or FIRST-LAST from SAARCOR_STRESS_SEEDS (decimal digits
// only, at most 12 each, so no sign or overflow slips through; 1 <= FIRST <= LAST).
std::pair<std::uint64_t, std::uint64_t> campaign_seeds() {
  const char* env = std::getenv("SAARCOR_STRESS_SEEDS");
  if (env == nullptr || *env == '\0') {
    return {1, kConfigs};
  }
  const std::string text(env);
  const auto number = [](const std::string& w, std::uint64_t& v) {
    if (w.empty() || w.size() > 12 || w.find_first_not_of("0123456789") != std::string::npos) {
      return false;
    }
    v = std::stoull(w);
    return true;
  };
  const std::size_t dash = text.find('-');
  std::uint64_t first = 0, last = 0;
  if (dash == std::string::npos || !number(text.substr(0, dash), first) ||
      !number(text.substr(dash + 1), last) || first < 1 || first > last) {
    throw std::runtime_error("SAARCOR_STRESS_SEEDS=" + text +
                             ": expected FIRST-LAST, 1 <= FIRST <= LAST");
  }
  return {first, last};
}

class RandomConfigDeep : public ::testing::TestWithParam<int> {};

TEST_P(RandomConfigDeep, FiftyConfigurationsEqualTheFunctionalModel) {
  const auto [from, to] = campaign_seeds();
  // Case k takes the k-th tenth of the seeds (the first cases one more when they do not divide).
  const std::uint64_t count = to - from + 1, k = static_cast<std::uint64_t>(GetParam());
  const std::uint64_t per = count / kChunks, extra = count % kChunks;
  const std::uint64_t first = from + k * per + std::min(k, extra);
  const std::uint64_t mine = per + (k < extra ? 1 : 0);
  if (mine == 0) {
    GTEST_SKIP() << "fewer seeds than cases";
  }
  stress::StressRunner runner(stress::deep_scenes());
  runner.run(first, first + mine - 1);
  const stress::StressTotals& t = runner.totals();
  EXPECT_EQ(t.configs, mine);
  std::printf("random configurations %llu..%llu: %llu run, %llu rays, %llu cycles, %.1f s\n",
              static_cast<unsigned long long>(first),
              static_cast<unsigned long long>(first + mine - 1),
              static_cast<unsigned long long>(t.configs), static_cast<unsigned long long>(t.rays),
              static_cast<unsigned long long>(t.cycles), t.seconds);
}

INSTANTIATE_TEST_SUITE_P(Seeds, RandomConfigDeep, ::testing::Range(0, kChunks));

}  // namespace
}  // namespace saarcor
