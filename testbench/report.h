// The report module (STYLE.md habits 4 and 5; gem5's statistics and its m5out writer): every
// statistic a report writes is declared once, with its dotted name, unit and description, next to
// the formula that gives its value; the JSON reports, stats.txt and the run folder of every
// command (render, render --frames, sweep, precision) are written here from those declarations.
// The counters themselves are declared where they are counted (units/program_types.h
// CounterDecl, units/functional_model.h, the hw/ registry, units/figures.h); this module names
// their places in the reports.
//
// The run folder of --out-dir: one folder per run holding everything a person keeps of it: the
// images, the report (report.json), every statistic one per line (stats.txt, gem5 style: name,
// value, description and unit), every configuration key resolved (config.json), the command line
// (command.txt) and, apart from the rest, the host's wall-clock figures (host.json). Rerunning the
// same command rewrites every file but host.json with the same bytes (docs/runs.md), so `diff -r`
// of two runs shows only what changed.
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "fixedfloat/format.h"
#include "host/float_reference.h"
#include "host/image_builder.h"
#include "testbench/chip.h"
#include "units/cost.h"
#include "units/figures.h"
#include "units/functional_model.h"

namespace saarcor {

struct FrameResult;
struct PreparedScene;
struct RenderSettings;
struct SequenceFrame;
struct SequenceResult;
struct PaperFigure;
struct PrecisionRow;
struct SweepOptions;
struct SweepPoint;
struct SweepResult;
struct SceneOptions;
struct SceneImage;
struct CompareResult;

// ---- statistics and their declarations ---------------------------------------------------------

// One statistic of a report: its dotted place in the JSON report (and, prefixed, its stats.txt
// name), its unit, its description and its value (an integer or a double, as the report writes).
struct ReportStat {
  std::string name;
  std::string unit;
  std::string desc;
  nlohmann::json value;
};

// The statistics as one JSON object, each at its dotted place ("usage.list" -> {"usage":
// {"list": v}}).
nlohmann::json nest(const std::vector<ReportStat>& stats);
// The value at a dotted place of a JSON object (null when it is not there).
const nlohmann::json& json_at(const nlohmann::json& j, const std::string& dotted);

// One line of stats.txt.
struct StatLine {
  std::string name;
  double value = 0.0;
  std::string desc;
  std::string unit;
};
// The statistics as stats.txt lines, named `prefix` + name.
std::vector<StatLine> stat_lines(const std::vector<ReportStat>& stats,
                                 const std::string& prefix = "");
// gem5's stats.txt layout: "name  value  # description (unit)", one statistic a line, between the
// begin/end markers; integers print as integers, other values with six decimals.
std::string stats_text(const std::vector<StatLine>& lines);
// Several dumps in one file (a sweep: one per point), each block headed by its `# title` line.
std::string stats_text_blocks(const std::vector<std::pair<std::string, std::vector<StatLine>>>& b);

// ---- the models' counters (FrameResult::counters) ----------------------------------------------

// The functional model's counters: per ray kind the per-ray counters (total and per ray), rays
// issued and returned; per unit its float ops; the units' own step counts. `rays` gets the rays
// of every kind.
std::vector<ReportStat> functional_counter_stats(const units::FunctionalFrame& frame,
                                                 std::uint64_t& rays);
// The float reference's counters of primary rays (binary32 ops are not counted).
std::vector<ReportStat> float_counter_stats(const host::FloatTraceStats& s);
// The float units' op counts, per unit (ops.traversal.add, ..., ops.rgs.total).
std::vector<ReportStat> op_stats(const units::UnitStats& u);

// ---- the cycle model's frame report ------------------------------------------------------------

// The frame's statistics as the report writes them: cycles, fps, rays, rates, the Table 4 figures
// (units/figures.h), the RGS's traffic, per-ray counters, per-unit and per-cache counts.
std::vector<ReportStat> cycle_stats(const CycleFrame& frame);
// The per-frame report: cycle_stats, host, pipelines, configuration (the cycle keys and, given
// `trees`, the kd-tree keys the image was built with: parameters_json), the hw/ registry (stats),
// (time_series).
nlohmann::json cycle_report_json(const CycleFrame& frame, const host::ImageParams* trees = nullptr);
// stats.txt's lines of a cycle report (as cycle_report_json wrote it; a sweep's points travel as
// JSON): each frame statistic as "frame.NAME" with its declaration's description and unit, then
// every statistic of the hw/ registry with its own.
std::vector<StatLine> cycle_stat_lines(const nlohmann::json& cycle);

// ---- frame sequences (render --frames N) -------------------------------------------------------

// The per-frame rows' columns and the summary's statistics are each declared once (kRowColumns,
// kSummaryColumns in report.cpp). The report (host timing only with host_times: each frame's
// top-level rebuild on this host, which a run folder keeps in host.json) and the CSV of the frames
// (no host timing), both from the per-frame rows' one declaration; the bus sweep's report (one
// sequence report per bandwidth).
nlohmann::json sequence_json(const SequenceResult& r, bool host_times = false);
std::string sequence_csv(const SequenceResult& r);
nlohmann::json bus_sweep_json(const std::vector<SequenceResult>& points);
// The printed per-frame table (with the host's rebuild times) and summary, and the bus sweep's
// table (a row per bandwidth: its summary statistics), from the same declarations as the JSON,
// the CSV and stats.txt.
std::string sequence_table(const SequenceResult& r);
std::string bus_sweep_table(const std::vector<SequenceResult>& points);
// host.json of a sequence: each frame's host seconds and top-level rebuild seconds, and the
// largest rebuild after frame 0.
nlohmann::json sequence_host_json(const SequenceResult& r);
// config.json of a sequence: the frame settings, the cycle keys (cycle model) and the tree keys.
nlohmann::json sequence_configuration_json(double time, const RenderSettings& s, bool cycle);
// stats.txt's lines of a sequence: its summary ("sequence.NAME") and every frame's row
// ("frameK.NAME"), each with its declaration's description and unit.
std::vector<StatLine> sequence_stat_lines(const SequenceResult& r);

// ---- sweeps -----------------------------------------------------------------------------------

// The points of a result as JSON ({"index", "settings", "cycle"} each) and back: what MPI ranks
// send rank 0 (doubles survive the round trip bit for bit); a rank's message (its points, or its
// error).
nlohmann::json sweep_points_json(const SweepResult& sweep);
std::vector<SweepPoint> sweep_points_from_json(const nlohmann::json& j);
nlohmann::json sweep_rank_message(const std::string& error, const SweepResult& sweep);
// A sweep point's cost (units/cost.h, docs/cost.md), its statistics declared once in report.cpp
// with name, unit and description: {"fp_units", "memory_kb", "luts", "block_rams"} of the chip.
nlohmann::json sweep_cost_json(const units::CostParams& params);

// ---- cost (saarcor cost, saarcor paper --table 1|2) -------------------------------------------

// `saarcor cost --json`'s report: units.<unit>.{add,mul,div,cmp,sqrt,memory_bits,memory_kb,luts,
// mult18x18,block_rams,memory[],memory_by_kind}, total.{...}, flops, table1.<ratio>.{without_
// traversal,full,paper_*}; with `table2` also table2.<unit>.{model,paper,ratio}.
nlohmann::json cost_report_json(const units::CostParams& params, bool table2);
// Those statistics' names, in column order (what --pareto-cost takes).
std::vector<std::string> sweep_cost_names();
// stats.txt's lines of one point: cycle_stat_lines, then "cost.NAME" for each cost statistic and,
// with `pareto`, "cost.pareto" (1 on the front).
std::vector<StatLine> sweep_point_stat_lines(const SweepPoint& p, bool pareto);
// The printed table, the CSV text (a shard's with the columns point and points first) and the
// JSON report of a sweep; the table's and the CSV's columns are statistics of the points' frame
// reports, named as cycle_stats declares them, then the cost statistics and, when the sweep marked
// its Pareto front, the column pareto_<cost> (1 on the front; '*' in the table).
std::string sweep_table(const SweepResult& sweep);
std::string sweep_csv(const SweepResult& sweep);
nlohmann::json sweep_json(const SweepResult& sweep, const SweepOptions& opts);
// The front's points, cheapest first, one line each (cost, fps, settings); empty without --pareto.
std::string sweep_pareto_text(const SweepResult& sweep);
// --out-dir for a sweep: the CSV, the report without host timing (host.json has it), each point's
// resolved configuration (config.json), each point's statistics as one block (stats.txt) and the
// command line.
void write_sweep_folder(const SweepOptions& opts, const SweepResult& sweep,
                        const RenderSettings& rs, int jobs, int ranks);

// ---- precision ------------------------------------------------------------------------------

// `saarcor precision`'s report (a row per format: same-triangle share, PSNR, t errors, mismatch
// classes) to `json`; with `out_dir` the run folder too (the rows' seconds in host.json).
void write_precision_report(const std::string& json, const std::string& out_dir,
                            const std::string& scene, const RenderSettings& settings, int lo,
                            int hi, const std::vector<PrecisionRow>& rows,
                            const std::vector<std::string>& argv);

// ---- the paper's tables ---------------------------------------------------------------------

// One table's figures for the paper's scene `paper` (Table 3: fps, cycles per packet, Mrays/s;
// Table 4: fps, the four usages, three hit rates, DynRTC, shading and total MB/s, those two and
// the shading bytes per pixel), each the model's, read from the frame's cycle report by its
// declared name, beside the paper's. The frame ran at width x height (the table's resolution over
// --scale): its fps is the one the table's frame would have, scaled by their pixels.
std::vector<PaperFigure> paper_figures(int table, const std::string& paper,
                                       const nlohmann::json& cycle, int width, int height);
// One table's entry for one scene of `saarcor paper`: the scene, the frame's resolution, each
// figure beside the paper's with their ratio (paper_figures), the settings and the model's whole
// cycle report.
nlohmann::json paper_entry_json(int table, const std::string& paper, const std::string& scene,
                                bool reference, int width, int height,
                                const std::vector<std::string>& settings,
                                const nlohmann::json& cycle);
// The tables' result: the entries, scene after scene (moved out of `per_scene`).
nlohmann::json paper_tables_json(int scale, const std::vector<std::string>& set,
                                 std::vector<nlohmann::json>& per_scene);
// The thread curve: per thread count its fps, speed-up, speed-up per doubling beside the paper's
// and the units' usage, from each count's cycle report.
nlohmann::json thread_curve_json(const std::vector<int>& counts,
                                 const std::vector<nlohmann::json>& reports,
                                 const std::string& resolution);

// ---- scene and compare ------------------------------------------------------------------------

// `saarcor scene --json` (the printout reads it too): the scene's counts, both kd-tree levels'
// statistics (per bottom tree and summed), the bytes per bank or why the image does not build.
nlohmann::json scene_report_json(const SceneOptions& options, const host::Scene& scene,
                                 double load_seconds, const SceneImage& image);
// `saarcor compare --report`: keys pixels, same_triangle_pct, bit_identical, t_rel_err_max,
// t_rel_err_median, psnr_db, max_channel_diff, mismatches (and a few more, docs/compare.md).
nlohmann::json compare_report_json(const CompareResult& r);

// ---- the run folder ----------------------------------------------------------------------------

// The command line as one shell line ending in '\n': words with characters outside
// [A-Za-z0-9_@%+=:,./-] are single-quoted, so pasting it reruns the same command.
std::string command_line_text(const std::vector<std::string>& argv);

// Checks DIR can be the run folder (not an existing file); throws "bad --out-dir 'DIR': ...".
void check_out_dir(const std::string& dir);
// DIR/name.
std::string run_file(const std::string& dir, const std::string& name);

// The one place host timing lives: removes every wall-clock figure (and the host's thread setup)
// from a cycle report and returns them as an object (its "host" entry).
nlohmann::json take_cycle_host(nlohmann::json& cycle);

// What one run folder holds besides its images: the files every command writes, and the
// command's own tables (sweep.csv, frames.csv) as {file name, text}.
struct RunFolder {
  std::string dir;
  nlohmann::json report;  // report.json: without host timing
  nlohmann::json config;  // config.json: every key resolved
  nlohmann::json host;    // host.json: the wall-clock figures
  std::string stats;      // stats.txt (stats_text or stats_text_blocks)
  std::vector<std::string> argv;
  std::vector<std::pair<std::string, std::string>> tables;
};
// Writes the folder's files: the tables, report.json, stats.txt, config.json, command.txt,
// host.json (the one writer of every command's run folder).
void write_run_folder(const RunFolder& folder);
// The file names write_run_folder writes, as {key, path} in `outputs` (the report's "outputs").
void list_run_folder(const RunFolder& folder,
                     std::vector<std::pair<std::string, std::string>>& outputs);

// ---- render ------------------------------------------------------------------------------------

// "Float<7,16> (e7m16)".
std::string describe_format(ff::Format f);
// The parameter tables' keys resolved (hw::ParamTable): the cycle keys with the unit depths they
// give (`cycle`), the kd-tree builder's keys (`trees`), each {"KEY": {value, unit, help}} as its
// table declares it. The one builder of the keys every config.json and every report's
// configuration holds (the render, sequence, precision and sweep folders, the cycle report).
nlohmann::json parameters_json(const units::CycleParams* cycle, const host::ImageParams* trees);
// `saarcor render`'s report: the scene, model, resolution, host time, rays, the model's counters,
// the configuration (frame, image, trees or cycle keys) and, with the cycle model, its frame
// report's figures at the top.
nlohmann::json render_report_json(const std::string& scene, const std::string& model,
                                  const FrameResult& frame, const PreparedScene& prep,
                                  const RenderSettings& settings);
// --report FILE: the report with the outputs' paths, added to `outputs`.
void write_render_report(const std::string& path, nlohmann::json report,
                         std::vector<std::pair<std::string, std::string>>& outputs);
// --out-dir DIR: the report without host timing, which goes to host.json; the configuration
// alone; every statistic one per line; the command line. File names in the report are relative
// to the folder, so a run folder reads the same wherever it is moved.
void write_render_folder(const std::string& dir, nlohmann::json report, const FrameResult& frame,
                         const std::vector<std::string>& argv,
                         std::vector<std::pair<std::string, std::string>>& outputs);

}  // namespace saarcor
