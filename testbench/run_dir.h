// `--out-dir DIR` (STYLE.md habit 5, gem5's m5out): one folder per run of `saarcor render`,
// `sweep` or `precision` holding everything a person keeps of it: the images, the report
// (report.json), every statistic one per line (stats.txt, gem5 style), every configuration key
// resolved (config.json), the command line (command.txt) and, apart from the rest, the host's
// wall-clock figures (host.json). Rerunning the same command rewrites every file but host.json
// with the same bytes (docs/runs.md), so `diff -r` of two runs shows only what changed.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace saarcor {

// The command line as one shell line ending in '\n': words with characters outside
// [A-Za-z0-9_@%+=:,./-] are single-quoted, so pasting it reruns the same command.
std::string command_line_text(const std::vector<std::string>& argv);

// One line of stats.txt.
struct StatLine {
  std::string name;
  double value = 0.0;
  std::string desc;
};
// gem5's stats.txt layout: "name  value  # description", one statistic a line, between the
// begin/end markers; integers print as integers, other values with six decimals.
std::string stats_text(const std::vector<StatLine>& lines);
// Several dumps in one file (a sweep: one per point), each block headed by its `# title` line.
std::string stats_text_blocks(const std::vector<std::pair<std::string, std::vector<StatLine>>>& b);

// A cycle report's (cycle_report_json) headline figures (cycles, fps, usage, hit rates,
// bandwidth, per ray) and then every statistic of the hw/ registry with its description and unit.
void append_cycle_stats(std::vector<StatLine>& lines, const nlohmann::json& cycle);
// The float and functional models' counters (FrameResult::counters): per-ray totals, op counts
// and unit step counts, each with its description.
void append_counter_stats(std::vector<StatLine>& lines, const nlohmann::json& counters);

// Checks DIR can be the run folder (not an existing file); throws "bad --out-dir 'DIR': ...".
void check_out_dir(const std::string& dir);
// DIR/name.
std::string run_file(const std::string& dir, const std::string& name);

// The one place host timing lives: removes every wall-clock figure (and the host's thread setup)
// from a cycle report and returns them as an object (its "host" entry).
nlohmann::json take_cycle_host(nlohmann::json& cycle);

}  // namespace saarcor
