// The sampled simulation's full validation (label deep; docs/sampling.md has its figures): every
// built-in scene and ten reference models under the covering design's eight configurations at
// 512x384 and 1024x768, the default --sample. It prints the table of `saarcor sample-check` and
// holds the cycles to the targets over the cases that give an interval: mean absolute error
// <= 1 %, largest <= 3 %, the full value inside the interval in >= 93 % of them. The host-time
// ratio is printed, not asserted (a timed assertion fails on a loaded machine).
#include <gtest/gtest.h>

#include "testbench/sample_check.h"
#include "testbench/testing.h"

namespace saarcor {
namespace {

TEST(SampleCheckDeep, EveryScenePairAndConfigurationAtBothResolutions) {
  std::vector<SampleCase> trusted, all;
  for (const std::string& scene : sample_check_scenes(std::string(SAARCOR_SHARED_SCENES), 10))
    for (const char* res : {"512x384", "1024x768"}) {
      const memif::MemoryImage image = sample_check_image(scene, res);
      for (const char* config :
           {"prototype", "t1-p1-tiny", "t4x3-p16-tiny-2way", "t16x2-p4-random-lat-1path",
            "t64-p16-tiny", "t4x4-p1-random-lat-shadows", "t64-p4-shadows-secondary",
            "t16-p16-random-lat-tiny"}) {
        SampleCase c = run_sample_case(image, config, SampleSpec{});
        c.scene = scene;
        c.res = res;
        all.push_back(c);
        if (c.trusted) trusted.push_back(std::move(c));
      }
    }
  std::printf("all cases:\n%s", sample_check_text(sample_check_summary(all)).c_str());
  const nlohmann::json s = sample_check_summary(trusted);
  std::printf("cases with an interval:\n%s", sample_check_text(s).c_str());
  const nlohmann::json& cycles = s["figures"][0];
  EXPECT_LE(cycles["mean_abs_error"].get<double>(), 1.0);
  EXPECT_LE(cycles["max_abs_error"].get<double>(), 3.0);
  EXPECT_GE(cycles["coverage_pct"].get<double>(), 93.0);
}

}  // namespace
}  // namespace saarcor
