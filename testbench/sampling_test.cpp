// The sampled simulation (testbench/sampling.h): the SPEC syntax, the plan, the estimators by
// hand, a sampled frame against the full one (its simulated packets bit for bit), a frame that
// defeats the sampling, and the command line.
#include "testbench/sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "testbench/report.h"
#include "testbench/sample_check.h"
#include "testbench/testing.h"

namespace saarcor {
namespace {

using test_support::error_of;

TEST(Sampling, SpecSyntaxAndDefault) {
  const SampleSpec d = parse_sample_spec("");
  EXPECT_EQ(sample_spec_text(d), "window=256,period=4608,warmup=128");
  const SampleSpec s = parse_sample_spec("window=64,period=640,warmup=32");
  EXPECT_EQ(s.window, 64);
  EXPECT_EQ(s.period, 640);
  EXPECT_EQ(s.warmup, 32);
  // Any subset, the rest at the default.
  EXPECT_EQ(sample_spec_text(parse_sample_spec("period=9000")),
            "window=256,period=9000,warmup=128");
  EXPECT_EQ(parse_sample_spec("warmup=0").warmup, 0);
}

TEST(Sampling, BadSpecIsOneLineNamingIt) {
  for (const char* bad :
       {"window", "window=", "window=x", "window=-1", "size=3", "window=0", "window=64,window=64",
        "window=64,period=100,warmup=40", "window=1.5", "window=64,"}) {
    const std::string e = error_of([&] { parse_sample_spec(bad); });
    EXPECT_EQ(e.rfind(std::string("bad --sample '") + bad + "': ", 0), 0u) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(Sampling, PlanHoldsOneWarmupAndWindowPerPeriod) {
  // 10,500 packets, periods of 1,000: ten periods, the last holding the 500 left over too, each
  // with 5 warm-up and 10 window packets in a row inside the period.
  const SamplePlan p = plan_sample(10500, parse_sample_spec("window=10,period=1000,warmup=5"));
  EXPECT_EQ(p.windows, 10);
  ASSERT_EQ(p.order.size(), 150u);
  ASSERT_EQ(p.marks.size(), 20u);
  for (int i = 0; i < 10; ++i) {
    const auto w = static_cast<std::size_t>(i);
    EXPECT_EQ(p.marks[2 * w], 15 * i + 5);
    EXPECT_EQ(p.marks[2 * w + 1], 15 * i + 15);
    const int first = p.order[15 * w];
    const int size = i < 9 ? 1000 : 1500;
    EXPECT_EQ(p.strata[w], size);
    EXPECT_GE(first, 1000 * i);
    EXPECT_LE(first + 15, 1000 * i + size);
    for (std::size_t k = 1; k < 15; ++k)
      EXPECT_EQ(p.order[15 * w + k], first + static_cast<int>(k));
    EXPECT_EQ(p.window_first[w], first + 5);  // where the window's covariate is read
  }
  // The places differ between periods (no column aliasing) and repeat between runs.
  std::set<int> offsets;
  for (int i = 0; i < 10; ++i)
    offsets.insert(p.order[15 * static_cast<std::size_t>(i)] - 1000 * i);
  EXPECT_GT(offsets.size(), 5u);
  EXPECT_EQ(plan_sample(10500, parse_sample_spec("window=10,period=1000,warmup=5")).order, p.order);
  EXPECT_EQ(plan_sample(999, parse_sample_spec("window=10,period=1000,warmup=5")).windows, 0);
}

TEST(Sampling, StudentT) {
  EXPECT_DOUBLE_EQ(student_t975(1), 12.7062);
  EXPECT_DOUBLE_EQ(student_t975(2), 4.3027);
  EXPECT_DOUBLE_EQ(student_t975(9), 2.2622);
  EXPECT_NEAR(student_t975(13), 2.1604, 2e-4);
  EXPECT_NEAR(student_t975(30), 2.0423, 2e-4);
  EXPECT_NEAR(student_t975(100), 1.9840, 2e-4);
}

TEST(Sampling, CyclesEstimateByHand) {
  // Windows of 10, 12 and 14 cycles per packet, 100 packets: mean 12 -> 1,200 cycles; sample
  // standard deviation 2, standard error 2 / sqrt(3) = 1.1547, t(2) = 4.3027: half-width
  // 4.3027 * 1.1547 * 100 = 496.83.
  const std::vector<double> thirds(3, 100.0 / 3);
  const FigureEstimate e = estimate_cycles({10, 12, 14}, thirds, 0.0);
  EXPECT_DOUBLE_EQ(e.value, 1200.0);
  EXPECT_NEAR(e.ci.low, 1200.0 - 496.83, 0.01);
  EXPECT_NEAR(e.ci.high, 1200.0 + 496.83, 0.01);
  // Half the frame sampled: the finite-population correction sqrt(1 - 0.5) narrows it.
  const FigureEstimate h = estimate_cycles({10, 12, 14}, thirds, 0.5);
  EXPECT_NEAR(h.ci.high - 1200.0, 496.83 * std::sqrt(0.5), 0.01);
  // A window standing for more packets weighs more: 10 x 20 + 12 x 30 + 14 x 50 = 1,260.
  EXPECT_DOUBLE_EQ(estimate_cycles({10, 12, 14}, {20, 30, 50}, 0.0).value, 1260.0);
}

TEST(Sampling, RegressionEstimateOnSyntheticData) {
  // A frame whose packets cost exactly 2 + 3x cycles for a covariate x: four periods of 100
  // packets with covariate means 2, 2, 3 and 5 (true total 100 x (8 + 8 + 11 + 17) = 4,400).
  // The windows fell on packets of covariate means 1, 2, 3 and 4 and measured 5, 8, 11 and 14
  // cycles per packet: the plain estimate is 100 x (5 + 8 + 11 + 14) = 3,800 (13.6 % low), the
  // regression estimate (slope 3, no residual) 3,800 + 3 x 100 x ((2+2+3+5) - (1+2+3+4)) = 4,400
  // exactly, with an interval of width 0.
  const std::vector<double> strata(4, 100.0);
  const std::vector<double> y = {5, 8, 11, 14}, x = {1, 2, 3, 4}, px = {2, 2, 3, 5};
  EXPECT_DOUBLE_EQ(estimate_cycles(y, strata, 0.0).value, 3800.0);
  const FigureEstimate exact = estimate_cycles(y, strata, 0.0, x, px);
  EXPECT_NEAR(exact.value, 4400.0, 1e-9);
  EXPECT_NEAR(exact.ci.low, 4400.0, 1e-9);
  EXPECT_NEAR(exact.ci.high, 4400.0, 1e-9);
  // With noise: y = 4, 6, 9, 11. Mean x 2.5, mean y 7.5, Sxx = 5, Sxy = 1.5 x 3.5 + 0.5 x 1.5 +
  // 0.5 x 1.5 + 1.5 x 3.5 = 12, slope b = 2.4. Estimate 100 x (4+6+9+11) + 2.4 x 100 x (12 - 10)
  // = 3,480. Fitted line 1.5 + 2.4x: 3.9, 6.3, 8.7, 11.1; residuals 0.1, -0.3, 0.3, -0.1, sum of
  // squares 0.2, over n - 2 = 2 degrees of freedom 0.1; standard error of the mean
  // sqrt(0.1 / 4) = 0.158114, times 400 packets = 63.2456, times t(2) = 4.3027: 272.13.
  const FigureEstimate noisy = estimate_cycles({4, 6, 9, 11}, strata, 0.0, x, px);
  EXPECT_NEAR(noisy.value, 3480.0, 1e-9);
  EXPECT_NEAR(noisy.ci.high - noisy.value, 272.13, 0.01);
  EXPECT_NEAR(noisy.value - noisy.ci.low, 272.13, 0.01);
  // A covariate without spread over the windows: slope 0, each window carried to its period as
  // the plain estimator does (the interval then on n - 2 degrees of freedom).
  EXPECT_DOUBLE_EQ(estimate_cycles(y, strata, 0.0, {1, 1, 1, 1}, px).value, 3800.0);
  EXPECT_NEAR(correlation(x, y), 1.0, 1e-12);
  EXPECT_EQ(correlation(x, {2, 2, 2, 2}), 0.0);
}

TEST(Sampling, RatioFigureEstimateByHand) {
  // Three windows of 100 cycles whose traversal unit issued 50, 60 and 70 cycles: pooled usage
  // 180 / 300 = 60 %; left out in turn 65, 60, 55 %, mean 60; jackknife variance
  // (3 - 1) / 3 * (25 + 0 + 25) = 33.33, sd 5.7735, times t(2) = 4.3027: 24.84 points.
  std::vector<units::FigureCounts> spans(3);
  for (std::size_t i = 0; i < 3; ++i) {
    spans[i].cycle = 100;
    spans[i].issued[0] = 50 + 10 * i;
  }
  const FigureEstimate e =
      estimate_figure(spans, units::figure_index("usage.traversal"), 90.0, 0.0);
  EXPECT_DOUBLE_EQ(e.value, 60.0);
  EXPECT_NEAR(e.ci.low, 60.0 - 24.842, 0.001);
  EXPECT_NEAR(e.ci.high, 60.0 + 24.842, 0.001);
}

memif::MemoryImage room(const std::string& res) {
  return sample_check_image("builtin:room", res);
}

TEST(Sampling, SampledFrameAgainstTheFullOne) {
  // The room at 256x192 (12,288 packets), periods of 256: 48 windows of 32 packets after 64 of
  // warm-up, 4,608 packets simulated, each checked bit for bit against the functional model.
  const memif::MemoryImage image = room("256x192");
  const units::CycleParams p = units::prototype_params();
  const CycleFrame full = run_cycle(image, p);
  const CycleFrame s =
      run_sampled(image, p, {}, parse_sample_spec("window=32,period=256,warmup=64"));
  ASSERT_TRUE(s.sampling);
  EXPECT_EQ(s.sampling->windows, 48);
  EXPECT_EQ(s.sampling->packets_simulated, 4608u);
  EXPECT_EQ(s.packets, 12288u);
  EXPECT_EQ(s.packets_retired, 4608u);
  EXPECT_TRUE(s.sampling->defeated.empty()) << s.sampling->defeated;
  EXPECT_NO_THROW(check_sampled_packets(image, p, {}, s));
  const double err = (static_cast<double>(s.cycles) - static_cast<double>(full.cycles)) /
                     static_cast<double>(full.cycles);
  EXPECT_LT(std::abs(err), 0.03) << s.cycles << " vs " << full.cycles;
  EXPECT_LE(s.sampling->cycles.low, static_cast<double>(full.cycles));
  EXPECT_GE(s.sampling->cycles.high, static_cast<double>(full.cycles));
  // The report: each figure at its usual key, its interval beside it.
  const nlohmann::json j = cycle_report_json(s);
  EXPECT_EQ(j["cycles"].get<std::uint64_t>(), s.cycles);
  EXPECT_EQ(json_at(j, "sampling.ci95.cycles").size(), 2u);
  EXPECT_EQ(json_at(j, "sampling.ci95.usage.traversal").size(), 2u);
  EXPECT_EQ(json_at(j, "sampling.ci95.bandwidth_mb_s.total").size(), 2u);
  EXPECT_EQ(json_at(j, "sampling.windows").get<int>(), 48);
  EXPECT_EQ(json_at(j, "sampling.packets_simulated").get<int>(), 4608);
  EXPECT_NE(sampling_text(s).find("sampled: window=32,period=256,warmup=64, 48 windows"),
            std::string::npos);
}

TEST(Sampling, FrameWithItsCostInFewPacketsSaysSo) {
  // The cube at 256x192 covers a few hundred of the 12,288 packets: windows of 8 packets either
  // miss it (a packet's rays leave at the root) or hold it. The windows' cycles per packet vary
  // with a coefficient of variation above 1, and the report gives no interval.
  const memif::MemoryImage image = sample_check_image("builtin:cube", "256x192");
  const CycleFrame s = run_sampled(image, units::prototype_params(), {},
                                   parse_sample_spec("window=8,period=128,warmup=8"));
  ASSERT_TRUE(s.sampling);
  EXPECT_EQ(s.sampling->windows, 96);
  EXPECT_GT(s.sampling->cycles_per_packet_cov, kMaxSampleCov);
  EXPECT_NE(s.sampling->defeated.find("concentrated in few packets"), std::string::npos);
  const nlohmann::json j = cycle_report_json(s);
  EXPECT_FALSE(j["sampling"]["trusted"].get<bool>());
  EXPECT_FALSE(j["sampling"].contains("ci95"));
  EXPECT_NE(sampling_text(s).find("no confidence interval: the cost is concentrated"),
            std::string::npos);
  // Too few windows: the default spec on the same frame has 2.
  const CycleFrame few = run_sampled(image, units::prototype_params(), {}, SampleSpec{});
  ASSERT_TRUE(few.sampling);
  EXPECT_EQ(few.sampling->defeated, "only 2 windows (an interval needs at least 10)");
}

TEST(SamplingBinary, SampleOptionAndBadSpec) {
  const test_support::CliRun ok = test_support::run_saarcor(
      "render builtin:room --model cycle --res 128x96 --sample window=16,period=128,warmup=32 "
      "--out " +
      (test_support::scratch_dir("sample") / "room").string());
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_NE(ok.out.find("sampled: window=16,period=128,warmup=32, 24 windows, 1152 of 3072"),
            std::string::npos)
      << ok.out;
  EXPECT_NE(ok.out.find("95 % intervals: cycles"), std::string::npos) << ok.out;
  test_support::expect_one_line_error(
      test_support::run_saarcor("render builtin:room --model cycle --res 64x48 --sample window=0"),
      "bad --sample 'window=0': window must be >= 1");
  test_support::expect_one_line_error(
      test_support::run_saarcor("sweep builtin:room --vary threads=8 --sample size=3"),
      "bad --sample 'size=3': unknown key 'size'");
  test_support::expect_one_line_error(
      test_support::run_saarcor("paper --scale 8 --sample window=9,period=10,warmup=2"),
      "exceeds the period");
}

}  // namespace
}  // namespace saarcor
