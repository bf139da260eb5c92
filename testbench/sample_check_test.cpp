// `saarcor sample-check` reduced for CI (the full validation is sample_check_deep_test.cpp, label
// deep): two scenes under two configurations of the covering design at 256x192, sampled with
// periods of 512 packets (windows of 128 between up to 128 of warm-up and 64 of cool-down), each
// case's simulated packets bit for bit against the functional model.
#include "testbench/sample_check.h"

#include <gtest/gtest.h>

#include <cmath>

#include "testbench/testing.h"

namespace saarcor {
namespace {

TEST(SampleCheck, ReducedValidationAgainstFullRuns) {
  const SampleSpec spec = parse_sample_spec("window=128,period=512,warmup=128,cooldown=64");
  const std::size_t simulated = plan_sample(12288, spec).order.size();
  EXPECT_GT(simulated, 24u * 128u);
  EXPECT_LE(simulated, 24u * 320u);
#ifdef SAARCOR_SANITIZED
  // The ASan/UBSan build: one scene and one configuration (full frames are slow there).
  const std::vector<const char*> scenes = {"builtin:room"}, configs = {"prototype"};
#else
  const std::vector<const char*> scenes = {"builtin:room", "builtin:glass"};
  const std::vector<const char*> configs = {"prototype", "t64-p4-shadows-secondary"};
#endif
  std::vector<SampleCase> cases;
  for (const char* scene : scenes) {
    const memif::MemoryImage image = sample_check_image(scene, "256x192");
    for (const char* config : configs) {
      SampleCase c = run_sample_case(image, config, spec);  // throws if a packet differs
      c.scene = scene;
      c.res = "256x192";
      // 12,288 packets: 24 periods of 512.
      EXPECT_EQ(c.packets, 12288u);
      EXPECT_EQ(c.packets_simulated, simulated);
      EXPECT_EQ(c.windows, 24);
      EXPECT_TRUE(c.trusted) << c.defeated;
      cases.push_back(std::move(c));
    }
  }
  const nlohmann::json s = sample_check_summary(cases);
  std::printf("%s", sample_check_text(s).c_str());
  const nlohmann::json& cycles = s["figures"][0];
  ASSERT_EQ(cycles["figure"], "cycles");
  EXPECT_LE(cycles["max_abs_error"].get<double>(), 3.0);
  EXPECT_EQ(cycles["coverage_pct"].get<double>(), 100.0);
  EXPECT_EQ(s["cases"].get<std::size_t>(), scenes.size() * configs.size());
  EXPECT_EQ(s["cases_defeated"].get<int>(), 0);
  // Every figure is tabulated, with its error unit.
  EXPECT_EQ(s["figures"].size(), sample_check_figures().size());
  EXPECT_EQ(s["figures"][2]["figure"], "usage.traversal");
  EXPECT_EQ(s["figures"][2]["error"], "points");
}

TEST(SampleCheck, BadInputIsOneLine) {
  test_support::expect_one_line_error(
      test_support::run_saarcor("sample-check --scene builtin:cube --res 64x48 --config nope"),
      "bad --config 'nope': one of prototype, t1-p1-tiny");
  test_support::expect_one_line_error(
      test_support::run_saarcor("sample-check --scene builtin:cube --res 64x48 --sample x=1"),
      "bad --sample 'x=1'");
  test_support::expect_one_line_error(
      test_support::run_saarcor("sample-check --models 10 --references /nonexistent --res 64x48"),
      "0 of the 10 reference models under '/nonexistent'");
}

}  // namespace
}  // namespace saarcor
