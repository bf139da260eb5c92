// Sampled simulation of a frame (testbench/sampling.h, docs/sampling.md).
#include "testbench/sampling.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "testbench/packet_cost.h"
#include "units/functional_model.h"

namespace saarcor {
namespace {

[[noreturn]] void bad_spec(const std::string& spec, const std::string& why) {
  throw std::runtime_error("bad --sample '" + spec + "': " + why);
}

int spec_value(const std::string& spec, const std::string& key, const std::string& text) {
  std::size_t used = 0;
  long v = 0;
  try {
    v = std::stol(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty() || v < 0 || v > 100000000)
    bad_spec(spec, key + " wants a whole number 0..100000000, got '" + text + "'");
  return static_cast<int>(v);
}

}  // namespace

SampleSpec parse_sample_spec(const std::string& spec) {
  SampleSpec s;
  if (spec.empty()) return s;
  bool seen[3] = {false, false, false};
  std::size_t pos = 0;
  while (pos <= spec.size()) {
    const std::size_t end = std::min(spec.find(',', pos), spec.size());
    const std::string kv = spec.substr(pos, end - pos);
    const std::size_t eq = kv.find('=');
    if (eq == std::string::npos) bad_spec(spec, "expected KEY=VALUE, got '" + kv + "'");
    const std::string key = kv.substr(0, eq);
    const int k = key == "window" ? 0 : key == "period" ? 1 : key == "warmup" ? 2 : -1;
    if (k < 0) bad_spec(spec, "unknown key '" + key + "' (window, period, warmup)");
    if (seen[k]) bad_spec(spec, key + " given twice");
    seen[k] = true;
    const int v = spec_value(spec, key, kv.substr(eq + 1));
    (k == 0 ? s.window : k == 1 ? s.period : s.warmup) = v;
    pos = end + 1;
  }
  if (s.window < 1) bad_spec(spec, "window must be >= 1");
  if (s.warmup + s.window > s.period)
    bad_spec(spec, "warmup + window (" + std::to_string(s.warmup + s.window) +
                       ") exceeds the period (" + std::to_string(s.period) + ")");
  return s;
}

std::string sample_spec_text(const SampleSpec& s) {
  return "window=" + std::to_string(s.window) + ",period=" + std::to_string(s.period) +
         ",warmup=" + std::to_string(s.warmup);
}

namespace {

// A fixed pseudo-random number per period (splitmix64): the same plan on every run.
std::uint64_t period_hash(std::uint64_t i) {
  std::uint64_t z = i + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

}  // namespace

SamplePlan plan_sample(int packets, const SampleSpec& s) {
  SamplePlan plan;
  // Period i is [iK, iK + K); its warm-up and window, U + W packets in a row, start at a place
  // drawn in [0, K - U - W] (stratified sampling: one window per period). A window at the same
  // place of every period would see the same columns of the image whenever K is a multiple of a
  // row's packets, and miss an object standing in the others.
  // The last period also holds the frame's remainder (the bottom rows of tiles): left out, its
  // packets would be estimated by the others' mean, a bias wherever they cost more or less.
  const int periods = packets / s.period;
  for (int i = 0; i < periods; ++i) {
    const int size = i + 1 < periods ? s.period : packets - i * s.period;
    const int slack = size - s.warmup - s.window;
    const int first = i * s.period + static_cast<int>(period_hash(static_cast<std::uint64_t>(i)) %
                                                      static_cast<std::uint64_t>(slack + 1));
    for (int k = first; k < first + s.warmup; ++k)
      plan.order.push_back(k);
    plan.marks.push_back(static_cast<int>(plan.order.size()));
    for (int k = first + s.warmup; k < first + s.warmup + s.window; ++k)
      plan.order.push_back(k);
    plan.marks.push_back(static_cast<int>(plan.order.size()));
    plan.strata.push_back(size);
    plan.window_first.push_back(first + s.warmup);
    ++plan.windows;
  }
  return plan;
}

double student_t975(int df) {
  // The table for small df; above, the Cornish-Fisher expansion around z (error < 1e-4 for
  // df >= 13).
  static constexpr double kSmall[] = {12.7062, 4.3027, 3.1824, 2.7764, 2.5706, 2.4469,
                                      2.3646,  2.3060, 2.2622, 2.2281, 2.2010, 2.1788};
  if (df < 1) throw std::logic_error("student_t975: df < 1");
  if (df <= 12) return kSmall[df - 1];
  const double z = 1.959964, n = df;
  const double z3 = z * z * z, z5 = z3 * z * z, z7 = z5 * z * z;
  return z + (z3 + z) / (4 * n) + (5 * z5 + 16 * z3 + 3 * z) / (96 * n * n) +
         (3 * z7 + 19 * z5 + 17 * z3 - 15 * z) / (384 * n * n * n);
}

namespace {

double mean_of(const std::vector<double>& v) {
  double m = 0;
  for (double x : v)
    m += x / static_cast<double>(v.size());
  return m;
}

// Sum of (a_i - mean a)(b_i - mean b).
double co_sum(const std::vector<double>& a, const std::vector<double>& b) {
  const double ma = mean_of(a), mb = mean_of(b);
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    s += (a[i] - ma) * (b[i] - mb);
  return s;
}

}  // namespace

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size() || a.size() < 2) return 0;
  const double aa = co_sum(a, a), bb = co_sum(b, b);
  return aa > 0 && bb > 0 ? co_sum(a, b) / std::sqrt(aa * bb) : 0;
}

FigureEstimate estimate_cycles(const std::vector<double>& cpp, const std::vector<double>& strata,
                               double sampled_fraction, const std::vector<double>& x,
                               const std::vector<double>& period_x) {
  FigureEstimate e;
  const std::size_t n = cpp.size();
  if (n == 0) return e;
  if (strata.size() != n) throw std::logic_error("estimate_cycles: one stratum a window");
  const bool regression = !x.empty();
  if (regression && (x.size() != n || period_x.size() != n))
    throw std::logic_error("estimate_cycles: one covariate a window and a period");
  // The slope; the intercept's degree of freedom is the mean's, the slope's one more.
  const double sxx = regression ? co_sum(x, x) : 0;
  const double b = sxx > 0 ? co_sum(x, cpp) / sxx : 0;
  const std::size_t fitted = regression ? 2 : 1;
  double packets = 0;
  for (std::size_t i = 0; i < n; ++i) {
    e.value += strata[i] * (cpp[i] + (regression ? b * (period_x[i] - x[i]) : 0.0));
    packets += strata[i];
  }
  if (n <= fitted) return e;
  const double my = mean_of(cpp), mx = regression ? mean_of(x) : 0;
  double ss = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = cpp[i] - my - (regression ? b * (x[i] - mx) : 0.0);
    ss += r * r;
  }
  const auto df = static_cast<double>(n - fitted);
  // The standard error of the mean, with the finite-population correction of sampling a share
  // `sampled_fraction` of the frame's packets.
  const double se =
      std::sqrt(ss / df / static_cast<double>(n) * std::max(0.0, 1.0 - sampled_fraction));
  const double half = student_t975(static_cast<int>(n - fitted)) * se * packets;
  e.ci = {e.value - half, e.value + half};
  return e;
}

