// Sampled simulation of a frame (docs/sampling.md; SMARTS, Wunderlich et al., ISCA 2003): the
// frame's packets in the RGC's dispatch order are split into periods of `period` packets; in each
// the cycle model runs `warmup` packets in detail (the pipeline fills with the period's packets,
// the caches with their items) and then measures `window` packets; the rest of the period is
// skipped. The figures of the frame are estimated from the measured windows with a 95 %
// confidence interval from the windows' sample variance. Every simulated packet (warm-up and
// window) is checked bit for bit against the functional model.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "memif/image_format.h"
#include "testbench/chip.h"
#include "units/cycle_params.h"
#include "units/figures.h"
#include "units/functional_model.h"

namespace saarcor {

// How a frame is sampled, in packets of the RGC's order (--sample window=W,period=K,warmup=U).
struct SampleSpec {
  int window = 256;   // measured packets per period
  int period = 4608;  // packets from one period's start to the next's
  int warmup = 128;   // packets simulated in detail before each window, not measured
};

// "" gives the default; otherwise comma-separated KEY=VALUE with the keys window, period and
// warmup (any subset, each at most once). Throws std::runtime_error, one line starting
// "bad --sample 'SPEC': ", for anything else or values with window < 1, warmup < 0 or
// warmup + window > period.
SampleSpec parse_sample_spec(const std::string& spec);
std::string sample_spec_text(const SampleSpec& s);  // "window=128,period=3200,warmup=128"

// The RGC's order of a sampled frame of `packets` packets and the hand-out counts at which the
// chip's counts are read: marks[2i] begins window i, marks[2i+1] ends it. Window i stands for the
// packets of its period, strata[i]: `period` each, the last period holding the frame's remainder
// too (fewer than `period` packets), so that every packet is represented.
struct SamplePlan {
  std::vector<int> order;
  std::vector<int> marks;
  std::vector<int> strata;
  std::vector<int> window_first;  // per window: its first measured packet
  int windows = 0;
};
SamplePlan plan_sample(int packets, const SampleSpec& s);

// Fewer windows than this give no interval (the sample variance of so few says little).
inline constexpr int kMinSampleWindows = 10;
// A coefficient of variation of the windows' cycles per packet above this: the frame's cost sits
// in a few windows, and the interval from their variance is not trusted.
inline constexpr double kMaxSampleCov = 1.0;

struct SampleInterval {
  double low = 0, high = 0;
};

// What a sampled frame's report says of its sampling (the JSON report's `sampling` object).
struct SampleSummary {
  SampleSpec spec;
  int windows = 0;
  std::uint64_t packets = 0;            // the frame's
  std::uint64_t packets_simulated = 0;  // warm-ups and windows
  std::uint64_t cycles_simulated = 0;   // the sampled run's clock at its end
  double cycles_per_packet_cov = 0;     // of the windows' cycles per packet
  // The packets' cost covariate (testbench/packet_cost.h): its host seconds, part of the run's,
  // and its correlation with the windows' cycles per packet over the windows.
  double covariate_seconds = 0;
  double covariate_correlation = 0;
  // Empty when the interval is trusted; otherwise why not (the report prints this instead).
  std::string defeated;
  SampleInterval cycles, fps, rays_per_s;
  std::array<SampleInterval, units::kFigureCount> figures{};  // kFigures' order
};

// The estimate of a figure and its interval from the windows' spans (counts of each window), for
// a frame of `packets` packets of which the windows hold `measured`: the pooled ratio (the figure
// of all windows' counts together) and its jackknife standard error, scaled by Student's t.
struct FigureEstimate {
  double value = 0;
  SampleInterval ci;
};
FigureEstimate estimate_figure(const std::vector<units::FigureCounts>& spans, int figure,
                               double clock_mhz, double sampled_fraction);
// The cycles of a frame from the windows' cycles per packet, window i standing for strata[i]
// packets (SamplePlan::strata).
// Without a covariate (x empty): the sum of strata[i] x cycles_per_packet[i]; the interval from
// their sample variance (n - 1 degrees of freedom).
// With one (the regression estimator; Cochran, Sampling Techniques, 7.1): x[i] is the mean
// covariate (testbench/packet_cost.h) of the packets window i's cycles follow, period_x[i] that of
// its period's packets, b the least-squares slope of cycles per packet on x over the windows. The
// total is the sum of strata[i] x (cycles_per_packet[i] + b (period_x[i] - x[i])): each window
// carried to its period by what the covariate says of the difference. The interval from the
// residuals about the fitted line (n - 2 degrees of freedom). A covariate that does not vary over
// the windows gives b = 0.
FigureEstimate estimate_cycles(const std::vector<double>& cycles_per_packet,
                               const std::vector<double>& strata, double sampled_fraction,
                               const std::vector<double>& x = {},
                               const std::vector<double>& period_x = {});
// The Pearson correlation of two equally long series (0 when either does not vary).
double correlation(const std::vector<double>& a, const std::vector<double>& b);
// Student's t quantile 0.975 for `df` degrees of freedom (>= 1).
double student_t975(int df);

// Runs the frame sampled as `spec` says: the frame's figures estimated into the returned frame's
// usual fields (cycles, fps, rays_per_s, figures; packets is the frame's, rays and the per-ray
// counters the simulated packets') and `sampling` set. A frame whose plan holds no window, or
// every packet, runs whole (no sampling).
CycleFrame run_sampled(const memif::MemoryImage& image, const units::CycleParams& params,
                       const CycleRunOptions& options, const SampleSpec& spec);
// A sampled frame's simulated packets (warm-ups and windows) against the functional model running
// the same packets: every hit record and pixel colour of theirs, the op counts, every ray returned
// once. Throws std::runtime_error naming the first differing pixel.
void check_sampled_packets(const memif::MemoryImage& image, const units::CycleParams& params,
                           const units::FunctionalParams& shading, const CycleFrame& frame);

// The text report's lines of a sampled frame: how it was sampled and each estimate's interval, or
// why the frame defeats the sampling.
std::string sampling_text(const CycleFrame& frame);

}  // namespace saarcor
