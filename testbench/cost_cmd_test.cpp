// `saarcor cost` and `saarcor paper --table 1|2` (testbench/cost_cmd.h, docs/cost.md): the JSON
// keys, Table 2 beside the paper's, Table 1's ratios, bad input; and the cost model's FP unit
// counts pinned to the operator instances of the RTL datapaths (rtl/*_unit.sv).
#include "testbench/cost_cmd.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "testbench/testing.h"

namespace saarcor {
namespace {

using test_support::expect_one_line_error;
using test_support::run_saarcor;
using test_support::scratch_dir;

// The fp operator instances of a SystemVerilog module's text, generate loops multiplied out
// (`for (genvar i = A; i < B; i++) begin ... end`): fp_add, fp_mul, fp_div, and fp_cmp,
// fp_cmp_core and fp_minmax (a comparator and a multiplexer) as comparators.
units::FpUnits rtl_operators(const std::string& sv) {
  static const std::regex loop(R"(for\s*\(\s*genvar\s+\w+\s*=\s*(\d+)\s*;\s*\w+\s*<\s*(\d+)\s*;)");
  static const std::regex inst(
      R"(^\s*(fp_add|fp_mul|fp_div|fp_cmp|fp_cmp_core|fp_minmax)\s+(#|\w))");
  static const std::regex word(R"(\b(begin|end)\b)");
  units::FpUnits u;
  std::vector<std::pair<int, int>> loops;  // (multiplier, begin depth it opened at)
  int depth = 0, pending = 0;
  std::istringstream in(sv);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_search(line, m, loop)) pending = std::stoi(m[2]) - std::stoi(m[1]);
    if (std::regex_search(line, m, inst)) {
      int k = 1;
      for (const auto& l : loops)
        k *= l.first;
      const std::string op = m[1];
      int* slot = op == "fp_add"   ? &u.add
                  : op == "fp_mul" ? &u.mul
                  : op == "fp_div" ? &u.div
                                   : &u.cmp;
      *slot += k;
    }
    for (auto it = std::sregex_iterator(line.begin(), line.end(), word);
         it != std::sregex_iterator(); ++it) {
      if ((*it)[1] == "begin") {
        ++depth;
        if (pending != 0) loops.emplace_back(pending, depth);
        pending = 0;
      } else {
        if (!loops.empty() && loops.back().second == depth) loops.pop_back();
        --depth;
      }
    }
  }
  return u;
}

units::FpUnits rtl_file(const std::string& name) {
  std::ifstream f(std::string(SAARCOR_SOURCE_DIR) + "/rtl/" + name);
  EXPECT_TRUE(f.good()) << name;
  std::stringstream ss;
  ss << f.rdbuf();
  return rtl_operators(ss.str());
}

TEST(CostRtl, OperatorCountParserMultipliesGenerateLoops) {
  const std::string sv =
      "  fp_add #(.E(E)) u_a (.clk);\n"
      "  for (genvar i = 0; i < 3; i++) begin : g\n"
      "    fp_mul #(.E(E)) u_m (.clk);\n"
      "    always_comb begin x = 1; end\n"
      "    fp_cmp_core #(.E(E)) u_c (.a);\n"
      "  end\n"
      "  fp_div #(.E(E)) u_d (.clk);\n";
  EXPECT_EQ(rtl_operators(sv), (units::FpUnits{1, 3, 1, 3, 0}));
}

TEST(CostRtl, FormulaFpUnitsEqualTheRtlOperatorInstances) {
  const units::ConfigurationCost c = units::configuration_cost(units::cost_preset("table2"));
  auto fp = [&](const char* key) {
    for (const auto& u : c.units)
      if (u.key == key) return u.fp;
    return units::FpUnits{};
  };
  // transform_unit.sv: three rows of 3 multipliers and 3 adders in a generate loop.
  EXPECT_EQ(rtl_file("transform_unit.sv"), fp("transformation"));
  // intersection_unit.sv: 1 divider, 2 multipliers, 3 adders; the acceptance is bit and
  // encoding tests, no comparator (D13).
  EXPECT_EQ(rtl_file("intersection_unit.sv"), fp("intersection"));
  // traversal_unit.sv is one lane of the node step: the formula's per-lane adder and divider,
  // and its 3 compares per lane less the termination compare (t_best < tn), which the RTL lane
  // leaves to the unit around it (docs/rtl.md).
  const units::FpUnits lane = rtl_file("traversal_unit.sv");
  const units::FpUnits k = fp("traversal");
  const int p = 4;
  EXPECT_EQ(lane.add, k.add / p);
  EXPECT_EQ(lane.div, k.div / p);
  EXPECT_EQ(lane.mul, k.mul);
  EXPECT_EQ(lane.cmp, k.cmp / p - 1);
}

