// The Perfetto timeline (units/perfetto_trace.h, docs/traces.md) on real frames: its slices are
// the frame's requests and misses, counted by the chip's own counters and by the request trace;
// its counters stay within what the chip holds; times are cycles at the clock; tracing moves no
// figure; a window after the frame is one error line. (scripts/check_trace_events.py checks the
// format's rules on a room window, under CTest, independently of the writer.)
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "testbench/chip.h"
#include "testbench/dynrtc_testing.h"
#include "testbench/testing.h"
#include "units/figures.h"
#include "units/perfetto_trace.h"

namespace saarcor {
namespace {

constexpr int kW = units::testing::kSanitized ? 16 : 32;
constexpr int kH = units::testing::kSanitized ? 12 : 24;

struct Timeline {
  nlohmann::json doc;
  std::string trace;
  CycleFrame frame;
};

Timeline run_timeline(const std::vector<std::string>& set, std::uint64_t from, std::uint64_t to) {
  const host::BuiltImage built = units::testing::build("builtin:room", kW, kH);
  units::CycleParams p = units::prototype_params();
  for (const std::string& kv : set)
    units::apply_cycle_setting(p, kv);
  CycleRunOptions o;
  std::ostringstream json, trace;
  o.trace.perfetto = &json;
  o.trace.trace = &trace;
  o.trace.from = from;
  o.trace.to = to;
  Timeline t;
  t.frame = run_cycle(built.image, p, o);
  t.doc = nlohmann::json::parse(json.str());
  t.trace = trace.str();
  return t;
}

// The X slices of the units' tracks (category: the unit's name), per unit name.
std::map<std::string, std::uint64_t> unit_slices(const nlohmann::json& doc) {
  std::map<std::string, std::uint64_t> n;
  for (const auto& e : doc["traceEvents"])
    if (e["ph"] == "X" && e["cat"] != "miss") ++n[e["cat"].get<std::string>()];
  return n;
}

std::uint64_t count_ph(const nlohmann::json& doc, const std::string& ph, const std::string& cat) {
  std::uint64_t n = 0;
  for (const auto& e : doc["traceEvents"])
    if (e["ph"] == ph && (cat.empty() || e.value("cat", "") == cat)) ++n;
  return n;
}

// Two DynRTPs of 8 threads over the whole frame: one slice per request each unit served (the
// chip's counters), one miss slice per cache miss, a flow per miss whose requester issued next.
TEST(Perfetto, WholeFrameSlicesAreTheChipsRequestsAndMisses) {
  const std::vector<std::string> set = {"pipelines=2", "threads=8"};
  const Timeline t = run_timeline(set, 0, UINT64_MAX);
  const std::map<std::string, std::uint64_t> slices = unit_slices(t.doc);
  for (int i = 0; i < units::kTable4Units; ++i) {
    EXPECT_GT(t.frame.requests[static_cast<std::size_t>(i)], 0u);
    EXPECT_EQ(slices.at(units::kTable4UnitNames[i]), t.frame.requests[static_cast<std::size_t>(i)])
        << units::kTable4UnitNames[i];
  }
  std::uint64_t misses = 0;
  for (const CycleFrame::CacheCount& c : t.frame.caches)
    misses += c.misses;
  EXPECT_GT(misses, 0u);
  EXPECT_EQ(count_ph(t.doc, "X", "miss"), misses);
  // Every flow starts at a miss; a miss is the first of its line's requests (merges wait with it).
  const std::uint64_t flows = count_ph(t.doc, "s", "miss");
  EXPECT_EQ(count_ph(t.doc, "f", "miss"), flows);
  EXPECT_GT(flows, 0u);
  EXPECT_LE(flows, misses);
  // Two processes, named; the frame's cycles in otherData.
  std::set<int> pids;
  for (const auto& e : t.doc["traceEvents"])
    if (e["ph"] == "M" && e["name"] == "process_name") pids.insert(e["pid"].get<int>());
  EXPECT_EQ(pids, (std::set<int>{1, 2}));
  EXPECT_EQ(t.doc["otherData"]["frame_cycles"].get<std::uint64_t>(), t.frame.cycles);
  // Tracing moves no figure.
  units::CycleParams p = units::prototype_params();
  for (const std::string& kv : set)
    units::apply_cycle_setting(p, kv);
  const CycleFrame plain = run_cycle(units::testing::build("builtin:room", kW, kH).image, p, {});
  EXPECT_EQ(plain.cycles, t.frame.cycles);
  EXPECT_EQ(plain.frame.rgb, t.frame.frame.rgb);
}

// A window: every slice starts inside it, there is one per request trace line (the requests
// issued in the window), the times are the cycles at 90 MHz (cycle 900 = 10 us), and the counters
// stay within the chip: busy threads at most the 64 threads, hit rates in [0, 100].
TEST(Perfetto, WindowHoldsTheTracesRequestsAtTheClock) {
  const std::uint64_t from = 300, to = 1500;
  const Timeline t = run_timeline({}, from, to);
  std::uint64_t lines = 0;
  std::istringstream in(t.trace);
  for (std::string l; std::getline(in, l);)
    lines += !l.starts_with("#");
  std::uint64_t slices = 0, busy = 0, hits = 0;
  for (const auto& e : t.doc["traceEvents"]) {
    if (e["ph"] == "X" && e["cat"] != "miss") {
      ++slices;
      const auto cycle = e["args"]["cycle"].get<std::uint64_t>();
      EXPECT_GE(cycle, from);
      EXPECT_LE(cycle, to);
      EXPECT_NEAR(e["ts"].get<double>(), static_cast<double>(cycle) / 90.0, 1e-4);
      // A step is one cycle: 11.1 ns at 90 MHz.
      EXPECT_NEAR(e["dur"].get<double>(), e["args"]["steps"].get<double>() / 90.0, 2e-4);
    }
    if (e["ph"] == "C" && e["name"] == "busy threads") {
      ++busy;
      EXPECT_LE(e["args"]["threads"].get<int>(), 64);
    }
    if (e["ph"] == "C" && e["name"].get<std::string>().ends_with("hit %")) {
      ++hits;
      EXPECT_GE(e["args"]["hit_pct"].get<double>(), 0.0);
      EXPECT_LE(e["args"]["hit_pct"].get<double>(), 100.0);
    }
  }
  EXPECT_GT(lines, 0u);
  EXPECT_EQ(slices, lines);
  // At most one sample per 32 cycles of the window, 1201 cycles: at most 38.
  EXPECT_GT(busy, 0u);
  EXPECT_LE(busy, (to - from) / units::kPerfettoCounterPeriod + 1);
  EXPECT_GT(hits, 0u);
}

TEST(Perfetto, WindowAfterTheFrameIsOneErrorLine) {
  EXPECT_NE(test_support::error_of([] {
              run_timeline({}, 50'000'000, UINT64_MAX);
            }).find("--trace-from 50000000 is after the frame's last cycle"),
            std::string::npos);
  const std::filesystem::path d = test_support::scratch_dir("perfetto");
  const std::string file = (d / "late.json").string();
  const std::string base = "render builtin:room --model cycle --res 16x12 --out " +
                           (d / "img").string() + " --perfetto ";
  test_support::expect_one_line_error(
      test_support::run_saarcor(base + file + " --trace-from 50000000"), "after the frame");
  EXPECT_FALSE(std::filesystem::exists(file));
  test_support::expect_one_line_error(
      test_support::run_saarcor("render builtin:room --model fp24 --res 16x12 --perfetto " + file),
      "--perfetto needs --model cycle");
  test_support::expect_one_line_error(test_support::run_saarcor(base + (d / "t.txt").string()),
                                      "ends in .json");
}

}  // namespace
}  // namespace saarcor
