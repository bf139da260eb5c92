// --out-dir: the command line and stats.txt formats, and the product end to end: `saarcor render`,
// `sweep` and `precision` run twice into two folders write the same bytes in every file but
// host.json (and command.txt, which names the folder), hit EXR and float EXR included, with
// report, configuration and statistics that agree with each other.
#include "testbench/report.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include "testbench/render_cmd.h"
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

std::set<std::string> names_in(const fs::path& d) {
  std::set<std::string> n;
  for (const auto& e : fs::directory_iterator(d))
    n.insert(e.path().filename().string());
  return n;
}

// Runs `args --out-dir A`, waits past a second boundary (a date stamp would change), runs
// `args --out-dir B`, and checks every file but host.json and command.txt is byte-identical.
void expect_rerun_identical(const std::string& tag, const std::string& args,
                            const std::set<std::string>& files) {
  const fs::path d = test_support::scratch_dir(tag);
  fs::remove_all(d);
  const fs::path a = d / "a", b = d / "b";
  test_support::CliRun r = test_support::run_saarcor(args + " --out-dir " + a.string());
  ASSERT_EQ(r.status, 0) << r.err;
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  r = test_support::run_saarcor(args + " --out-dir " + b.string());
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_EQ(names_in(a), files);
  ASSERT_EQ(names_in(b), files);
  for (const std::string& f : files) {
    if (f == "host.json" || f == "command.txt") continue;
    // The journal's first record holds the command line (the folder's name); its others, the
    // points or frames, must match.
    const auto body = [&](const fs::path& p) {
      const std::string t = slurp(p);
      return f == "journal.txt" ? t.substr(t.find('\n') + 1) : t;
    };
    EXPECT_EQ(body(a / f), body(b / f)) << f << " differs between two runs of " << args;
  }
  // command.txt is the command line: the same but for the folder's name.
  EXPECT_EQ(slurp(a / "command.txt"),
            std::string(SAARCOR_BIN_DIR) + "/saarcor " + args + " --out-dir " + a.string() + "\n");
}

nlohmann::json read_json(const fs::path& p) {
  std::ifstream f(p);
  return nlohmann::json::parse(f);
}

// Every statistic of stats.txt carries a description and a unit from its declaration:
// "name  value  # description (unit)".
void expect_every_line_declared(const std::string& stats) {
  std::istringstream in(stats);
  std::size_t checked = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line.starts_with("----------") || line.starts_with("# ")) continue;
    const std::size_t hash = line.find("  # ");
    ASSERT_NE(hash, std::string::npos) << line;
    const std::string desc = line.substr(hash + 4);
    EXPECT_TRUE(desc.size() > 4 && desc.back() == ')' && desc.find(" (") != std::string::npos &&
                desc.find(" (") > 0)
        << line;
    ++checked;
  }
  EXPECT_GT(checked, 0u);
}

// Every configuration's keys come from the parameter tables through parameters_json: the cycle
// keys with the unit depths they give, the kd-tree keys, each with its declared unit and help.
TEST(RunDir, ConfigurationKeysComeFromTheParameterTables) {
  const units::CycleParams cycle;
  const host::ImageParams trees;
  const nlohmann::json both = parameters_json(&cycle, &trees);
  EXPECT_EQ(both["threads"]["value"], 64);  // the prototype's defaults
  EXPECT_FALSE(both["threads"]["help"].get<std::string>().empty());
  EXPECT_EQ(both["depth.traversal"], cycle.traversal_depth());
  EXPECT_EQ(both["kd.traversal_cost"]["value"], 30);
  EXPECT_EQ(parameters_json(nullptr, &trees).count("threads"), 0u);
  EXPECT_EQ(parameters_json(nullptr, &trees)["kd.traversal_cost"], both["kd.traversal_cost"]);
  EXPECT_TRUE(parameters_json(nullptr, nullptr).empty());
  // A frame sequence's config.json holds the same keys (depth.* included) as the cycle report.
  RenderSettings s = frame_settings("8x6", 0.0, false, 0, 4.0);
  const nlohmann::json seq = sequence_configuration_json(0.0, s, true);
  EXPECT_EQ(seq["cycle"], parameters_json(&cycle, nullptr));
  EXPECT_EQ(seq["trees"], parameters_json(nullptr, &trees));
}

