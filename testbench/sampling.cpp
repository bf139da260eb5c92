// Sampled simulation of a frame (testbench/sampling.h, docs/sampling.md).
#include "testbench/sampling.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
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
  bool seen[4] = {false, false, false, false};
  std::size_t pos = 0;
  while (pos <= spec.size()) {
    const std::size_t end = std::min(spec.find(',', pos), spec.size());
    const std::string kv = spec.substr(pos, end - pos);
    const std::size_t eq = kv.find('=');
    if (eq == std::string::npos) bad_spec(spec, "expected KEY=VALUE, got '" + kv + "'");
    const std::string key = kv.substr(0, eq);
    const int k = key == "window"     ? 0
                  : key == "period"   ? 1
                  : key == "warmup"   ? 2
                  : key == "cooldown" ? 3
                                      : -1;
    if (k < 0) bad_spec(spec, "unknown key '" + key + "' (window, period, warmup, cooldown)");
    if (seen[k]) bad_spec(spec, key + " given twice");
    seen[k] = true;
    const int v = spec_value(spec, key, kv.substr(eq + 1));
    (k == 0 ? s.window : k == 1 ? s.period : k == 2 ? s.warmup : s.cooldown) = v;
    pos = end + 1;
  }
  if (seen[0] && s.window < 1) bad_spec(spec, "window must be >= 1");
  if (seen[0] && seen[1] && seen[2] && seen[3] && s.warmup + s.window + s.cooldown > s.period)
    bad_spec(spec, "warmup + window + cooldown (" +
                       std::to_string(s.warmup + s.window + s.cooldown) + ") exceeds the period (" +
                       std::to_string(s.period) + ")");
  if (seen[0] && seen[1] && s.window > s.period)
    bad_spec(spec, "window (" + std::to_string(s.window) + ") exceeds the period (" +
                       std::to_string(s.period) + ")");
  return s;
}

namespace {

// With several DynRTPs each has its own caches, and a window's packets find in them, in the frame,
// the items of the tile row above: the warm-up reaches back over as much of that row as the
// caches hold. The default caches (512 items) hold about a row's: without the row the Duck at
// 1024x768 came out +6.3 % and +7.6 % under two and four DynRTPs. Eight-item caches hold a few
// packets' (three DynRTPs: the Duck -0.5 % without the row, -0.8 % with it).
int row_above(const units::CycleParams& p, const units::PacketTiling& tiling) {
  if (p.pipelines == 1) return 0;
  int items = 0;
  for (const auto& c : p.cache)
    items = std::max(items, c.items);
  return static_cast<int>(
      std::lround(tiling.tiles_x * std::min(1.0, items / static_cast<double>(kRowItems))));
}

}  // namespace

SampleSpec resolve_sample_spec(const SampleSpec& s, const units::CycleParams& p,
                               const units::PacketTiling& tiling) {
  const int t = p.threads * p.pipelines;
  const int packets = tiling.count();
  SampleSpec r = s;
  if (r.warmup == kAuto) r.warmup = std::max(64, 2 * t) + row_above(p, tiling);
  if (r.cooldown == kAuto) r.cooldown = std::max(32, t);
  if (r.window == kAuto) r.window = std::max(2 * t, tiling.tiles_x);
  if (r.period == kAuto) {
    const auto by_share = static_cast<int>(
        std::lround(static_cast<double>(r.warmup + r.window + r.cooldown) / kSampleShare));
    r.period = std::max(r.window, std::min(by_share, packets / kSampleWindows));
  }
  return r;
}

