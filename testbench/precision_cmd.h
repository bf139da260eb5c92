// `saarcor precision`: the paper's "parameterised precision" study (section 4: the FP units were
// modelled "with a parameterized precision in order to evaluate its effect on performance and
// rendering quality"; 16 mantissa bits were chosen). The functional model runs in Float<7, m> for
// each m and is compared with the float reference (docs/compare.md): same-triangle share and
// PSNR per m, printed as a table, written as JSON and drawn as a PNG plot.
#pragma once

#include <string>
#include <vector>

#include "testbench/compare.h"
#include "testbench/hit_buffer.h"
#include "testbench/render_cmd.h"

namespace saarcor {

struct PrecisionRow {
  int mantissa = 16;
  double same_triangle_pct = 0.0;
  double psnr_db = 0.0;  // +inf when the images are identical
  std::optional<double> t_rel_err_median;
  std::optional<double> t_rel_err_max;
  MismatchCounts mismatches;
  double seconds = 0.0;  // the functional model's run time
};

// "M" or "A..B" with kMinMantissa <= A <= B <= kMaxMantissa; throws "bad --mantissa ...".
std::pair<int, int> parse_mantissa_range(const std::string& text);

// Renders the float reference once and the functional model for each m in [lo, hi], with a
// terminal heartbeat (formats done / total) when `heartbeat`.
std::vector<PrecisionRow> run_precision_study(const std::string& scene,
                                              const RenderSettings& settings, int lo, int hi,
                                              bool heartbeat = true);

// The plot: x = mantissa bits; left axis same-triangle share (blue), right axis PSNR (red);
// dashed guides at the acceptance thresholds (99 %, 35 dB) and at m = 16 (fp24).
struct PrecisionPlot {
  Rgb8Image image;
  std::vector<PixelCoord> same_points;  // marker centres, one per row
  std::vector<PixelCoord> psnr_points;
};
PrecisionPlot plot_precision(const std::vector<PrecisionRow>& rows, const std::string& title);
inline constexpr std::uint8_t kSameColour[3] = {30, 80, 220};
inline constexpr std::uint8_t kPsnrColour[3] = {220, 40, 30};

std::string precision_table(const std::vector<PrecisionRow>& rows);

struct PrecisionOptions {
  std::string scene;
  std::string mantissa = "10..23";
  std::string res = "512x384";
  std::string out = "out/precision";  // PREFIX.png (plot), PREFIX.json (table)
  double bank_mb = 4.0;
  // --out-dir DIR (testbench/run_dir.h): precision.png, report.json, stats.txt, config.json,
  // command.txt, host.json; --out is refused with it.
  std::string out_dir;
  bool out_given = false;         // --out was on the command line (not its default)
  std::vector<std::string> argv;  // the command line, for command.txt
};

int run_precision(const PrecisionOptions& opts);

}  // namespace saarcor
