// `saarcor sweep`: design-space exploration with the cycle model. One scene is loaded and its
// memory image built once; the cycle model then runs a frame for every point of the cartesian
// product of the --vary lists (on top of --preset and --set), and every point's hit records and
// image are checked bit for bit against the functional fp24 model on the same image: timing may
// change, results never do. Prints one row per point (cycles, fps, speed-up over the
// first point, the paper's Table 4 columns), and writes the same as JSON and CSV
// (docs/cycle-model.md, "Sweeps").
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "testbench/render_cmd.h"

namespace saarcor {

// One --vary KEY=V1,V2,...: a cycle-model key (docs/cycle-model.md) and its values as given.
struct SweepAxis {
  std::string key;
  std::vector<std::string> values;
};
// Parses "KEY=V1,V2,..."; throws "bad --vary 'TEXT': ..." on a missing key, an empty value or a
// repeated value. The values themselves are checked by the cycle model's key table (sweep_points).
SweepAxis parse_sweep_axis(const std::string& text);

// The points of the product, first axis slowest; each point is the KEY=VALUE list its frame adds
// to the --set overrides. Every point's whole configuration is resolved (and so checked) here,
// before any frame runs. Throws on a repeated key, a bad value or more than kMaxSweepPoints points.
inline constexpr std::size_t kMaxSweepPoints = 256;
std::vector<std::vector<std::string>> sweep_points(const std::vector<SweepAxis>& axes,
                                                   const CycleRenderOptions& base);

struct SweepOptions {
  std::string scene;
  std::string model = "cycle";    // or cycle-e7m23 (the image and the reference in e7m23)
  std::vector<std::string> vary;  // --vary KEY=V1,V2,... (repeatable)
  std::string res = "128x96";
  double time = 0.0;
  bool shadows = false;
  int depth = 0;
  double bank_mb = 4.0;
  std::string preset = "prototype";
  std::vector<std::string> set;
  int host_threads = 0;
  // --sample [SPEC]: every point sampled (testbench/sampling.h), its simulated packets checked
  // against the functional model instead of the whole frame.
  bool sample = false;
  std::string sample_spec;
  std::string report;  // JSON path, optional
  std::string csv;     // CSV path, optional
  // Frames at once on this host (worker threads); 0 = the hardware's cores (under MPI: the cores
  // over the ranks on this host). The rows are the same for every count.
  int jobs = 0;
  std::string shard;  // "K/N": only the points of shard K of N (1 <= K <= N), for array jobs
  // --out-dir DIR (testbench/report.h write_run_folder): sweep.csv, report.json, stats.txt,
  // config.json, command.txt, host.json; --csv and --report are refused with it.
  std::string out_dir;
  std::vector<std::string> argv;  // the command line, for command.txt
  // --resume DIR: the run folder of a sweep that was stopped (testbench/run_journal.h): only the
  // points its journal lacks run, and the folder ends as an uninterrupted run leaves it. Implies
  // --out-dir DIR.
  std::string resume;
  // --pareto: mark the points no other point beats in both frame rate (higher is better) and
  // cost (lower is better); --pareto-cost names the cost (a cost column: luts, the default,
  // block_rams, memory_kb, fp_units) and implies --pareto.
  bool pareto = false;
  std::string pareto_cost;
};

// (bugprone-exception-escape: nlohmann::json's default constructor is not declared noexcept; a
// null json allocates nothing.)
struct SweepPoint {                   // NOLINT(bugprone-exception-escape)
  std::size_t index = 0;              // the point's place in the whole sweep (0-based)
  std::vector<std::string> settings;  // the KEY=VALUE the point adds
  nlohmann::json cycle;               // the frame's cycle report (cycle_report_json)
  nlohmann::json cost;                // the configuration's cost (sweep_cost_json)
  double speedup = 1.0;               // the first point's cycles over this point's
  bool pareto = false;                // on the Pareto front (mark_pareto)
};
struct SweepResult {
  std::vector<SweepAxis> axes;
  std::vector<SweepPoint> points;
  std::string functional_model;       // the reference: "fp24", or "e7m23" for cycle-e7m23
  std::uint64_t functional_rays = 0;  // its frame's rays
  // A shard holds every `shards`-th point from `shard` on (points i with i % shards == shard) of
  // the sweep's `total_points`; its CSV starts with the columns point and points, which
  // merge_sweep_csv needs. One shard of one is the whole sweep.
  std::size_t shard = 0;
  std::size_t shards = 1;
  std::size_t total_points = 0;
  std::string pareto_cost;  // the cost the front was marked against (mark_pareto); empty: none
};

// How run_sweep_points runs: `jobs` frames at once, the points of one shard.
struct SweepRun {
  int jobs = 1;
  std::size_t shard = 0;
  std::size_t shards = 1;
  bool heartbeat = true;  // points done / total on the terminal (testbench/heartbeat.h)
  // Points already finished (a resumed run's journal), by index: not run again, returned as they
  // are. A group of points with other trees whose points are all here builds no image.
  std::map<std::size_t, SweepPoint> finished;
  // Called with each point as it finishes (from the worker that ran it; serialised by the callee).
  std::function<void(const SweepPoint&)> on_point;
};
// "K/N" with 1 <= K <= N <= kMaxSweepPoints -> {K - 1, N}; throws "bad --shard 'TEXT': ...".
std::pair<std::size_t, std::size_t> parse_shard(const std::string& text);

// Throws "sweep point WHERE: ..." unless the cycle model's frame has the reference's hit records
// (every bit), image and ray count.
void check_sweep_point(const FrameResult& frame, const FrameResult& reference,
                       const std::string& where);

// Runs every point of the run's shard, `run.jobs` frames at once (the model keeps no global state:
// each frame owns its kernel, units and caches and reads the shared memory image). With jobs > 1
// each frame's thread programs run on its worker's thread (--host-threads 1) unless --host-threads
// says otherwise. The points come back in sweep order whatever finishes first; throws naming the
// first point (in sweep order) whose hit records or image differ from the functional fp24
// model's, as a serial run would. After SIGINT or SIGTERM (testbench/run_journal.h stop_signal)
// no point starts: the result holds the points that finished.
SweepResult run_sweep_points(const std::vector<SweepAxis>& axes, const PreparedScene& prepared,
                             const RenderSettings& settings, const SweepRun& run = {});
// Every point's speed-up over the first point held (the sweep's first point in a whole sweep).
void set_speedups(SweepResult& sweep);

// The Pareto front of (performance, cost) pairs, higher performance and lower cost better: true
// for each pair no other pair dominates (at least as fast and at most as costly, and strictly
// better in one of the two). Equal pairs do not dominate each other: both are on the front.
std::vector<bool> pareto_front(const std::vector<std::pair<double, double>>& performance_cost);
// "luts" when empty; throws "bad --pareto-cost 'NAME': ..." for a name that is no cost column.
std::string pareto_cost_name(const std::string& name);
// Marks each held point's `pareto` against the frame rate and the named cost (the points held:
// a shard's front is its own; sweep-merge marks the whole sweep's).
void mark_pareto(SweepResult& sweep, const std::string& cost);

// The points as JSON and back (MPI ranks), the printed table, the CSV and the JSON report are
// testbench/report.h's (sweep_points_json, sweep_table, sweep_csv, sweep_json).

// Shard CSVs (named for the messages) -> the CSV of the whole sweep, byte for byte the one a
// single process writes: rows in point order, speed-ups over point 0 recomputed from the cycles.
// Throws naming the file on a header that differs, a file that is not a shard CSV, or a point
// missing or given twice.
std::string merge_sweep_csv(const std::vector<std::pair<std::string, std::string>>& shard_csvs);

struct SweepMergeOptions {
  std::vector<std::string> parts;  // shard CSVs
  std::string out;                 // the merged CSV
};
int run_sweep_merge(const SweepMergeOptions& opts);

// Returns 0; throws std::runtime_error with one line on bad input (before any frame runs) or on
// a point whose results differ from the functional model's. Files are written only at the end.
int run_sweep(const SweepOptions& opts);

}  // namespace saarcor