std::string sample_spec_text(const SampleSpec& s) {
  const auto v = [](int x) { return x == kAuto ? std::string("auto") : std::to_string(x); };
  return "window=" + v(s.window) + ",period=" + v(s.period) + ",warmup=" + v(s.warmup) +
         ",cooldown=" + v(s.cooldown);
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
  if (s.window < 1 || s.period < s.window || s.warmup < 0 || s.cooldown < 0)
    throw std::logic_error("plan_sample: an unresolved or impossible spec " + sample_spec_text(s));
  SamplePlan plan;
  // Period i is [iK, iK + K); its window of W packets starts at a place drawn in [iK, iK + K - W]
  // (stratified sampling, one window per period, every packet of the period as likely to be
  // measured as any other). A window at the same place of every period would see the same columns
  // of the image whenever K is a multiple of a row's packets, and miss an object standing in the
  // others. The last period also holds the frame's remainder (the bottom rows of tiles): left out,
  // its packets would be estimated by the others' mean, a bias wherever they cost more or less.
  // Around the window run its warm-up (the U packets before it: the caches fill, and the threads
  // with the window's neighbours) and its cool-down (the C after it: its last packets share the
  // machine with their neighbours, as in the frame, not with the next warm-up's). Both may reach
  // into the neighbouring periods; where a warm-up would overlap the packets run before it, it
  // starts after them (the run is then continuous, as the frame is), and neither runs past the
  // frame's ends (there the frame itself starts or drains).
  const int periods = packets / s.period;
  for (int i = 0; i < periods; ++i) {
    const int size = i + 1 < periods ? s.period : packets - i * s.period;
    plan.window_first.push_back(i * s.period +
                                static_cast<int>(period_hash(static_cast<std::uint64_t>(i)) %
                                                 static_cast<std::uint64_t>(size - s.window + 1)));
    plan.strata.push_back(size);
  }
  plan.windows = periods;
  int end = 0;  // the packets before `end` are handed out or skipped
  for (int i = 0; i < periods; ++i) {
    const int window = plan.window_first[static_cast<std::size_t>(i)];
    const int next = i + 1 < periods ? plan.window_first[static_cast<std::size_t>(i) + 1] : packets;
    for (int k = std::max(end, window - s.warmup); k < window; ++k)
      plan.order.push_back(k);
    plan.marks.push_back(static_cast<int>(plan.order.size()));
    for (int k = window; k < window + s.window; ++k)
      plan.order.push_back(k);
    plan.marks.push_back(static_cast<int>(plan.order.size()));
    end = std::min(next, window + s.window + s.cooldown);
    for (int k = window + s.window; k < end; ++k)
      plan.order.push_back(k);
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

namespace {

// Least squares on the normal equations a x = b (a symmetric, positive semi-definite, k x k):
// Cholesky with a column whose pivot has vanished (no spread left once the earlier columns are
// fitted, such as transformations in a scene without instances) dropped, its coefficient 0.
std::vector<double> least_squares(std::vector<std::vector<double>> a, std::vector<double> b) {
  const std::size_t k = b.size();
  std::vector<bool> dropped(k, false);
  std::vector<std::vector<double>> l(k, std::vector<double>(k, 0.0));
  for (std::size_t j = 0; j < k; ++j) {
    double d = a[j][j];
    for (std::size_t m = 0; m < j; ++m)
      d -= l[j][m] * l[j][m];
    if (!(d > 1e-9 * a[j][j]) || a[j][j] <= 0) {
      dropped[j] = true;
      continue;
    }
    l[j][j] = std::sqrt(d);
    for (std::size_t i = j + 1; i < k; ++i) {
      double v = a[i][j];
      for (std::size_t m = 0; m < j; ++m)
        v -= l[i][m] * l[j][m];
      l[i][j] = v / l[j][j];
    }
  }
  // L z = b, then L^T x = z, over the kept columns.
  std::vector<double> z(k, 0.0), x(k, 0.0);
  for (std::size_t i = 0; i < k; ++i) {
    if (dropped[i]) continue;
    double v = b[i];
    for (std::size_t m = 0; m < i; ++m)
      v -= l[i][m] * z[m];
    z[i] = v / l[i][i];
  }
  for (std::size_t i = k; i-- > 0;) {
    if (dropped[i]) continue;
    double v = z[i];
    for (std::size_t m = i + 1; m < k; ++m)
      v -= l[m][i] * x[m];
    x[i] = v / l[i][i];
  }
  return x;
}

// A packet's features as the fit reads them: only the constant without features.
CostFeatures feature_row(const std::vector<CostFeatures>& features, std::size_t packet) {
  CostFeatures f{};
  f[0] = 1.0;
  if (!features.empty()) f = features.at(packet);
  return f;
}

// The least-squares coefficients of every measured packet's charge on its features (k of them).
std::vector<double> fit_charges(const std::vector<WindowCharges>& windows,
                                const std::vector<CostFeatures>& features, std::size_t k) {
  std::vector<std::vector<double>> a(k, std::vector<double>(k, 0.0));
  std::vector<double> b(k, 0.0);
  for (const WindowCharges& w : windows)
    for (std::size_t j = 0; j < w.charges.size(); ++j) {
      const CostFeatures f = feature_row(features, static_cast<std::size_t>(w.first) + j);
      for (std::size_t r = 0; r < k; ++r) {
        b[r] += f[r] * w.charges[j];
        for (std::size_t c = 0; c < k; ++c)
          a[r][c] += f[r] * f[c];
      }
    }
  return least_squares(a, b);
}

}  // namespace

FigureEstimate estimate_cycles(const std::vector<WindowCharges>& windows,
                               const std::vector<CostFeatures>& features, double sampled_fraction,
                               double* fit_correlation, std::vector<double>* fitted) {
  FigureEstimate e;
  const std::size_t n = windows.size();
  if (n == 0) return e;
  const std::size_t k = features.empty() ? 1 : static_cast<std::size_t>(kCostFeatures);
  const std::vector<double> beta = fit_charges(windows, features, k);
  const auto fit = [&](std::size_t packet) {
    const CostFeatures f = feature_row(features, packet);
    double v = 0;
    for (std::size_t r = 0; r < k; ++r)
      v += beta[r] * f[r];
    return v;
  };
  // The fit over the frame's packets (as many as the strata hold), and each window's residual.
  double packets = 0;
  for (const WindowCharges& w : windows)
    packets += w.stratum;
  if (features.empty()) {
    e.value = beta[0] * packets;
  } else {
    if (static_cast<double>(features.size()) != packets)
      throw std::logic_error("estimate_cycles: one feature row a packet of the frame");
    if (fitted != nullptr) fitted->assign(features.size(), 0.0);
    for (std::size_t p = 0; p < features.size(); ++p) {
      const double v = fit(p);
      e.value += v;
      if (fitted != nullptr) (*fitted)[p] = v;
    }
  }
  std::vector<double> residual(n), measured(n), window_fit(n);
  for (std::size_t i = 0; i < n; ++i) {
    const WindowCharges& w = windows[i];
    double y = 0, f = 0;
    for (std::size_t j = 0; j < w.charges.size(); ++j) {
      y += w.charges[j];
      f += fit(static_cast<std::size_t>(w.first) + j);
    }
    const auto size = static_cast<double>(std::max<std::size_t>(w.charges.size(), 1));
    measured[i] = y / size;
    window_fit[i] = f / size;
    residual[i] = measured[i] - window_fit[i];
    e.value += w.stratum * residual[i];
  }
  if (fit_correlation != nullptr) *fit_correlation = correlation(measured, window_fit);
  if (n < 2) return e;
  const double mr = mean_of(residual);
  double ss = 0;
  for (double r : residual)
    ss += (r - mr) * (r - mr);
  // The standard error of the mean residual, with the finite-population correction of sampling
  // a share `sampled_fraction` of the frame's packets.
  const double se = std::sqrt(ss / static_cast<double>(n - 1) / static_cast<double>(n) *
                              std::max(0.0, 1.0 - sampled_fraction));
  const double half = student_t975(static_cast<int>(n - 1)) * se * packets;
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
std::string defeated_because(const SampleSummary& s) {
  char buf[256];
  if (s.windows < kMinSampleWindows) {
    std::snprintf(buf, sizeof buf, "only %d windows (an interval needs at least %d)", s.windows,
                  kMinSampleWindows);
    return buf;
  }
  if (s.costly_windows < kMinCostlyWindows) {
    std::snprintf(buf, sizeof buf,
                  "the cost is concentrated in few packets (half of it in %llu of %llu packets, "
                  "which %d windows reach; an interval needs %d)",
                  static_cast<unsigned long long>(s.costly_packets),
                  static_cast<unsigned long long>(s.packets), s.costly_windows, kMinCostlyWindows);
    return buf;
  }
  return "";
}

// The fewest packets holding half the fitted cost of the frame, and how many windows reach them.
void costly_packets(const std::vector<double>& fitted, const SamplePlan& plan,
                    const SampleSpec& spec, SampleSummary& s) {
  std::vector<std::pair<double, std::size_t>> by_cost;
  double total = 0;
  for (std::size_t p = 0; p < fitted.size(); ++p) {
    by_cost.emplace_back(std::max(0.0, fitted[p]), p);
    total += std::max(0.0, fitted[p]);
  }
  std::sort(by_cost.begin(), by_cost.end(), std::greater<>());
  std::vector<bool> costly(fitted.size(), false);
  double held = 0;
  for (const auto& [cost, p] : by_cost) {
    if (held >= 0.5 * total) break;
    held += cost;
    costly[p] = true;
    ++s.costly_packets;
  }
  for (int first : plan.window_first)
    for (int k = first; k < first + spec.window; ++k)
      if (costly[static_cast<std::size_t>(k)]) {
        ++s.costly_windows;
        break;
      }
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

// The frame's figures from the run's windows and the packets' covariate into `c` (its usual
// fields) and `s`.
void estimate_frame(const units::CycleParams& p, const SamplePlan& plan, std::uint64_t packets,
                    const std::vector<CostFeatures>& features, CycleFrame& c, SampleSummary& s) {
  std::vector<units::FigureCounts> spans;
  std::vector<WindowCharges> windows;
  std::vector<double> cpp;
  for (std::size_t i = 0; i < static_cast<std::size_t>(plan.windows); ++i) {
    spans.push_back(units::span(c.marks[2 * i], c.marks[2 * i + 1]));
    // The window's packets' charged cycles: their own share of the machine.
    WindowCharges w;
    w.first = plan.window_first[i];
    w.stratum = plan.strata[i];
    w.charges.assign(c.packet_charges.begin() + plan.marks[2 * i],
                     c.packet_charges.begin() + plan.marks[2 * i + 1]);
    double sum = 0;
    for (double x : w.charges)
      sum += x;
    cpp.push_back(sum / static_cast<double>(w.charges.size()));
    windows.push_back(std::move(w));
  }
  const double f = static_cast<double>(plan.windows) * s.spec.window / static_cast<double>(packets);
  std::vector<double> fitted;
  FigureEstimate cycles = estimate_cycles(windows, features, f, &s.covariate_correlation, &fitted);
  costly_packets(fitted, plan, s.spec, s);
  // The cycles in which no packet was in flight (before the first hand-out, the frame buffer's
  // last writes) are the frame's as the sampled run's.
  const auto uncharged = static_cast<double>(c.uncharged_cycles);
  cycles.value += uncharged;
  cycles.ci.low += uncharged;
  cycles.ci.high += uncharged;
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
  s.defeated = defeated_because(s);
}

}  // namespace

CycleFrame run_sampled(const memif::MemoryImage& image, const units::CycleParams& params,
                       const CycleRunOptions& options, const SampleSpec& requested) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto& r = image.registers();
  const units::PacketTiling tiling =
      units::packet_tiling(static_cast<int>(r.width), static_cast<int>(r.height), params.packet);
  const int packets = tiling.count();
  const SampleSpec spec = resolve_sample_spec(requested, params, tiling);
  const SamplePlan plan = plan_sample(packets, spec);
  if (plan.windows == 0 || static_cast<int>(plan.order.size()) >= packets)
    return run_cycle(image, params, options);
  // The cost features of every packet, inside the run's host time: the chip's run does not read
  // them, so where the run may use two host threads (--host-threads 2) they are traced on one of
  // their own while the chip runs, else before it. covariate_seconds is their own time either way.
  double covariate_seconds = 0;
  const auto trace_features = [&image, &params, paths = cost_paths(image, options.shading),
                               &covariate_seconds] {
    const auto tc = std::chrono::steady_clock::now();
    std::vector<CostFeatures> f;
    for (const RayCost& r : packet_costs(image, params.packet, paths))
      f.push_back(cost_features(r));
    covariate_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - tc).count();
    return f;
  };
  std::future<std::vector<CostFeatures>> traced;
  std::vector<CostFeatures> features;
  if (options.programs == units::ProgramMode::kAhead)
    traced = std::async(std::launch::async, trace_features);
  else
    features = trace_features();
  CycleRunOptions o = options;
  o.packet_order = plan.order;
  o.marks = plan.marks;
  o.interval = 0;  // a time series of a sampled run would mix the periods
  o.charge_packets = true;
  CycleFrame c = run_cycle(image, params, o);
  if (traced.valid()) features = traced.get();
  auto s = std::make_shared<SampleSummary>();
  s->spec = spec;
  s->windows = plan.windows;
  s->packets = static_cast<std::uint64_t>(packets);
  s->packets_simulated = plan.order.size();
  s->cycles_simulated = c.cycles;
  s->covariate_seconds = covariate_seconds;
  estimate_frame(params, plan, static_cast<std::uint64_t>(packets), features, c, *s);
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
