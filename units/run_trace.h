// The cycle model's traces (docs/traces.md): the request trace (units/request_trace.h), a line
// per request when a unit issues it, and a Kanata log (version 0004, the format the Konata
// pipeline viewer opens) of each request's stages in its unit: queued on the input path, fetching
// its items, waiting for the data, ready, issuing, in the pipeline, waiting to be delivered. Both
// are written by a UnitObserver on every unit of the run; a run without them has none.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <limits>
#include <string>
#include <vector>

#include "units/cycle_unit.h"

namespace saarcor::units {

struct RunTraceOptions {
  std::ostream* trace = nullptr;     // request trace lines
  std::ostream* konata = nullptr;    // Kanata log
  std::ostream* perfetto = nullptr;  // Chrome trace-event JSON (units/perfetto_trace.h)
  // The cycle window: trace lines of requests issued in [from, to]; Kanata records of requests
  // that entered their unit (queued or, chained, issued) in [from, to]; the Perfetto timeline's
  // slices of requests issued and misses accepted in [from, to], its counters sampled in it.
  std::uint64_t from = 0;
  std::uint64_t to = std::numeric_limits<std::uint64_t>::max();
  std::vector<std::uint32_t> konata_threads;  // the Kanata log's threads; empty: every thread
  int packet = -1;  // >= 0: only this primary packet's requests (both outputs)
  bool any() const { return trace != nullptr || konata != nullptr || perfetto != nullptr; }
};

// The stage names of a Kanata record, in order (a zero-length stage is left out).
inline constexpr const char* kKonataStages[] = {"queue", "fetch", "wait", "ready",
                                                "issue", "pipe",  "out"};

class RunTracer final : public UnitObserver {
 public:
  // `threads_per_pipeline`: thread t belongs to DynRTP t / threads_per_pipeline. Writes the trace
  // header.
  RunTracer(const RunTraceOptions& options, const ThreadTable& threads, int threads_per_pipeline);

  void queued(std::uint64_t cycle, UnitId to, ThreadToken t) override;
  void accepted(std::uint64_t cycle, UnitId unit, ThreadToken t, int items) override;
  void fetched(std::uint64_t cycle, ThreadToken t) override;
  void ready(std::uint64_t cycle, ThreadToken t) override;
  void issued(std::uint64_t cycle, UnitId unit, ThreadToken t, const Request& r, int steps,
              std::uint64_t done_at) override;
  void left(std::uint64_t cycle, ThreadToken t) override;

  // Writes the Kanata log (its records are kept until the run ends: cycles in the file must
  // rise, and a record's stages are known only when it leaves). Call once, after the run.
  void finish();

  // A request's stay in a unit (kUnset: the stage did not happen).
  static constexpr std::uint64_t kUnset = std::numeric_limits<std::uint64_t>::max();
  struct Record {
    UnitId unit = UnitId::kNone;
    Phase phase = Phase::kDone;
    ThreadToken thread = 0;
    int packet = -1;
    std::uint32_t seq = 0;
    std::uint32_t item = memif::kNone;
    int steps = 0;
    std::uint64_t mask = 0;
    RayKind kind = RayKind::kPrimary;
    std::uint64_t queued = kUnset, accepted = kUnset, fetched = kUnset, ready = kUnset,
                  issued = kUnset, done_at = kUnset, left = kUnset;
    bool open = false;
  };
  // The records kept so far, in the order they left (tests).
  const std::vector<Record>& records() const { return done_; }

 private:
  void close(Record& r, std::uint64_t cycle);
  bool konata_thread(ThreadToken t) const {
    return konata_all_ || (t < konata_thread_.size() && konata_thread_[t]);
  }

  RunTraceOptions o_;
  const ThreadTable& threads_;
  int per_pipeline_;
  bool konata_all_ = true;
  std::vector<bool> konata_thread_;
  std::vector<Record> open_;  // per thread: the request in its current unit
  std::vector<Record> done_;  // Kanata records, in the order they left
};

// The Kanata log of `records` (the whole file): header, records in the order they entered, each
// with its label, its stages and its retirement, cycles rising.
void write_konata(std::ostream& out, std::vector<RunTracer::Record> records,
                  int threads_per_pipeline);

}  // namespace saarcor::units
