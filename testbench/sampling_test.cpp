// The sampled simulation (testbench/sampling.h): the SPEC syntax, the plan, the estimators by
// hand, a sampled frame against the full one (its simulated packets bit for bit), a frame that
// defeats the sampling, and the command line.
#include "testbench/sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <set>

#include "host/image_builder.h"
#include "host/scene.h"
#include "testbench/report.h"
#include "testbench/sample_check.h"
#include "testbench/testing.h"

namespace saarcor {
namespace {

using test_support::error_of;

TEST(Sampling, SpecSyntaxAndDefault) {
  const SampleSpec d = parse_sample_spec("");
  EXPECT_EQ(sample_spec_text(d), "window=auto,period=auto,warmup=auto,cooldown=auto");
  const SampleSpec s = parse_sample_spec("window=64,period=640,warmup=32,cooldown=16");
  EXPECT_EQ(s.window, 64);
  EXPECT_EQ(s.period, 640);
  EXPECT_EQ(s.warmup, 32);
  EXPECT_EQ(s.cooldown, 16);
  // Any subset, the rest chosen for the machine and the frame.
  EXPECT_EQ(sample_spec_text(parse_sample_spec("period=9000")),
            "window=auto,period=9000,warmup=auto,cooldown=auto");
  EXPECT_EQ(parse_sample_spec("warmup=0").warmup, 0);
}

TEST(Sampling, DefaultChosenForTheMachineAndTheFrame) {
  // The prototype, 64 threads of 4-ray packets (2x2 tiles), at 1024x768: 196,608 packets, 512 a
  // row of tiles. Warm-up 128, cool-down 64, window a row, 512; 704 packets at 8 % is a period of
  // 8,800 (22 windows).
  units::CycleParams p = units::prototype_params();
  EXPECT_EQ(sample_spec_text(resolve_sample_spec({}, p, units::packet_tiling(1024, 768, 4))),
            "window=512,period=8800,warmup=128,cooldown=64");
  // At 512x384 (49,152 packets, 256 a row) 448 packets at 8 % would be 8 windows: the period
  // shrinks to give 20.
  EXPECT_EQ(sample_spec_text(resolve_sample_spec({}, p, units::packet_tiling(512, 384, 4))),
            "window=256,period=2457,warmup=128,cooldown=64");
  // 12 threads (4 x 3 DynRTPs) of 16-ray packets at 1024x768 (49,152 packets, 256 a row):
  // warm-up 64 and, with several DynRTPs, the row above, 320; cool-down 32, window 256;
  // 608 / 0.08 = 7,600 would give 6 windows, so 2,457.
  p.threads = 4;
  p.pipelines = 3;
  p.packet = 16;
  const units::PacketTiling t16 = units::packet_tiling(1024, 768, 16);
  EXPECT_EQ(sample_spec_text(resolve_sample_spec({}, p, t16)),
            "window=256,period=2457,warmup=320,cooldown=32");
  // What the SPEC gives is kept.
  EXPECT_EQ(
      sample_spec_text(resolve_sample_spec(parse_sample_spec("window=10,cooldown=0"), p, t16)),
      "window=10,period=2457,warmup=320,cooldown=0");
  // Caches of 8 items hold 8/512 of the row above: 4 of its 256 packets.
  for (auto& c : p.cache)
    c.items = 8;
  EXPECT_EQ(resolve_sample_spec({}, p, t16).warmup, 68);
  // 256 threads (64 on each of 4 DynRTPs): windows of two thread tables, longer than a row.
  p.threads = 64;
  p.pipelines = 4;
  EXPECT_EQ(resolve_sample_spec({}, p, t16).window, 512);
}

TEST(Sampling, BadSpecIsOneLineNamingIt) {
  for (const char* bad : {"window", "window=", "window=x", "window=-1", "size=3", "window=0",
                          "window=64,window=64", "window=64,period=100,warmup=40,cooldown=0",
                          "window=200,period=100", "window=1.5", "window=64,"}) {
    const std::string e = error_of([&] { parse_sample_spec(bad); });
    EXPECT_EQ(e.rfind(std::string("bad --sample '") + bad + "': ", 0), 0u) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(Sampling, PlanPlacesEachWindowInItsPeriodWithItsNeighbours) {
  // 10,500 packets, periods of 1,000: ten windows of 10, the last period holding the 500 left
  // over too; each window anywhere in its period, after up to 5 warm-up packets and before up to
  // 3 cool-down packets.
  const SampleSpec spec = parse_sample_spec("window=10,period=1000,warmup=5,cooldown=3");
  const SamplePlan p = plan_sample(10500, spec);
  EXPECT_EQ(p.windows, 10);
  ASSERT_EQ(p.marks.size(), 20u);
  // Every packet handed out once, in the frame's order.
  for (std::size_t k = 1; k < p.order.size(); ++k)
    EXPECT_LT(p.order[k - 1], p.order[k]);
  for (int i = 0; i < 10; ++i) {
    const auto w = static_cast<std::size_t>(i);
    const int first = p.window_first[w];
    const int size = i < 9 ? 1000 : 1500;
    EXPECT_EQ(p.strata[w], size);
    EXPECT_GE(first, 1000 * i);
    EXPECT_LE(first + 10, 1000 * i + size);
    // The window's packets between its marks.
    ASSERT_EQ(p.marks[2 * w + 1] - p.marks[2 * w], 10);
    for (int k = 0; k < 10; ++k)
      EXPECT_EQ(p.order[static_cast<std::size_t>(p.marks[2 * w] + k)], first + k);
    // Between the previous window and this one: the previous window's cool-down and this one's
    // warm-up, 3 and 5 packets when the windows lie far enough apart.
    if (i == 0) continue;
    const int prev = p.window_first[w - 1];
    const std::vector<int> between(p.order.begin() + p.marks[2 * w - 1],
                                   p.order.begin() + p.marks[2 * w]);
    for (int k : between)
      EXPECT_TRUE(k > prev + 9 && k < first) << k;
    if (first - (prev + 10) >= 8) {
      EXPECT_EQ(between, (std::vector<int>{prev + 10, prev + 11, prev + 12, first - 5, first - 4,
                                           first - 3, first - 2, first - 1}));
    }
  }
  // At most 18 packets a period (fewer where windows lie close or at the frame's start).
  EXPECT_GT(p.order.size(), 150u);
  EXPECT_LE(p.order.size(), 180u);
  // The places differ between periods (no column aliasing) and repeat between runs.
  std::set<int> offsets;
  for (int i = 0; i < 10; ++i)
    offsets.insert(p.window_first[static_cast<std::size_t>(i)] - 1000 * i);
  EXPECT_GT(offsets.size(), 5u);
  EXPECT_EQ(plan_sample(10500, spec).order, p.order);
  EXPECT_EQ(plan_sample(999, spec).windows, 0);
  // Two windows drawn next to each other: the cool-down stops at the next window, the warm-up
  // after the previous cool-down; nothing is handed out twice.
  const SamplePlan dense = plan_sample(400, SampleSpec{20, 20, 30, 30});
  EXPECT_EQ(dense.windows, 20);
  EXPECT_EQ(dense.order.size(), 400u);
}

TEST(Sampling, StudentT) {
  EXPECT_DOUBLE_EQ(student_t975(1), 12.7062);
  EXPECT_DOUBLE_EQ(student_t975(2), 4.3027);
  EXPECT_DOUBLE_EQ(student_t975(9), 2.2622);
  EXPECT_NEAR(student_t975(13), 2.1604, 2e-4);
  EXPECT_NEAR(student_t975(30), 2.0423, 2e-4);
  EXPECT_NEAR(student_t975(100), 1.9840, 2e-4);
}

// Windows of equal charges per packet (2 packets each) standing for the given strata.
std::vector<WindowCharges> windows_of(const std::vector<double>& per_packet,
                                      const std::vector<double>& strata) {
  std::vector<WindowCharges> w;
  for (std::size_t i = 0; i < per_packet.size(); ++i)
    w.push_back({{per_packet[i], per_packet[i]}, static_cast<int>(2 * i), strata[i]});
  return w;
}

TEST(Sampling, CyclesEstimateByHand) {
  // Windows of 10, 12 and 14 cycles per packet, 100 packets, no features: the fit is the mean 12,
  // the residuals -2, 0, 2 -> 1,200 cycles; their sample standard deviation 2, standard error
  // 2 / sqrt(3) = 1.1547, t(2) = 4.3027: half-width 4.3027 * 1.1547 * 100 = 496.83.
  const std::vector<double> thirds(3, 100.0 / 3);
  const FigureEstimate e = estimate_cycles(windows_of({10, 12, 14}, thirds), {}, 0.0);
  EXPECT_DOUBLE_EQ(e.value, 1200.0);
  EXPECT_NEAR(e.ci.low, 1200.0 - 496.83, 0.01);
  EXPECT_NEAR(e.ci.high, 1200.0 + 496.83, 0.01);
  // Half the frame sampled: the finite-population correction sqrt(1 - 0.5) narrows it.
  const FigureEstimate h = estimate_cycles(windows_of({10, 12, 14}, thirds), {}, 0.5);
  EXPECT_NEAR(h.ci.high - 1200.0, 496.83 * std::sqrt(0.5), 0.01);
  // A window standing for more packets weighs more: 12 x 100 - 2 x 20 + 2 x 50 = 1,260, the
  // plain stratified 10 x 20 + 12 x 30 + 14 x 50.
  EXPECT_DOUBLE_EQ(estimate_cycles(windows_of({10, 12, 14}, {20, 30, 50}), {}, 0.0).value, 1260.0);
}

// A frame of `n` packets whose steps (feature 1) are `steps(k)`, its other work none.
std::vector<CostFeatures> frame_features(int n, const std::function<double(int)>& steps) {
  std::vector<CostFeatures> f(static_cast<std::size_t>(n), CostFeatures{});
  for (int k = 0; k < n; ++k) {
    f[static_cast<std::size_t>(k)][0] = 1.0;
    f[static_cast<std::size_t>(k)][1] = steps(k);
  }
  return f;
}

// Four windows of 5 packets at 0, 100, 200 and 300, each standing for 100, their packets
// charged 2 + 3 x steps(k), window 0's `noise` more.
std::vector<WindowCharges> line_windows(const std::function<double(int)>& steps, double noise) {
  std::vector<WindowCharges> w;
  for (int i = 0; i < 4; ++i) {
    WindowCharges c{{}, 100 * i, 100.0};
    for (int k = c.first; k < c.first + 5; ++k)
      c.charges.push_back(2 + 3 * steps(k) + (i == 0 ? noise : 0.0));
    w.push_back(c);
  }
  return w;
}

TEST(Sampling, RegressionEstimateOnSyntheticData) {
  // 400 packets costing exactly 2 + 3 x steps, steps k % 7: the true total is the sum over the
  // frame. Four windows of 5 packets at 0, 100, 200, 300 fit it exactly: the estimate is exact
  // and its interval has width 0, whatever the windows saw. Features without spread (tests,
  // leaves, ...) get no coefficient.
  const auto steps = [](int k) { return static_cast<double>(k % 7); };
  const std::vector<CostFeatures> f = frame_features(400, steps);
  double truth = 0;
  for (int k = 0; k < 400; ++k)
    truth += 2 + 3 * steps(k);
  std::vector<WindowCharges> w = line_windows(steps, 0.0);
  double r = 0;
  const FigureEstimate exact = estimate_cycles(w, f, 0.0, &r);
  EXPECT_NEAR(exact.value, truth, 1e-6);
  EXPECT_NEAR(exact.ci.high - exact.ci.low, 0.0, 1e-6);
  EXPECT_NEAR(r, 1.0, 1e-9);
  EXPECT_NEAR(correlation({1, 2, 3, 4}, {5, 8, 11, 14}), 1.0, 1e-12);
  EXPECT_EQ(correlation({1, 2, 3, 4}, {2, 2, 2, 2}), 0.0);
}

TEST(Sampling, RegressionEstimateAgainstAClosedForm) {
  // The frame and windows above, with noise +1 on every packet of window 0: the least-squares
  // line through the 20 packets against an independent closed form (slope Sxy / Sxx, intercept
  // mean y - slope mean x), then the frame's fit plus each window's mean residual times its 100
  // packets.
  const auto steps = [](int k) { return static_cast<double>(k % 7); };
  const std::vector<CostFeatures> f = frame_features(400, steps);
  std::vector<WindowCharges> w = line_windows(steps, 1.0);
  double sx = 0, sy = 0;
  std::vector<std::pair<double, double>> xy;
  for (const WindowCharges& c : w)
    for (std::size_t j = 0; j < c.charges.size(); ++j)
      xy.emplace_back(steps(c.first + static_cast<int>(j)), c.charges[j]);
  for (const auto& [x, y] : xy) {
    sx += x / 20;
    sy += y / 20;
  }
  double sxx = 0, sxy = 0;
  for (const auto& [x, y] : xy) {
    sxx += (x - sx) * (x - sx);
    sxy += (x - sx) * (y - sy);
  }
  const double b = sxy / sxx, a = sy - b * sx;
  double expect = 0;
  for (int k = 0; k < 400; ++k)
    expect += a + b * steps(k);
  std::vector<double> res;
  for (const WindowCharges& c : w) {
    double m = 0;
    for (std::size_t j = 0; j < c.charges.size(); ++j)
      m += (c.charges[j] - a - b * steps(c.first + static_cast<int>(j))) / 5;
    res.push_back(m);
    expect += 100 * m;
  }
  const FigureEstimate noisy = estimate_cycles(w, f, 0.0);
  EXPECT_NEAR(noisy.value, expect, 1e-6);
  const double mr = (res[0] + res[1] + res[2] + res[3]) / 4;
  double ss = 0;
  for (double x : res)
    ss += (x - mr) * (x - mr);
  EXPECT_NEAR(noisy.ci.high - noisy.value, student_t975(3) * std::sqrt(ss / 3 / 4) * 400, 1e-6);
  EXPECT_GT(noisy.ci.high - noisy.value, 1.0);  // the noise widens it
  // The plain estimator on the same windows: the windows' mean charges times their strata.
  double plain = 0;
  for (const WindowCharges& c : w) {
    double m = 0;
    for (double x : c.charges)
      m += x / 5;
    plain += 100 * m;
  }
  EXPECT_NEAR(estimate_cycles(w, {}, 0.0).value, plain, 1e-6);
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

TEST(Sampling, ChargesAddUpToTheCyclesAndChangeNothing) {
  // Charging the packets (units::PacketCharges) only watches: the same cycles and figures; and
  // the charges with the cycles no packet was in flight in are the frame's cycles.
  const memif::MemoryImage image = room("128x96");
  const units::CycleParams p = units::prototype_params();
  const CycleFrame plain = run_cycle(image, p);
  CycleRunOptions o;
  o.charge_packets = true;
  const CycleFrame charged = run_cycle(image, p, o);
  EXPECT_EQ(charged.cycles, plain.cycles);
  EXPECT_EQ(charged.figures.value, plain.figures.value);
  EXPECT_TRUE(plain.packet_charges.empty());
  ASSERT_EQ(charged.packet_charges.size(), charged.packets);
  double sum = 0;
  for (double c : charged.packet_charges) {
    EXPECT_GT(c, 0.0);
    sum += c;
  }
  EXPECT_GT(charged.uncharged_cycles, 0u);
  EXPECT_NEAR(sum + static_cast<double>(charged.uncharged_cycles),
              static_cast<double>(charged.cycles), 1e-6 * static_cast<double>(charged.cycles));
}

TEST(Sampling, SampledFrameAgainstTheFullOne) {
  // The room at 256x192 (12,288 packets), periods of 256: 48 windows of 32 packets, each after up
  // to 64 of warm-up and before up to 32 of cool-down; each simulated packet checked bit for bit
  // against the functional model.
  const memif::MemoryImage image = room("256x192");
  const units::CycleParams p = units::prototype_params();
  const CycleFrame full = run_cycle(image, p);
  const SampleSpec spec = parse_sample_spec("window=32,period=256,warmup=64,cooldown=32");
  const CycleFrame s = run_sampled(image, p, {}, spec);
  ASSERT_TRUE(s.sampling);
  const std::size_t simulated = plan_sample(12288, spec).order.size();
  EXPECT_GT(simulated, 4000u);
  EXPECT_LE(simulated, 48u * 128u);
  EXPECT_EQ(s.sampling->windows, 48);
  EXPECT_EQ(s.sampling->packets_simulated, simulated);
  EXPECT_EQ(s.packets, 12288u);
  EXPECT_EQ(s.packets_retired, simulated);
  EXPECT_TRUE(s.sampling->defeated.empty()) << s.sampling->defeated;
  EXPECT_NO_THROW(check_sampled_packets(image, p, {}, s));
  // Every record of the full frame was written by its packet (no ray's t is zero bytes); the
  // sampled run wrote its packets' pixels and no other (FrameSink: never written before the run).
  for (const units::FrameSink::Pixel& px : full.frame.pixels)
    ASSERT_NE(px.t, 0u);
  std::set<std::uint32_t> handed_out;
  const units::PacketTiling tiling = units::packet_tiling(256, 192, p.packet);
  for (int packet : plan_sample(12288, spec).order)
    for (std::uint32_t px : units::packet_pixels(tiling, 256, 192, packet))
      handed_out.insert(px);
  for (std::uint32_t i = 0; i < s.frame.pixels.size(); ++i) {
    ASSERT_EQ(s.frame.pixels[i].t != 0u, handed_out.count(i) == 1) << "pixel " << i;
    if (handed_out.count(i) == 0) {
      ASSERT_EQ(s.frame.pixels[i].instance, 0u) << "pixel " << i;
    }
  }
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
  EXPECT_EQ(json_at(j, "sampling.packets_simulated").get<std::size_t>(), simulated);
  EXPECT_NE(
      sampling_text(s).find("sampled: window=32,period=256,warmup=64,cooldown=32, 48 windows"),
      std::string::npos);
}

// A scene seen from `away` times its camera's distance, at 256x192.
memif::MemoryImage distant(const std::string& name, double away) {
  host::Scene scene = host::load_scene(name);
  scene.cameras.at(0).position *= static_cast<float>(away);
  host::ImageParams ip;
  ip.width = 256;
  ip.height = 192;
  return host::build_image(scene, ip).image;
}

TEST(Sampling, FrameWithItsCostInFewPacketsSaysSo) {
  // SunCOR from thirty times its camera's distance: the field of sunflowers, hundreds of instances,
  // covers a few hundred of the 12,288 packets; the rest leave at the scene's box. Half the frame's
  // fitted cost sits in those packets, which fewer than 5 of the 24 windows reach: the report
  // gives no interval and says why.
  const memif::MemoryImage image = distant("builtin:suncor", 30.0);
  const CycleFrame s = run_sampled(image, units::prototype_params(), {},
                                   parse_sample_spec("window=64,period=512,warmup=64,cooldown=32"));
  ASSERT_TRUE(s.sampling);
  EXPECT_EQ(s.sampling->windows, 24);
  EXPECT_LT(s.sampling->costly_windows, kMinCostlyWindows);
  EXPECT_LT(s.sampling->costly_packets, 600u);
  EXPECT_NE(s.sampling->defeated.find("concentrated in few packets"), std::string::npos)
      << s.sampling->defeated;
  const nlohmann::json j = cycle_report_json(s);
  EXPECT_FALSE(j["sampling"]["trusted"].get<bool>());
  EXPECT_FALSE(j["sampling"].contains("ci95"));
  EXPECT_NE(sampling_text(s).find("no confidence interval: the cost is concentrated"),
            std::string::npos);
  // From three times its distance it fills a quarter of the frame: the same sampling is trusted.
  const CycleFrame near =
      run_sampled(distant("builtin:suncor", 3.0), units::prototype_params(), {},
                  parse_sample_spec("window=64,period=512,warmup=64,cooldown=32"));
  ASSERT_TRUE(near.sampling);
  EXPECT_GE(near.sampling->costly_windows, kMinCostlyWindows);
  EXPECT_EQ(near.sampling->defeated, "");
  // Too few windows: periods of 2,048 packets give 6.
  const CycleFrame few =
      run_sampled(image, units::prototype_params(), {}, parse_sample_spec("window=64,period=2048"));
  ASSERT_TRUE(few.sampling);
  EXPECT_EQ(few.sampling->defeated, "only 6 windows (an interval needs at least 10)");
}

TEST(SamplingBinary, SampleOptionAndBadSpec) {
  const test_support::CliRun ok = test_support::run_saarcor(
      "render builtin:room --model cycle --res 128x96 --sample window=16,period=128,warmup=32,"
      "cooldown=16 "
      "--out " +
      (test_support::scratch_dir("sample") / "room").string());
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_NE(ok.out.find("sampled: window=16,period=128,warmup=32,cooldown=16, 24 windows, "),
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
      test_support::run_saarcor("paper --scale 8 --sample window=9,period=10,warmup=2,cooldown=0"),
      "exceeds the period");
}

}  // namespace
}  // namespace saarcor
