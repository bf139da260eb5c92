// `saarcor sweep`: design-space exploration with the cycle model. One scene is loaded and its
// memory image built once; the cycle model then runs a frame for every point of the cartesian
// product of the --vary lists (on top of --preset and --set), and every point's hit records and
// image are checked bit for bit against the functional fp24 model on the same image: timing may
// change, results never do (issue 6). Prints one row per point (cycles, fps, speed-up over the
// first point, the paper's Table 4 columns), and writes the same as JSON and CSV
// (docs/cycle-model.md, "Sweeps").
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
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
  std::string report;  // JSON path, optional
  std::string csv;     // CSV path, optional
};

// (bugprone-exception-escape: nlohmann::json's default constructor is not declared noexcept; a
// null json allocates nothing.)
struct SweepPoint {                   // NOLINT(bugprone-exception-escape)
  std::vector<std::string> settings;  // the KEY=VALUE the point adds
  nlohmann::json cycle;               // the frame's cycle report (cycle_report_json)
  double speedup = 1.0;               // the first point's cycles over this point's
};
struct SweepResult {
  std::vector<SweepAxis> axes;
  std::vector<SweepPoint> points;
  std::string functional_model;       // the reference: "fp24", or "e7m23" for cycle-e7m23
  std::uint64_t functional_rays = 0;  // its frame's rays
};

// Throws "sweep point WHERE: ..." unless the cycle model's frame has the reference's hit records
// (every bit), image and ray count.
void check_sweep_point(const FrameResult& frame, const FrameResult& reference,
                       const std::string& where);

// Runs every point; throws naming the first point whose hit records or image differ from the
// functional fp24 model's.
SweepResult run_sweep_points(const std::vector<SweepAxis>& axes, const PreparedScene& prepared,
                             const RenderSettings& settings);

// The printed table, the CSV text and the JSON report of a sweep.
std::string sweep_table(const SweepResult& sweep);
std::string sweep_csv(const SweepResult& sweep);
nlohmann::json sweep_json(const SweepResult& sweep, const SweepOptions& opts);

// Returns 0; throws std::runtime_error with one line on bad input (before any frame runs) or on
// a point whose results differ from the functional model's. Files are written only at the end.
int run_sweep(const SweepOptions& opts);

}  // namespace saarcor
