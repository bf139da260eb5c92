// The cost columns of `saarcor sweep` and its Pareto front (--pareto): every point's cost from
// the cost model of its configuration (units/cost.h), in the table, the CSV, the JSON and
// stats.txt; fronts computed by hand, ties included; sweep-merge's front; bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "testbench/report.h"
#include "testbench/sweep_cmd.h"
#include "testbench/testing.h"

namespace saarcor {
namespace {

namespace fs = std::filesystem;
using test_support::error_of;

TEST(SweepPareto, HandComputedFronts) {
  // (fps, cost): A (10, 100) is beaten by B (20, 100); B and C are equal, neither beats the other;
  // D (5, 50) is the cheapest; E (15, 200) is beaten by B; F (30, 300) by G (30, 250), which no
  // point beats. Front: B, C, D, G.
  EXPECT_EQ(
      pareto_front({{10, 100}, {20, 100}, {20, 100}, {5, 50}, {15, 200}, {30, 300}, {30, 250}}),
      (std::vector<bool>{false, true, true, true, false, false, true}));
  // The same cost: the faster one alone. The same frame rate: the cheaper one alone.
  EXPECT_EQ(pareto_front({{10, 5}, {12, 5}}), (std::vector<bool>{false, true}));
  EXPECT_EQ(pareto_front({{10, 5}, {10, 6}}), (std::vector<bool>{true, false}));
  // Faster and dearer at each step: all on the front. One point: on it. None: none.
  EXPECT_EQ(pareto_front({{1, 1}, {2, 2}, {3, 3}}), (std::vector<bool>{true, true, true}));
  EXPECT_EQ(pareto_front({{7, 7}}), std::vector<bool>{true});
  EXPECT_TRUE(pareto_front({}).empty());
}

TEST(SweepPareto, CostNames) {
  EXPECT_EQ(pareto_cost_name(""), "luts");
  EXPECT_EQ(pareto_cost_name("block_rams"), "block_rams");
  EXPECT_EQ(error_of([] { pareto_cost_name("area"); }),
            "bad --pareto-cost 'area': expected a cost column (fp_units, memory_kb, luts, "
            "block_rams)");
}

// builtin:room at 64x48, threads 2 and 16: the same FP units (the same LUTs), more memory with
// more threads. Run once, shared by the tests.
const SweepResult& two_thread_counts() {
  static const SweepResult r = [] {
    RenderSettings s;
    s.res = {64, 48};
    const PreparedScene room = prepare_scene("builtin:room", s);
    return run_sweep_points({parse_sweep_axis("threads=2,16")}, room, s);
  }();
  return r;
}

TEST(SweepCost, EveryPointCarriesItsConfigurationsCost) {
  const SweepResult& r = two_thread_counts();
  ASSERT_EQ(r.points.size(), 2u);
  for (const SweepPoint& p : r.points) {
    // The prototype's FP units and LUTs whatever the threads (units/cost_test.cpp
    // Cost.Table2AreaByHand: 48 units, 33,164 LUTs for P = 4).
    EXPECT_EQ(p.cost["fp_units"].get<double>(), 48);
    EXPECT_EQ(p.cost["luts"].get<double>(), 33'164);
  }
  // Each point's memory is the cost model's for its thread count, on the prototype's light table.
  for (int i = 0; i < 2; ++i) {
    units::CostParams params = units::cost_preset("prototype");
    units::apply_cost_setting(params, i == 0 ? "threads=2" : "threads=16");
    const units::ConfigurationCost c = units::configuration_cost(params);
    EXPECT_DOUBLE_EQ(r.points[i].cost["memory_kb"].get<double>(), c.memory_kb_total());
    EXPECT_EQ(r.points[i].cost["block_rams"].get<double>(), c.area_total.block_rams);
  }
  EXPECT_LT(r.points[0].cost["memory_kb"].get<double>(),
            r.points[1].cost["memory_kb"].get<double>());
  EXPECT_LT(r.points[0].cost["block_rams"].get<double>(),
            r.points[1].cost["block_rams"].get<double>());
}

// The columns of the table and the CSV, and the stats.txt lines, from the declarations.
TEST(SweepCost, ColumnsAndStatsLines) {
  const SweepResult& r = two_thread_counts();
  const std::string csv = sweep_csv(r);
  EXPECT_NE(csv.find(",simd_efficiency,fp_units,memory_kb,luts,block_rams\n"), std::string::npos)
      << csv;
  EXPECT_NE(sweep_table(r).find("FP   mem KB    LUTs  BRAM"), std::string::npos) << sweep_table(r);
  const std::vector<StatLine> lines = sweep_point_stat_lines(r.points[0], false);
  const auto luts = std::ranges::find(lines, std::string("cost.luts"), &StatLine::name);
  ASSERT_NE(luts, lines.end());
  EXPECT_EQ(luts->value, 33'164);
  EXPECT_EQ(luts->unit, "LUTs");
  EXPECT_EQ(std::ranges::count(lines, std::string("cost.pareto"), &StatLine::name), 0);
}

TEST(SweepCost, ParetoColumnListAndJson) {
  SweepResult r = two_thread_counts();
  const double fps2 = r.points[0].cycle["fps"].get<double>();
  const double fps16 = r.points[1].cycle["fps"].get<double>();
  ASSERT_GT(fps16, fps2);  // 16 threads hide the latencies 2 wait out
  // Against the LUTs (equal): 16 threads are faster at the same cost, 2 threads are beaten.
  mark_pareto(r, "luts");
  EXPECT_FALSE(r.points[0].pareto);
  EXPECT_TRUE(r.points[1].pareto);
  const std::string csv = sweep_csv(r);
  EXPECT_NE(csv.find(",luts,block_rams,pareto_luts\n"), std::string::npos) << csv;
  EXPECT_EQ(csv.substr(csv.size() - 3), ",1\n") << csv;
  std::istringstream t(sweep_table(r));
  std::string head, row1, row2;
  std::getline(t, head);
  std::getline(t, row1);
  std::getline(t, row2);
  EXPECT_TRUE(head.ends_with("front")) << head;
  EXPECT_TRUE(row2.ends_with("*")) << row2;
  EXPECT_FALSE(row1.ends_with("*")) << row1;
  EXPECT_EQ(row1.size(), head.size());
  const std::string list = sweep_pareto_text(r);
  EXPECT_EQ(list.rfind("Pareto front (frame rate against luts, LUTs): 1 of 2 points", 0), 0u)
      << list;
  EXPECT_NE(list.find("33164.00 luts"), std::string::npos) << list;
  EXPECT_TRUE(list.ends_with("fps  threads=16\n")) << list;
  SweepOptions o;
  o.vary = {"threads=2,16"};
  const nlohmann::json j = sweep_json(r, o);
  EXPECT_EQ(j["pareto"]["cost"], "luts");
  EXPECT_EQ(j["pareto"]["points"], nlohmann::json::array({1}));
  EXPECT_FALSE(j["points"][0]["pareto"].get<bool>());
  EXPECT_EQ(j["points"][1]["cost"]["luts"].get<double>(), 33'164);
  EXPECT_EQ(j["cost_stats"]["block_rams"]["unit"], "block RAMs");
  // Against the block RAMs: 2 threads are cheaper, 16 faster; both on the front.
  mark_pareto(r, "block_rams");
  EXPECT_TRUE(r.points[0].pareto);
  EXPECT_TRUE(r.points[1].pareto);
  EXPECT_EQ(sweep_pareto_text(r).rfind("Pareto front (frame rate against block_rams, block RAMs): "
                                       "2 of 2 points",
                                       0),
            0u);
  const std::vector<StatLine> lines = sweep_point_stat_lines(r.points[0], true);
  EXPECT_EQ(lines.back().name, "cost.pareto");
  EXPECT_EQ(lines.back().value, 1.0);
}

TEST(SaarcorBinary, SweepParetoEndToEndAndBadInput) {
  const fs::path d = test_support::scratch_dir("sweep_pareto");
  fs::remove_all(d);
  const test_support::CliRun r = test_support::run_saarcor(
      "sweep builtin:cube --res 16x12 --vary threads=1,4 --vary packet=4,16 --pareto --out-dir " +
      (d / "run").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("Pareto front (frame rate against luts, LUTs): "), std::string::npos)
      << r.out;
  std::ifstream stats(d / "run" / "stats.txt");
  std::stringstream ss;
  ss << stats.rdbuf();
  EXPECT_EQ(std::ranges::count(ss.str(), '\n') > 0, true);
  for (const char* name :
       {"cost.fp_units ", "cost.memory_kb ", "cost.luts ", "cost.block_rams ", "cost.pareto "}) {
    std::size_t n = 0;
    for (std::size_t at = ss.str().find(name); at != std::string::npos;
         at = ss.str().find(name, at + 1))
      ++n;
    EXPECT_EQ(n, 4u) << name;  // one line per point
  }
  std::ifstream csv(d / "run" / "sweep.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_TRUE(header.ends_with(",fp_units,memory_kb,luts,block_rams,pareto_luts")) << header;
  // Bad input: one line naming the option or the key, before any frame.
  test_support::expect_one_line_error(
      test_support::run_saarcor("sweep builtin:cube --res 8x8 --vary threads=4 --pareto-cost area"),
      "bad --pareto-cost 'area'");
  test_support::expect_one_line_error(
      test_support::run_saarcor("sweep builtin:cube --res 8x8 --vary cache.list.ways=1,3"),
      "cache.list.ways");
  test_support::expect_one_line_error(
      test_support::run_saarcor(
          "sweep builtin:cube --res 8x8 --vary pipelines=1,16 --set threads=512"),
      "pipelines");
}

}  // namespace
}  // namespace saarcor
