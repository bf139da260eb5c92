// Statistics registry of the simulation kernel (docs/hw.md; STYLE.md: gem5 stats with
// dotted names, unit and description; DRAMsim3's epoch dumps as a time series).
//
// Every statistic is declared once, by the module that updates it, with a hierarchical dotted
// name (`dynrtp0.traversal.busy_cycles`), a unit and one line of description. The registry owns
// the storage; modules keep the returned reference and update it in place (no lookup per cycle).
// Names are kept sorted, so every dump is deterministic. hw/ includes only std: JSON is written by
// hand.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace saarcor::hw {

// A monotonically updated integer (events, cycles, bytes). `set` exists for gauges such as a
// maximum occupancy.
struct Counter {
  std::uint64_t value = 0;
  Counter& operator+=(std::uint64_t n) {
    value += n;
    return *this;
  }
  Counter& operator++() {
    ++value;
    return *this;
  }
  void set(std::uint64_t v) { value = v; }
  void set_max(std::uint64_t v) {
    if (v > value) value = v;
  }
};

// Mean of the samples given to it (e.g. latency per request). Reports 0 when empty.
struct Average {
  double sum = 0.0;
  std::uint64_t count = 0;
  void sample(double v) {
    sum += v;
    ++count;
  }
  double mean() const { return count == 0 ? 0.0 : sum / static_cast<double>(count); }
};

// Fixed-width buckets [lo + i*width, lo + (i+1)*width), with underflow and overflow counts.
struct Histogram {
  double lo = 0.0;
  double width = 1.0;
  std::vector<std::uint64_t> buckets;
  std::uint64_t underflow = 0;
  std::uint64_t overflow = 0;
  std::uint64_t count = 0;
  double sum = 0.0;
  void sample(double v);
};

// The formulas the registry's derived figures are computed with (gem5's Formula operators), each
// written once: a cache's hit rate and a memory client's bandwidth (memif/), and the Table 4
// figures over the chip's sums of the same counters (units/figures.h).

// part / whole; 0 when whole is 0.
inline double ratio(std::uint64_t part, std::uint64_t whole) {
  return whole == 0 ? 0.0 : static_cast<double>(part) / static_cast<double>(whole);
}
// 100 part / whole; 0 when whole is 0.
inline double percent(std::uint64_t part, std::uint64_t whole) {
  return whole == 0 ? 0.0 : 100.0 * static_cast<double>(part) / static_cast<double>(whole);
}
// Bytes moved in `cycles` cycles at `clock_hz` as MB per second, MB = 2^20 bytes (D39); 0 over no
// cycles.
inline double mb_per_s(std::uint64_t bytes, std::uint64_t cycles, double clock_hz) {
  if (cycles == 0) return 0.0;
  return static_cast<double>(bytes) * clock_hz / static_cast<double>(cycles) / 1048576.0;
}

class Stats {
 public:
  enum class Kind { kCounter, kAverage, kHistogram, kFormula };

  Stats() = default;
  Stats(const Stats&) = delete;
  Stats& operator=(const Stats&) = delete;

  // Declare a statistic. A name may be declared once; a second declaration, an empty name or a
  // name with an empty dotted component throws std::logic_error naming it. References stay valid
  // for the registry's lifetime.
  Counter& counter(const std::string& name, const std::string& unit, const std::string& desc);
  Average& average(const std::string& name, const std::string& unit, const std::string& desc);
  Histogram& histogram(const std::string& name, const std::string& unit, const std::string& desc,
                       double lo, double width, int buckets);
  // A value computed when dumped (rates, ratios). The function must stay callable while the
  // registry is dumped.
  void formula(const std::string& name, const std::string& unit, const std::string& desc,
               std::function<double()> fn);

  bool contains(const std::string& name) const { return index_.count(name) != 0; }
  // Current value of a counter, average (mean), histogram (sample count) or formula; throws
  // std::logic_error for an unknown name.
  double value(const std::string& name) const;
  const Counter& get_counter(const std::string& name) const;
  std::vector<std::string> names() const;

  // Everything as one JSON object: {"name": {"kind":..., "unit":..., "desc":..., "value":...}}
  // sorted by name; histograms add lo, width, buckets, underflow, overflow.
  std::string json() const;

  // Time series (an epoch dump every `period` cycles): the kernel calls sample(cycle) at every
  // multiple of the period. Series hold counters, averages (mean) and formulas; the set of names
  // is fixed by the first sample (a later declaration throws).
  void set_time_series_period(std::uint64_t period) { period_ = period; }
  std::uint64_t time_series_period() const { return period_; }
  void sample(std::uint64_t cycle);
  // {"period": N, "names": [...], "samples": [[cycle, v0, v1, ...], ...]}
  std::string time_series_json() const;
  // The series as sampled: the names of its columns, and its rows ([cycle, v0, v1, ...]).
  const std::vector<std::string>& time_series_names() const { return series_names_; }
  const std::vector<std::vector<double>>& time_series() const { return series_; }
  // The column of the rows that holds counter `c` (column 0 is the cycle); throws
  // std::logic_error when `c` is not sampled (no sample yet, or not this registry's).
  std::size_t time_series_column(const Counter& c) const;

 private:
  struct Entry {
    std::string name, unit, desc;
    Kind kind;
    std::unique_ptr<Counter> c;
    std::unique_ptr<Average> a;
    std::unique_ptr<Histogram> h;
    std::function<double()> f;
  };
  Entry& declare(const std::string& name, const std::string& unit, const std::string& desc,
                 Kind kind);
  double entry_value(const Entry& e) const;

  std::vector<std::unique_ptr<Entry>> entries_;
  std::map<std::string, std::size_t> index_;  // sorted: deterministic dumps
  std::uint64_t period_ = 0;
  std::vector<std::size_t> series_entries_;
  std::vector<std::string> series_names_;
  std::unordered_map<const Counter*, std::size_t> series_columns_;
  std::vector<std::vector<double>> series_;
};

// JSON helpers shared by the hw/ and memif/ dumps.
std::string json_escape(const std::string& s);
std::string json_number(double v);

}  // namespace saarcor::hw