namespace {

units::FigureCounts add_counts(units::FigureCounts a, const units::FigureCounts& b, int sign) {
  const auto add = [sign](std::uint64_t& x, std::uint64_t y) { x = sign > 0 ? x + y : x - y; };
  add(a.cycle, b.cycle);
  for (std::size_t i = 0; i < units::kTable4Units; ++i)
    add(a.issued[i], b.issued[i]);
  for (std::size_t c = 0; c < units::kCacheUnits; ++c) {
    add(a.requests[c], b.requests[c]);
    add(a.hits[c], b.hits[c]);
    add(a.bytes[c], b.bytes[c]);
  }
  add(a.shading_bytes, b.shading_bytes);
  add(a.frame_bytes, b.frame_bytes);
  a.pipelines = b.pipelines;
  return a;
}

double figure_of(const units::FigureCounts& total, int figure, double clock_mhz) {
  units::FigureCounts zero;
  zero.pipelines = total.pipelines;
  return units::kFigures[figure].compute(units::span(zero, total), clock_mhz);
}

}  // namespace

FigureEstimate estimate_figure(const std::vector<units::FigureCounts>& spans, int figure,
                               double clock_mhz, double sampled_fraction) {
  FigureEstimate e;
  if (spans.empty()) return e;
  units::FigureCounts total;
  total.pipelines = spans.front().pipelines;
  for (const units::FigureCounts& s : spans)
    total = add_counts(total, s, 1);
  e.value = figure_of(total, figure, clock_mhz);
  const std::size_t n = spans.size();
  if (n < 2) return e;
  // Jackknife: the figure with each window left out; its spread is the ratio's standard error.
  std::vector<double> loo(n);
  double mean = 0;
  for (std::size_t j = 0; j < n; ++j) {
    loo[j] = figure_of(add_counts(total, spans[j], -1), figure, clock_mhz);
    mean += loo[j] / static_cast<double>(n);
  }
  double ss = 0;
  for (double v : loo)
    ss += (v - mean) * (v - mean);
  const double var = ss * static_cast<double>(n - 1) / static_cast<double>(n);
  const double half = student_t975(static_cast<int>(n) - 1) *
                      std::sqrt(var * std::max(0.0, 1.0 - sampled_fraction));
  e.ci = {e.value - half, e.value + half};
  return e;
}

