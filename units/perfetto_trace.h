// The cycle model's timeline in the Chrome trace-event format (JSON), which Perfetto's UI and
// chrome://tracing open (docs/traces.md "Perfetto timeline"): one process per DynRTP, one track
// per unit with each issued request as a slice named by its phase and thread, one track per
// outstanding-miss slot (MSHR) of each cache with each miss as a slice from its acceptance to its
// fill, a flow arrow from a miss to the issue of the request that waited for it, and counters of
// the units' input queues, the threads holding a packet and each cache's hit rate. Cycles become
// microseconds at the modelled clock. Written from the same hooks as the request trace and the
// Kanata log (units/run_trace.h); tracing changes no figure.
#pragma once

#include <array>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "memif/cache.h"
#include "units/cycle_params.h"
#include "units/cycle_unit.h"
#include "units/figures.h"
#include "units/run_trace.h"

namespace saarcor::units {

// Counter samples are taken at most once every this many cycles (at the first hook call of each
// span); a cache's hit rate is that of the requests of the span since its last sample.
inline constexpr std::uint64_t kPerfettoCounterPeriod = 32;

// What the timeline reads besides the hooks: the chip's shape, its clock and its caches (per
// DynRTP: the traversal, list and transformation caches, Table 4's order).
struct PerfettoChip {
  int pipelines = 1;
  int threads_per_pipeline = 1;
  double clock_mhz = 90;
  int max_misses = 8;
  std::vector<std::array<const memif::Cache*, kCacheUnits>> caches;
};

class PerfettoTracer final : public UnitObserver, public memif::CacheObserver {
 public:
  // Keeps the events of the window [options.from, options.to] until finish() writes them to
  // *options.perfetto.
  PerfettoTracer(const RunTraceOptions& options, const ThreadTable& threads, PerfettoChip chip);

  void queued(std::uint64_t cycle, UnitId to, ThreadToken t) override;
  void accepted(std::uint64_t cycle, UnitId unit, ThreadToken t, int items) override;
  void fetched(std::uint64_t cycle, ThreadToken) override { sample(cycle); }
  void ready(std::uint64_t cycle, ThreadToken) override { sample(cycle); }
  void issued(std::uint64_t cycle, UnitId unit, ThreadToken t, const Request& r, int steps,
              std::uint64_t done_at) override;
  void left(std::uint64_t cycle, ThreadToken t) override;
  void miss(std::uint64_t cycle, const memif::Cache& cache, std::uint32_t item, int mshr,
            const memif::Label& label) override;
  void filled(std::uint64_t cycle, const memif::Cache& cache, int mshr) override;

  // Writes the file (events in time order, then the track names). `cycles`: the frame's length;
  // throws std::runtime_error (one line) when the window starts after it.
  void finish(std::uint64_t cycles);

  // What the file holds (tests): request slices per Table 4 unit and in all, miss slices, flows
  // (each a start and a finish), counter events.
  struct Counts {
    std::array<std::uint64_t, kTable4Units> unit_slices{};
    std::uint64_t slices = 0, misses = 0, flows = 0, counters = 0;
  };
  const Counts& counts() const { return counts_; }

 private:
  struct Event {
    std::uint64_t cycle;
    std::string json;
  };
  struct OpenMiss {
    std::uint64_t cycle = 0;
    std::uint32_t item = 0;
    ThreadToken thread = 0;
    bool open = false;
  };
  struct PendingFlow {
    std::uint64_t cycle;
    int tid;
  };
  bool in_window(std::uint64_t cycle) const { return cycle >= o_.from && cycle <= o_.to; }
  int pipeline_of(ThreadToken t) const { return static_cast<int>(t) / chip_.threads_per_pipeline; }
  void sample(std::uint64_t cycle);
  void sample_pipeline(std::uint64_t cycle, int p);
  void add_flows(std::uint64_t cycle, UnitId unit, ThreadToken t);
  std::string ts(std::uint64_t cycle) const;
  std::string dur(std::uint64_t from, std::uint64_t to) const;
  std::string head(const char* ph, const std::string& name, int pid, int tid,
                   std::uint64_t cycle) const;
  int cache_slot(const memif::Cache& cache, int& pipeline) const;
  void write_names(std::ostream& out) const;

  RunTraceOptions o_;
  const ThreadTable& threads_;
  PerfettoChip chip_;
  std::vector<Event> events_;
  std::uint64_t next_sample_ = 0;
  std::uint64_t next_flow_ = 1;
  std::vector<std::array<int, kMaxUnits>> queues_;  // per DynRTP, per unit: threads on its inputs
  std::vector<int> busy_;                           // per DynRTP: threads holding a packet
  std::vector<bool> busy_thread_;
  // Per DynRTP and cache: requests and hits (merges included) at the last sample.
  std::vector<std::array<std::array<std::uint64_t, 2>, kCacheUnits>> last_cache_;
  std::vector<OpenMiss> open_miss_;              // per DynRTP, cache and MSHR
  std::vector<std::vector<PendingFlow>> flows_;  // per thread: misses its next issue waited for
  Counts counts_;
};

// Forwards every hook to each observer of the list (the request trace, the Kanata log and the
// timeline of one run).
class ObserverFan final : public UnitObserver {
 public:
  void add(UnitObserver* o) { list_.push_back(o); }
  void queued(std::uint64_t c, UnitId to, ThreadToken t) override {
    for (UnitObserver* o : list_)
      o->queued(c, to, t);
  }
  void accepted(std::uint64_t c, UnitId u, ThreadToken t, int items) override {
    for (UnitObserver* o : list_)
      o->accepted(c, u, t, items);
  }
  void fetched(std::uint64_t c, ThreadToken t) override {
    for (UnitObserver* o : list_)
      o->fetched(c, t);
  }
  void ready(std::uint64_t c, ThreadToken t) override {
    for (UnitObserver* o : list_)
      o->ready(c, t);
  }
  void issued(std::uint64_t c, UnitId u, ThreadToken t, const Request& r, int steps,
              std::uint64_t done_at) override {
    for (UnitObserver* o : list_)
      o->issued(c, u, t, r, steps, done_at);
  }
  void left(std::uint64_t c, ThreadToken t) override {
    for (UnitObserver* o : list_)
      o->left(c, t);
  }
  void cache_request(std::uint64_t c, UnitId u, const memif::CacheRequest& r) override {
    for (UnitObserver* o : list_)
      o->cache_request(c, u, r);
  }
  void cache_response(std::uint64_t c, UnitId u, const memif::CacheResponse& r) override {
    for (UnitObserver* o : list_)
      o->cache_response(c, u, r);
  }
  void cache_blocked(std::uint64_t c, UnitId u) override {
    for (UnitObserver* o : list_)
      o->cache_blocked(c, u);
  }

 private:
  std::vector<UnitObserver*> list_;
};

}  // namespace saarcor::units
