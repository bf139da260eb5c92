// Sampled simulation of a frame (docs/sampling.md; SMARTS, Wunderlich et al., ISCA 2003): the
// frame's packets in the RGC's dispatch order are split into periods of `period` packets; in each
// the cycle model measures a window of `window` packets, run in detail between `warmup` packets
// before it and `cooldown` after it (the threads and caches hold the window's neighbours, as in
// the frame); the rest is skipped. Each simulated packet is charged its share of the cycles
// (units::PacketCharges); the frame's cycles come from a regression of the windows' charges on
// per-packet cost features (testbench/packet_cost.h), with a 95 % confidence interval from what it
// leaves over between windows; the other figures are the windows' pooled ratios. Every simulated
// packet is checked bit for bit against the functional model.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "memif/image_format.h"
#include "testbench/chip.h"
#include "testbench/packet_cost.h"
#include "units/cycle_params.h"
#include "units/figures.h"
#include "units/functional_model.h"

namespace saarcor {

// How a frame is sampled, in packets of the RGC's order
// (--sample window=W,period=K,warmup=U,cooldown=C). A value of kAuto is chosen for the machine and
// the frame by resolve_sample_spec.
inline constexpr int kAuto = -1;
struct SampleSpec {
  int window = kAuto;    // measured packets per period
  int period = kAuto;    // packets from one period's start to the next's
  int warmup = kAuto;    // packets simulated in detail before each window, not measured
  int cooldown = kAuto;  // packets simulated in detail after each window, not measured
};

// The automatic choice (docs/sampling.md "The default") for a frame of `tiling`'s packets, with T
// the chip's threads (DynRTPs x threads): warm-up max(64, 2T) packets, plus with several DynRTPs
// the share of the row of tiles above that the largest cache holds, and cool-down max(32, T) (the
// threads in flight around a window are its neighbours, as in the frame; several DynRTPs' caches
// hold the row above); window max(2T, a row
// of tiles) packets (a window then sees every column of the image once); period the shorter of
// what keeps the simulated share at kSampleShare and what gives kSampleWindows windows.
inline constexpr double kSampleShare = 0.08;
inline constexpr int kSampleWindows = 20;
// Cache items that hold about a row of tiles' items (the default caches'): with several DynRTPs
// the warm-up covers the share of the row above that the largest cache holds.
inline constexpr int kRowItems = 512;
SampleSpec resolve_sample_spec(const SampleSpec& s, const units::CycleParams& p,
                               const units::PacketTiling& tiling);

// "" gives the default (every value kAuto); otherwise comma-separated KEY=VALUE with the keys
// window, period, warmup and cooldown (any subset, each at most once, the rest kAuto). Throws
// std::runtime_error, one line starting "bad --sample 'SPEC': ", for anything else or values with
// window < 1, or warmup + window + cooldown > period where all given.
SampleSpec parse_sample_spec(const std::string& spec);
std::string sample_spec_text(
    const SampleSpec& s);  // "window=128,period=3200,warmup=128,cooldown=64"
// ("auto" for a kAuto value)

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
SamplePlan plan_sample(int packets, const SampleSpec& s);  // s resolved (no kAuto)

// Fewer windows than this give no interval (the sample variance of so few says little).
inline constexpr int kMinSampleWindows = 10;
// The frame's cost sits in few packets when the packets the fit says hold half of it lie in fewer
// windows than this: the windows' residuals then say little of where the cost is, and the
// interval from their variance is not trusted.
inline constexpr int kMinCostlyWindows = 5;

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
  // The packets the fit says hold half the frame's cost, and the windows holding any of them.
  std::uint64_t costly_packets = 0;
  int costly_windows = 0;
  // The packets' cost features (testbench/packet_cost.h): their host seconds, part of the run's,
  // and the correlation over the windows of their cycles per packet with the fit's.
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
// A measured window as the cycles estimate reads it.
struct WindowCharges {
  std::vector<double> charges;  // its packets' charged cycles (units::PacketCharges), in order
  int first = 0;                // its first packet (in the frame's tiling order)
  double stratum = 0;           // the packets it stands for (SamplePlan::strata)
};
// The cycles of a frame by the generalised regression estimator (Sarndal, Swensson and Wretman,
// Model Assisted Survey Sampling, 6.4; Cochran, Sampling Techniques, 7): a least-squares fit of
// the windows' packets' charged cycles on their cost features predicts every packet of the frame
// (`features`, one per packet, testbench/packet_cost.h); each window's mean residual carries what
// the fit missed to the packets it stands for. The total is the sum of the fit over the frame plus
// the sum over windows of stratum_i x mean residual_i; the interval from the residual means'
// sample variance over the windows (n - 1 degrees of freedom) with the finite-population
// correction of sampling `sampled_fraction` of the packets. Without features (empty) the fit is a
// constant: the plain stratified estimator, the sum of stratum_i x the window's mean charge. A
// feature without spread over the windows' packets gets no coefficient. `fit_correlation`, when
// given: the correlation over the windows of their mean charge with the fit's; `fitted`, when
// given and features are: the fit of every packet of the frame.
FigureEstimate estimate_cycles(const std::vector<WindowCharges>& windows,
                               const std::vector<CostFeatures>& features, double sampled_fraction,
                               double* fit_correlation = nullptr,
                               std::vector<double>* fitted = nullptr);
// The Pearson correlation of two equally long series (0 when either does not vary).
double correlation(const std::vector<double>& a, const std::vector<double>& b);
// Student's t quantile 0.975 for `df` degrees of freedom (>= 1).
double student_t975(int df);

// Runs the frame sampled as `spec` says (its kAuto values resolved; SampleSummary::spec holds
// what was run): the frame's figures estimated into the returned frame's usual fields (cycles,
// fps, rays_per_s, figures; packets is the frame's, rays and the per-ray counters the simulated
// packets') and `sampling` set. A frame whose plan holds no window, or every packet, runs whole
// (no sampling).
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