namespace {

bool same_record(const units::FrameSink::Pixel& a, const units::FrameSink::Pixel& b) {
  return a.t == b.t && a.u == b.u && a.v == b.v && a.cos == b.cos && a.instance == b.instance &&
         a.triangle == b.triangle && a.o == b.o && a.d == b.d && a.counters == b.counters;
}

}  // namespace

void check_sampled_packets(const memif::MemoryImage& image, const units::CycleParams& p,
                           const units::FunctionalParams& shading, const CycleFrame& c) {
  if (!c.sampling) throw std::logic_error("check_sampled_packets: the frame was not sampled");
  const std::vector<int> order =
      plan_sample(static_cast<int>(c.sampling->packets), c.sampling->spec).order;
  const units::FunctionalFrame fn =
      units::run_functional_packets(image, units::functional_params(p, shading), order);
  const units::PacketTiling tiling = units::packet_tiling(fn.width, fn.height, p.packet);
  for (int packet : order)
    for (std::uint32_t px : units::packet_pixels(tiling, fn.width, fn.height, packet)) {
      if (px == memif::kNone) continue;
      const bool rgb = std::equal(fn.rgb.begin() + 3 * px, fn.rgb.begin() + 3 * px + 3,
                                  c.frame.rgb.begin() + 3 * px);
      if (!rgb || !same_record(fn.pixels[px], c.frame.pixels[px]))
        throw std::runtime_error(
            "sampled cycle model: pixel " + std::to_string(px % std::uint32_t(fn.width)) + "," +
            std::to_string(px / std::uint32_t(fn.width)) + " differs from the functional model's");
    }
  const bool ops = c.frame.units.traversal_ops == fn.units.traversal_ops &&
                   c.frame.units.transformation_ops == fn.units.transformation_ops &&
                   c.frame.units.intersection_ops == fn.units.intersection_ops;
  if (!ops || c.frame.rays_issued != fn.rays_issued || c.frame.rays_returned != fn.rays_issued)
    throw std::runtime_error(
        "sampled cycle model: the op counts or rays differ from the functional model's");
}