TEST(RunDir, CommandLineQuotesWhatAShellWouldSplit) {
  EXPECT_EQ(command_line_text({"saarcor", "render", "builtin:room", "--res", "64x48"}),
            "saarcor render builtin:room --res 64x48\n");
  EXPECT_EQ(command_line_text({"saarcor", "render", "my scene.glb", "--set", "a=b;c", "it's", ""}),
            "saarcor render 'my scene.glb' --set 'a=b;c' 'it'\\''s' ''\n");
}

TEST(RunDir, StatsTextIsGem5Style) {
  const std::string s = stats_text({{"frame.cycles", 34755, "simulated cycles", "cycles"},
                                    {"frame.fps", 2589.5554603, "frames per second", ""}});
  EXPECT_EQ(s,
            "\n---------- Begin Simulation Statistics ----------\n"
            "frame.cycles                                                            34755  # "
            "simulated cycles (cycles)\n"
            "frame.fps                                                         2589.555460  # "
            "frames per second\n"
            "\n---------- End Simulation Statistics   ----------\n");
}

TEST(RunDir, RenderRerunGivesTheSameBytes) {
  const std::string args = "render builtin:room --model cycle --res 48x32 --hits --exr";
  expect_rerun_identical("rundir_render", args,
                         {"image.png", "image.exr", "hits.exr", "report.json", "stats.txt",
                          "config.json", "command.txt", "host.json"});
  const fs::path a = test_support::scratch_dir("rundir_render") / "a";
  const nlohmann::json report = read_json(a / "report.json");
  const nlohmann::json config = read_json(a / "config.json");
  const nlohmann::json host = read_json(a / "host.json");
  // Host timing lives in host.json only.
  EXPECT_FALSE(report.contains("host"));
  EXPECT_FALSE(report.contains("seconds"));
  EXPECT_FALSE(report["configuration"].contains("load_seconds"));
  EXPECT_GT(host["seconds"].get<double>(), 0.0);
  EXPECT_GT(host["cycle_model"]["sim_cycles_per_s"].get<double>(), 0.0);
  // config.json is the report's resolved configuration: every cycle key at its default, the
  // tree keys, the frame.
  EXPECT_EQ(config["cycle"], report["configuration"]["cycle"]);
  EXPECT_EQ(config["cycle"]["threads"]["value"], 64);
  EXPECT_EQ(config["cycle"]["cache.list.items"]["value"], 512);
  EXPECT_EQ(config["cycle"]["kd.traversal_cost"]["value"], 30);
  EXPECT_EQ(config["resolution"]["width"], 48);
  EXPECT_EQ(config["model"], "cycle");
  EXPECT_EQ(report["outputs"]["hits"], "hits.exr");
  // stats.txt carries the report's figures and the registry, one per line.
  const std::string stats = slurp(a / "stats.txt");
  char line[160];
  std::snprintf(line, sizeof line, "\nframe.cycles %*llu  # simulated cycles of the frame", 64,
                report["cycles"].get<unsigned long long>());
  EXPECT_NE(stats.find(line), std::string::npos) << stats.substr(0, 400);
  std::size_t lines = 0;
  for (const auto& [name, s] : report["stats"].items()) {
    ++lines;
    EXPECT_NE(stats.find("\n" + name + " "), std::string::npos) << name;
  }
  EXPECT_GT(lines, 20u);
  expect_every_line_declared(stats);
}