TEST(CostCmd, Table2PresetJsonAndText) {
  const auto dir = scratch_dir("cost_json");
  const std::string json = (dir / "cost.json").string();
  const auto r = run_saarcor("cost --preset table2 --json " + json);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("  ratio model/paper"), std::string::npos);
  EXPECT_NE(r.out.find("44.50"), std::string::npos);  // Table 2's traversal memory
  EXPECT_NE(r.out.find("stacks"), std::string::npos);
  std::ifstream f(json);
  const nlohmann::json j = nlohmann::json::parse(f);
  for (const char* u : {"traversal", "list", "transformation", "intersection", "caches", "shader"})
    for (const char* k : {"add", "mul", "div", "cmp", "memory_bits", "memory_kb"})
      EXPECT_TRUE(j["units"][u].contains(k)) << u << "." << k;
  EXPECT_EQ(j["units"]["traversal"]["cmp"].get<int>(), 12);
  // 64 entries x (21 + 4 + 8 x 24) bits x 32 threads (docs/cost.md).
  EXPECT_EQ(j["units"]["traversal"]["memory_by_kind"]["stacks"].get<std::int64_t>(), 444'416);
  EXPECT_EQ(j["units"]["transformation"]["mul"].get<int>(), 9);
  EXPECT_EQ(j["total"]["memory_bits"].get<std::int64_t>(), 826'592);
  EXPECT_NEAR(j["total"]["memory_kb"].get<double>(), 100.90, 0.01);
  EXPECT_DOUBLE_EQ(j["flops"].get<double>(), 48 * 90e6);
  EXPECT_DOUBLE_EQ(j["table1"]["dyn1_over_static"]["without_traversal"].get<double>(), 24.0 / 36);
  EXPECT_DOUBLE_EQ(j["table1"]["dyn1_over_dyn3"]["full"].get<double>(), 44.0 / 109);
  EXPECT_DOUBLE_EQ(j["table2"]["traversal"]["memory_kb"]["paper"].get<double>(), 44.5);
  EXPECT_EQ(j["configuration"]["threads"].get<double>(), 32);
  // The area estimate (units/cost_test.cpp Cost.Table2AreaByHand has the sums).
  EXPECT_EQ(j["units"]["traversal"]["luts"].get<std::int64_t>(), 10'080);
  EXPECT_EQ(j["units"]["transformation"]["mult18x18"].get<int>(), 9);
  EXPECT_EQ(j["units"]["caches"]["block_rams"].get<int>(), 7);
  EXPECT_EQ(j["total"]["luts"].get<std::int64_t>(), 33'164);
  EXPECT_EQ(j["total"]["block_rams"].get<int>(), 41);
  EXPECT_EQ(j["total"]["per_pipeline"]["luts"].get<std::int64_t>(), 33'164);
  EXPECT_EQ(j["operator_area"]["div"]["luts"].get<int>(), 1504);
  EXPECT_NE(r.out.find("LUTs  BRAM"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("33164 LUTs (49.1 %), 12 MULT18X18 (8.3 %), at least 41 block RAMs"),
            std::string::npos)
      << r.out;
}

TEST(CostCmd, PrototypeHasNoPaperLinesAndSetsApply) {
  const auto r = run_saarcor("cost --set threads=16 --set lights=4");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.find("paper  "), std::string::npos);
  EXPECT_NE(r.out.find("16 threads"), std::string::npos);
  EXPECT_NE(r.out.find("(4 lights)"), std::string::npos);
}

TEST(CostCmd, BadInputIsOneLineNamingTheKey) {
  const auto dir = scratch_dir("cost_bad");
  const std::string json = (dir / "x.json").string();
  expect_one_line_error(run_saarcor("cost --set cache.list.ways=3 --json " + json),
                        "cache.list.ways");
  EXPECT_FALSE(std::filesystem::exists(json));
  expect_one_line_error(run_saarcor("cost --set lights=-2"), "lights");
  expect_one_line_error(run_saarcor("cost --set threads=0"), "threads");
  expect_one_line_error(run_saarcor("cost --set nokey=1"), "nokey");
  expect_one_line_error(run_saarcor("cost --preset nope"), "preset");
  expect_one_line_error(run_saarcor("cost --json out.txt"), "--json");
}

TEST(CostCmd, PaperTables1And2) {
  const auto t1 = run_saarcor("paper --table 1");
  ASSERT_EQ(t1.status, 0) << t1.err;
  EXPECT_NE(t1.out.find("RT_Dyn1 / RT_Dyn3"), std::string::npos);
  EXPECT_NE(t1.out.find("66.7%"), std::string::npos);  // 24 / 36 beside the paper's 66 %
  EXPECT_NE(t1.out.find("40.4%"), std::string::npos);  // 44 / 109 beside 32 %
  const auto t2 = run_saarcor("paper --table 2");
  ASSERT_EQ(t2.status, 0) << t2.err;
  EXPECT_NE(t2.out.find("Table 2"), std::string::npos);
  EXPECT_NE(t2.out.find("32 threads"), std::string::npos);
  EXPECT_NE(t2.out.find("75.00"), std::string::npos);  // the paper's total
  const auto dir = scratch_dir("paper_cost");
  const std::string json = (dir / "t2.json").string();
  const auto t2j = run_saarcor("paper --table 2 --json " + json);
  ASSERT_EQ(t2j.status, 0) << t2j.err;
  std::ifstream f(json);
  const nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_DOUBLE_EQ(j["table2"]["total"]["memory_kb"]["paper"].get<double>(), 75.0);
  expect_one_line_error(run_saarcor("paper --table 1 --csv t.csv"), "--csv");
  expect_one_line_error(run_saarcor("paper --table 5"), "--table");
  expect_one_line_error(run_saarcor("paper --table 2 --set stack=0"), "stack");
}

}  // namespace
}  // namespace saarcor
