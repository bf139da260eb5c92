// The paper's Table 4 figures, each declared once (STYLE.md habit 4): unit usage, cache hit rates
// and bandwidth over a span of cycles, with a name, a unit, one line of help and the formula that
// computes it from the chip's cumulative counts. The cycle model's figures (CycleFigures, the
// frame's and each interval's), the render report, its time series, stats.txt and the frame
// sequence's per-frame rows all follow this table (D39; docs/cycle-model.md "Report";
// testbench/report.h writes them).
#pragma once

#include <array>
#include <cstdint>
#include <iterator>
#include <string_view>

#include "hw/stats.h"
#include "units/cycle_params.h"

namespace saarcor::units {

// The four DynRTC units Table 4 reports, in its column order.
inline constexpr int kTable4Units = 4;
inline constexpr const char* kTable4UnitNames[kTable4Units] = {"traversal", "list",
                                                               "transformation", "intersection"};

// The chip's cumulative counts at one cycle, summed over its DynRTPs; the figures of a span are
// computed from the difference of the counts at its two ends.
struct FigureCounts {
  std::uint64_t cycle = 0;
  std::array<std::uint64_t, kTable4Units> issued{};  // cycles a unit issued a step
  std::array<std::uint64_t, kCacheUnits> requests{}, hits{}, bytes{};  // hits: merges included
  std::uint64_t shading_bytes = 0, frame_bytes = 0;  // the RGS's shading reads, pixel writes
  int pipelines = 1;  // usage is per unit: issue cycles over cycles x DynRTPs
};

// The counts of the span (a, b]: b's minus a's; the DynRTPs are b's.
inline FigureCounts span(const FigureCounts& a, const FigureCounts& b) {
  FigureCounts s;
  s.cycle = b.cycle - a.cycle;
  for (std::size_t i = 0; i < kTable4Units; ++i)
    s.issued[i] = b.issued[i] - a.issued[i];
  for (std::size_t c = 0; c < kCacheUnits; ++c) {
    s.requests[c] = b.requests[c] - a.requests[c];
    s.hits[c] = b.hits[c] - a.hits[c];
    s.bytes[c] = b.bytes[c] - a.bytes[c];
  }
  s.shading_bytes = b.shading_bytes - a.shading_bytes;
  s.frame_bytes = b.frame_bytes - a.frame_bytes;
  s.pipelines = b.pipelines;
  return s;
}

namespace figure {

// The formulas are the registry's (hw/stats.h): a figure over the chip's sums of the counters is
// computed as a cache's or a memory client's own statistic is. MB/s at the modelled clock (D39).
inline double mb_per_s(std::uint64_t bytes, std::uint64_t cycles, double clock_mhz) {
  return hw::mb_per_s(bytes, cycles, clock_mhz * 1e6);
}
template <int kUnit>
double usage(const FigureCounts& s, double) {
  return hw::percent(s.issued[kUnit], s.cycle * static_cast<std::uint64_t>(s.pipelines));
}
template <int kCache>
double cache_hit(const FigureCounts& s, double) {
  return s.requests[kCache] == 0 ? 100.0 : hw::percent(s.hits[kCache], s.requests[kCache]);
}
inline double dynrtc(const FigureCounts& s, double clock_mhz) {
  std::uint64_t bytes = 0;
  for (std::uint64_t b : s.bytes)
    bytes += b;
  return mb_per_s(bytes, s.cycle, clock_mhz);
}
inline double shading(const FigureCounts& s, double clock_mhz) {
  return mb_per_s(s.shading_bytes, s.cycle, clock_mhz);
}
inline double frame_buffer(const FigureCounts& s, double clock_mhz) {
  return mb_per_s(s.frame_bytes, s.cycle, clock_mhz);
}
inline double rgs(const FigureCounts& s, double clock_mhz) {
  return shading(s, clock_mhz) + frame_buffer(s, clock_mhz);
}
inline double total(const FigureCounts& s, double clock_mhz) {
  return dynrtc(s, clock_mhz) + shading(s, clock_mhz) + frame_buffer(s, clock_mhz);
}

}  // namespace figure

// One figure: where the reports write it, its unit and help (stats.txt's description), and its
// formula over the counts of a span.
struct FigureInfo {
  const char* name;  // "object.key": its place in the frame's report and in the time series
  const char* unit;
  const char* help;
  double (*compute)(const FigureCounts& span, double clock_mhz);
  bool in_report;  // written by render --report (frame and time series)
};

inline constexpr FigureInfo kFigures[] = {
    {"usage.traversal", "%", "% of cycles the traversal unit issued", figure::usage<0>, true},
    {"usage.list", "%", "% of cycles the list unit issued", figure::usage<1>, true},
    {"usage.transformation", "%", "% of cycles the transformation unit issued", figure::usage<2>,
     true},
    {"usage.intersection", "%", "% of cycles the intersection unit issued", figure::usage<3>, true},
    {"cache_hit.traversal", "%",
     "% of the traversal cache's packet requests that hit (merges count)", figure::cache_hit<0>,
     true},
    {"cache_hit.list", "%", "% of the list cache's packet requests that hit (merges count)",
     figure::cache_hit<1>, true},
    {"cache_hit.transformation", "%",
     "% of the transformation cache's packet requests that hit (merges count)",
     figure::cache_hit<2>, true},
    {"bandwidth_mb_s.dynrtc", "MB/s", "dynrtc memory bandwidth (MB = 2^20 B)", figure::dynrtc,
     true},
    {"bandwidth_mb_s.shading", "MB/s", "shading memory bandwidth (MB = 2^20 B)", figure::shading,
     true},
    {"bandwidth_mb_s.frame_buffer", "MB/s", "frame_buffer memory bandwidth (MB = 2^20 B)",
     figure::frame_buffer, true},
    {"bandwidth_mb_s.total", "MB/s", "total memory bandwidth (MB = 2^20 B)", figure::total, true},
    // The paper's shading column counts the frame buffer too (docs/fidelity.md): the frame
    // sequence's rows and the Table 4 printouts report it beside the DynRTC's.
    {"bandwidth_mb_s.rgs", "MB/s",
     "rgs memory bandwidth: shading reads and frame-buffer writes (MB = 2^20 B)", figure::rgs,
     false},
};
inline constexpr int kFigureCount = static_cast<int>(std::size(kFigures));

// The index of the figure named `name` in kFigures (a compile-time error for an unknown name).
consteval int figure_index(std::string_view name) {
  for (int i = 0; i < kFigureCount; ++i)
    if (name == kFigures[i].name) return i;
  throw "no such figure";
}

// The unit usages and the cache hit rates are consecutive, in Table 4's column order.
consteval bool figures_in_column_order() {
  for (int i = 0; i < kTable4Units; ++i)
    if (std::string_view(kFigures[figure_index("usage.traversal") + i].name).substr(6) !=
        kTable4UnitNames[i])
      return false;
  for (int c = 0; c < kCacheUnits; ++c)
    if (std::string_view(kFigures[figure_index("cache_hit.traversal") + c].name).substr(10) !=
        cache_unit_name(CacheUnit(c)))
      return false;
  return true;
}
static_assert(figures_in_column_order());

// The figures of a span of cycles, in kFigures' order.
struct CycleFigures {
  std::uint64_t cycle = 0;  // end of the span
  std::array<double, kFigureCount> value{};

  double usage(int unit) const { return at(figure_index("usage.traversal") + unit); }
  double cache_hit(int cache) const { return at(figure_index("cache_hit.traversal") + cache); }
  double bw_dynrtc() const { return at(figure_index("bandwidth_mb_s.dynrtc")); }
  double bw_shading() const { return at(figure_index("bandwidth_mb_s.shading")); }
  double bw_frame() const { return at(figure_index("bandwidth_mb_s.frame_buffer")); }
  double bw_total() const { return at(figure_index("bandwidth_mb_s.total")); }
  double bw_rgs() const { return at(figure_index("bandwidth_mb_s.rgs")); }
  double at(int figure) const { return value[static_cast<std::size_t>(figure)]; }
};

// Every figure of the span (a, b].
inline CycleFigures compute_figures(const FigureCounts& a, const FigureCounts& b,
                                    double clock_mhz) {
  CycleFigures f;
  f.cycle = b.cycle;
  const FigureCounts s = span(a, b);
  for (int i = 0; i < kFigureCount; ++i)
    f.value[static_cast<std::size_t>(i)] = kFigures[i].compute(s, clock_mhz);
  return f;
}

}  // namespace saarcor::units