TEST(RunDir, FunctionalRenderListsItsCountersAndTrees) {
  const fs::path d = test_support::scratch_dir("rundir_fp24");
  fs::remove_all(d);
  const test_support::CliRun r =
      test_support::run_saarcor("render builtin:cube --res 16x12 --out-dir " + d.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(names_in(d), (std::set<std::string>{"image.png", "report.json", "stats.txt",
                                                "config.json", "command.txt", "host.json"}));
  const nlohmann::json config = read_json(d / "config.json");
  EXPECT_EQ(config["trees"]["kd.traversal_cost"]["value"], 30);
  EXPECT_EQ(config["image_format"], "Float<7,16> (e7m16)");
  const std::string stats = slurp(d / "stats.txt");
  EXPECT_NE(stats.find("\nrays "), std::string::npos);
  EXPECT_NE(stats.find("ops.intersection.div"), std::string::npos);
  EXPECT_NE(stats.find("# ray-triangle intersection tests, per ray (tests/ray)"),
            std::string::npos);
  expect_every_line_declared(stats);
}

TEST(RunDir, SweepRerunGivesTheSameBytes) {
  expect_rerun_identical("rundir_sweep",
                         "sweep builtin:cube --res 16x12 --vary threads=1,4 --jobs 2",
                         {"sweep.csv", "report.json", "stats.txt", "config.json", "command.txt",
                          "host.json", "journal.txt"});
  const fs::path a = test_support::scratch_dir("rundir_sweep") / "a";
  const nlohmann::json config = read_json(a / "config.json");
  ASSERT_EQ(config["points"].size(), 2u);
  EXPECT_EQ(config["points"][1]["configuration"]["threads"]["value"], 4);
  EXPECT_EQ(config["vary"][0]["key"], "threads");
  EXPECT_EQ(read_json(a / "host.json")["jobs"], 2);
  EXPECT_FALSE(read_json(a / "report.json")["points"][0]["report"].contains("host"));
  const std::string stats = slurp(a / "stats.txt");
  EXPECT_NE(stats.find("# point 2 of 2: threads=4\n"), std::string::npos) << stats.substr(0, 300);
  expect_every_line_declared(stats);
}

TEST(RunDir, PrecisionRerunGivesTheSameBytes) {
  expect_rerun_identical(
      "rundir_precision", "precision builtin:cube --res 16x12 --mantissa 15..16",
      {"precision.png", "report.json", "stats.txt", "config.json", "command.txt", "host.json"});
  const fs::path a = test_support::scratch_dir("rundir_precision") / "a";
  EXPECT_EQ(read_json(a / "config.json")["mantissa"]["to"], 16);
  EXPECT_EQ(read_json(a / "host.json")["rows"].size(), 2u);
  EXPECT_NE(slurp(a / "stats.txt").find("e7m16.same_triangle_pct"), std::string::npos);
}

TEST(RunDir, OutDirNamesEveryFile) {
  const fs::path d = test_support::scratch_dir("rundir_bad");
  test_support::expect_one_line_error(
      test_support::run_saarcor("render builtin:cube --res 8x8 --out-dir " + d.string() +
                                " --report r.json"),
      "--out-dir names every file it writes");
  test_support::expect_one_line_error(
      test_support::run_saarcor("render builtin:cube --res 8x8 --out x --out-dir " + d.string()),
      "--out-dir names every file it writes");
  test_support::expect_one_line_error(
      test_support::run_saarcor("render builtin:cube --res 8x8 --hits"),
      "bad --hits: expected a file name FILE.exr (or --out-dir DIR)");
  test_support::expect_one_line_error(
      test_support::run_saarcor("sweep builtin:cube --vary threads=1 --csv a.csv --out-dir " +
                                d.string()),
      "drop --csv and --report");
  test_support::expect_one_line_error(
      test_support::run_saarcor("precision builtin:cube --out p --out-dir " + d.string()),
      "drop --out");
  std::ofstream(d / "file") << "x";
  test_support::expect_one_line_error(
      test_support::run_saarcor("render builtin:cube --out-dir " + (d / "file").string()),
      "a file of that name exists");
}

}  // namespace
}  // namespace saarcor
