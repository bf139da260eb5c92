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
