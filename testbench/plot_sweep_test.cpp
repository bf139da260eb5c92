// scripts/plot_sweep.py (Debian's /usr/bin/python3 with python3-matplotlib): a sweep CSV from the
// binary becomes one PNG per varied key, a precision run folder its curve; bad input is one line.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "testbench/image_io.h"
#include "testbench/testing.h"

namespace saarcor {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Runs the script; returns its exit status, its output in `out`.
int plot(const std::string& args, std::string& out) {
  const fs::path log = test_support::scratch_dir("plot") / "plot.log";
  const std::string cmd = std::string(SAARCOR_SYSTEM_PYTHON) + " " + SAARCOR_SOURCE_DIR +
                          "/scripts/plot_sweep.py " + args + " >" + log.string() + " 2>&1";
  const int rc = std::system(cmd.c_str());
  out = slurp(log);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

void expect_png(const fs::path& p, int width, int height) {
  ASSERT_TRUE(fs::exists(p)) << p;
  EXPECT_EQ(slurp(p).substr(0, 8), "\x89PNG\r\n\x1a\n") << p;
  const Rgb8Image img = read_rgb8(p.string());
  EXPECT_EQ(img.width, width) << p;
  EXPECT_EQ(img.height, height) << p;
}

TEST(PlotSweep, OnePngPerVariedKey) {
  const fs::path d = test_support::scratch_dir("plot_sweep");
  fs::remove_all(d);
  const fs::path csv = d / "sweep.csv";
  const test_support::CliRun r = test_support::run_saarcor(
      "sweep builtin:cube --res 16x12 --vary threads=1,4,16 --vary packet=4,16 --csv " +
      csv.string());
  ASSERT_EQ(r.status, 0) << r.err;
  std::string out;
  ASSERT_EQ(plot(csv.string() + " --out-dir " + (d / "figures").string(), out), 0) << out;
  // 11 x 7.5 inches at 100 dpi.
  expect_png(d / "figures" / "sweep_threads.png", 1100, 750);
  expect_png(d / "figures" / "sweep_packet.png", 1100, 750);
  EXPECT_EQ(out, (d / "figures" / "sweep_threads.png").string() + "\n" +
                     (d / "figures" / "sweep_packet.png").string() + "\n");
  // The same CSV gives the same bytes.
  const std::string first = slurp(d / "figures" / "sweep_threads.png");
  ASSERT_EQ(plot(csv.string() + " --out-dir " + (d / "again").string(), out), 0) << out;
  EXPECT_EQ(slurp(d / "again" / "sweep_threads.png"), first);
}

// A sweep with --pareto: its CSV has the cost columns and pareto_luts, and the script draws frame
// rate against the LUT estimate with the front besides the per-key figures; --cost names other
// costs, one panel each.
TEST(PlotSweep, ParetoFigureFromASweepWithCost) {
  const fs::path d = test_support::scratch_dir("plot_pareto");
  fs::remove_all(d);
  const fs::path csv = d / "sweep.csv";
  const test_support::CliRun r = test_support::run_saarcor(
      "sweep builtin:cube --res 16x12 --vary threads=1,4 --vary packet=4,16 --pareto --csv " +
      csv.string());
  ASSERT_EQ(r.status, 0) << r.err;
  std::string out;
  ASSERT_EQ(plot(csv.string() + " --out-dir " + (d / "figures").string(), out), 0) << out;
  // One panel: 6.5 x 5.5 inches at 100 dpi.
  expect_png(d / "figures" / "sweep_pareto.png", 650, 550);
  EXPECT_EQ(out, (d / "figures" / "sweep_threads.png").string() + "\n" +
                     (d / "figures" / "sweep_packet.png").string() + "\n" +
                     (d / "figures" / "sweep_pareto.png").string() + "\n");
  ASSERT_EQ(plot(csv.string() + " --cost luts,block_rams --out-dir " + (d / "two").string(), out),
            0)
      << out;
  expect_png(d / "two" / "sweep_pareto.png", 1300, 550);
  EXPECT_EQ(plot(csv.string() + " --cost area --out-dir " + (d / "bad").string(), out), 1);
  EXPECT_EQ(out,
            "plot_sweep.py: error: bad --cost 'area': expected cost columns among fp_units, "
            "memory_kb, luts, block_rams\n");
  EXPECT_FALSE(fs::exists(d / "bad" / "sweep_threads.png"));  // checked before any figure
}

// The script's front for another cost than the CSV's: the rule of saarcor sweep --pareto, on the
// hand-computed front of testbench/sweep_cost_test.cpp (SweepPareto.HandComputedFronts).
TEST(PlotSweep, ScriptsParetoRuleIsTheBinarys) {
  const fs::path d = test_support::scratch_dir("plot_rule");
  const fs::path py = d / "rule.py";
  std::ofstream(py) << "import importlib.util, sys\n"
                       "spec = importlib.util.spec_from_file_location('plot_sweep', sys.argv[1])\n"
                       "m = importlib.util.module_from_spec(spec)\n"
                       "spec.loader.exec_module(m)\n"
                       "print(m.pareto_front([(10, 100), (20, 100), (20, 100), (5, 50), "
                       "(15, 200), (30, 300), (30, 250)]))\n";
  const fs::path log = d / "rule.log";
  const std::string cmd = std::string(SAARCOR_SYSTEM_PYTHON) + " " + py.string() + " " +
                          SAARCOR_SOURCE_DIR + "/scripts/plot_sweep.py >" + log.string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << slurp(log);
  EXPECT_EQ(slurp(log), "[False, True, True, True, False, False, True]\n");
}

TEST(PlotSweep, PrecisionCurveFromARunFolder) {
  const fs::path d = test_support::scratch_dir("plot_precision");
  fs::remove_all(d);
  const test_support::CliRun r = test_support::run_saarcor(
      "precision builtin:cube --res 16x12 --mantissa 14..16 --out-dir " + (d / "run").string());
  ASSERT_EQ(r.status, 0) << r.err;
  std::string out;
  ASSERT_EQ(plot((d / "run").string(), out), 0) << out;
  expect_png(d / "run" / "precision_curve.png", 800, 500);
}

TEST(PlotSweep, BadInputIsOneLine) {
  const fs::path d = test_support::scratch_dir("plot_bad");
  std::ofstream(d / "shard.csv") << "point,points,threads,cycles\n0,2,1,100\n";
  std::string out;
  EXPECT_EQ(plot((d / "shard.csv").string(), out), 1);
  EXPECT_EQ(out, "plot_sweep.py: error: " + (d / "shard.csv").string() +
                     ": a shard CSV: merge the shards first (saarcor sweep-merge)\n");
  EXPECT_EQ(plot((d / "none.csv").string(), out), 1);
  EXPECT_EQ(out, "plot_sweep.py: error: " + (d / "none.csv").string() + ": no such file\n");
}

}  // namespace
}  // namespace saarcor