namespace {

// Why the windows' sample defeats the interval, or "".
std::string defeated_because(int windows, double cov) {
  char buf[160];
  if (windows < kMinSampleWindows) {
    std::snprintf(buf, sizeof buf, "only %d windows (an interval needs at least %d)", windows,
                  kMinSampleWindows);
    return buf;
  }
  if (cov > kMaxSampleCov) {
    std::snprintf(buf, sizeof buf,
                  "the cost is concentrated in few packets (coefficient of variation of the "
                  "windows' cycles per packet %.2f > %.2f)",
                  cov, kMaxSampleCov);
    return buf;
  }
  return "";
}

double coefficient_of_variation(const std::vector<double>& v) {
  if (v.size() < 2) return 0;
  double mean = 0, ss = 0;
  for (double x : v)
    mean += x / static_cast<double>(v.size());
  for (double x : v)
    ss += (x - mean) * (x - mean);
  return mean > 0 ? std::sqrt(ss / static_cast<double>(v.size() - 1)) / mean : 0;
}

// The covariate's means per window (its own packets) and per period (estimate_cycles' x and
// period_x).
void covariate_means(const SamplePlan& plan, const SampleSpec& spec,
                     const std::vector<double>& cost, std::vector<double>& x,
                     std::vector<double>& period_x) {
  std::vector<double> prefix(cost.size() + 1, 0.0);
  for (std::size_t k = 0; k < cost.size(); ++k)
    prefix[k + 1] = prefix[k] + cost[k];
  const auto mean = [&](std::size_t a, std::size_t b) {
    b = std::min(b, cost.size());
    return b > a ? (prefix[b] - prefix[a]) / static_cast<double>(b - a) : 0.0;
  };
  for (int i = 0; i < plan.windows; ++i) {
    const auto first = static_cast<std::size_t>(plan.window_first[std::size_t(i)]);
    x.push_back(mean(first, first + static_cast<std::size_t>(spec.window)));
    const auto begin = static_cast<std::size_t>(i) * static_cast<std::size_t>(spec.period);
    period_x.push_back(mean(begin, begin + static_cast<std::size_t>(plan.strata[std::size_t(i)])));
  }
}

// The frame's figures from the run's windows and the packets' covariate into `c` (its usual
// fields) and `s`.
void estimate_frame(const units::CycleParams& p, const SamplePlan& plan, std::uint64_t packets,
                    const std::vector<double>& cost, CycleFrame& c, SampleSummary& s) {
  std::vector<units::FigureCounts> spans;
  std::vector<double> cpp, x, period_x;
  for (int i = 0; i < plan.windows; ++i) {
    spans.push_back(units::span(c.marks[2 * std::size_t(i)], c.marks[2 * std::size_t(i) + 1]));
    cpp.push_back(static_cast<double>(spans.back().cycle) / s.spec.window);
  }
  covariate_means(plan, s.spec, cost, x, period_x);
  s.covariate_correlation = correlation(x, cpp);
  const double f = static_cast<double>(plan.windows) * s.spec.window / static_cast<double>(packets);
  const FigureEstimate cycles = estimate_cycles(
      cpp, std::vector<double>(plan.strata.begin(), plan.strata.end()), f, x, period_x);
  const double hz = p.clock_mhz * 1e6;
  // The frame's rays from the simulated packets' rays per packet (`rays` stays theirs, as the
  // per-ray counters beside it are).
  const double rays =
      static_cast<double>(c.rays) / static_cast<double>(c.packets) * static_cast<double>(packets);
  c.cycles = static_cast<std::uint64_t>(std::llround(cycles.value));
  c.fps = hz / cycles.value;
  c.rays_per_s = rays * c.fps;
  s.cycles = cycles.ci;
  s.fps = {hz / cycles.ci.high, hz / cycles.ci.low};
  s.rays_per_s = {rays * s.fps.low, rays * s.fps.high};
  for (int k = 0; k < units::kFigureCount; ++k) {
    const FigureEstimate e = estimate_figure(spans, k, p.clock_mhz, f);
    c.figures.value[static_cast<std::size_t>(k)] = e.value;
    s.figures[static_cast<std::size_t>(k)] = e.ci;
  }
  c.figures.cycle = c.cycles;
  // The RGS's bytes per pixel: the simulated packets' bytes over their pixels.
  c.shading_bytes_per_pixel *= static_cast<double>(packets) / static_cast<double>(c.packets);
  s.cycles_per_packet_cov = coefficient_of_variation(cpp);
  s.defeated = defeated_because(plan.windows, s.cycles_per_packet_cov);
}

}  // namespace

CycleFrame run_sampled(const memif::MemoryImage& image, const units::CycleParams& params,
                       const CycleRunOptions& options, const SampleSpec& spec) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto& r = image.registers();
  const int packets =
      units::packet_tiling(static_cast<int>(r.width), static_cast<int>(r.height), params.packet)
          .count();
  const SamplePlan plan = plan_sample(packets, spec);
  if (plan.windows == 0 || static_cast<int>(plan.order.size()) > packets)
    return run_cycle(image, params, options);
  // The covariate of every packet, before the run and inside its host time.
  const auto tc = std::chrono::steady_clock::now();
  std::vector<double> cost;
  for (const RayCost& r : packet_costs(image, params.packet))
    cost.push_back(cost_covariate(r));
  const double covariate_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - tc).count();
  CycleRunOptions o = options;
  o.packet_order = plan.order;
  o.marks = plan.marks;
  o.interval = 0;  // a time series of a sampled run would mix the periods
  CycleFrame c = run_cycle(image, params, o);
  auto s = std::make_shared<SampleSummary>();
  s->spec = spec;
  s->windows = plan.windows;
  s->packets = static_cast<std::uint64_t>(packets);
  s->packets_simulated = plan.order.size();
  s->cycles_simulated = c.cycles;
  s->covariate_seconds = covariate_seconds;
  estimate_frame(params, plan, static_cast<std::uint64_t>(packets), cost, c, *s);
  c.packets = static_cast<std::uint64_t>(packets);
  c.sampling = std::move(s);
  c.host_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  c.frame.seconds = c.host_seconds;
  return c;
}

std::string sampling_text(const CycleFrame& c) {
  if (!c.sampling) return "";
  const SampleSummary& s = *c.sampling;
  char buf[256];
  std::string t;
  std::snprintf(buf, sizeof buf,
                "sampled: %s, %d windows, %llu of %llu packets simulated (%.1f %%)\n",
                sample_spec_text(s.spec).c_str(), s.windows,
                static_cast<unsigned long long>(s.packets_simulated),
                static_cast<unsigned long long>(s.packets),
                100.0 * static_cast<double>(s.packets_simulated) / static_cast<double>(s.packets));
  t += buf;
  if (!s.defeated.empty()) return t + "  no confidence interval: " + s.defeated + "\n";
  std::snprintf(
      buf, sizeof buf, "  95 %% intervals: cycles %.0f [%.0f, %.0f], fps %.2f [%.2f, %.2f]\n",
      static_cast<double>(c.cycles), s.cycles.low, s.cycles.high, c.fps, s.fps.low, s.fps.high);
  t += buf;
  for (int k = 0; k < units::kFigureCount; ++k) {
    if (!units::kFigures[k].in_report) continue;
    const SampleInterval& i = s.figures[static_cast<std::size_t>(k)];
    std::snprintf(buf, sizeof buf, "  %-28s %10.2f [%.2f, %.2f] %s\n", units::kFigures[k].name,
                  c.figures.at(k), i.low, i.high, units::kFigures[k].unit);
    t += buf;
  }
  return t;
}

}  // namespace saarcor
