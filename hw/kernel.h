// The simulation kernel (docs/hw.md): owns the clock, knows every module and channel,
// runs cycles as evaluate-all then commit-all, skips idle cycles, stops stuck runs with a
// watchdog report, keeps the statistics registry and drives the VCD tracer.
//
// A cycle c, as a script:
//   1. evaluate every module (registration order, or a fresh random order per cycle when
//      shuffle_seed != 0: the figures must not change), except modules that sleep (opt-in,
//      Module::sleep_when_idle) and have no event due: their cycle would repeat their last one;
//   2. trace (VCD, start-of-cycle channel state + this cycle's busy/stall);
//   3. commit every module that made progress (channels need no commit: hw/channel.h; their
//      pushes and pops wake the declared consumer / producer when they happen);
//   4. busy/stall statistics, time-series sample, clock advances to c+1;
//   5. if nothing happened (no progress, no channel activity) and idle skipping is on, jump to the
//      earliest cycle at which something can happen (a channel item's latency elapses, a module's
//      next_wakeup, the watchdog deadline, the next time-series sample, the cycle limit). The
//      jumped-over cycles would have been exact repeats, so every figure is identical.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "hw/channel.h"
#include "hw/module.h"
#include "hw/schedule.h"
#include "hw/stats.h"

namespace saarcor::hw {

class VcdTracer;

struct KernelConfig {
  bool idle_skip = true;                   // jump over cycles in which nothing can change
  std::uint64_t watchdog_cycles = 100000;  // stop after this many cycles without progress
  std::uint64_t shuffle_seed = 0;          // != 0: evaluate modules in a random order every cycle
  std::uint64_t time_series_period = 0;    // != 0: Stats::sample every this many cycles
};

struct RunResult {
  enum class Status { kDone, kCycleLimit, kWatchdog };
  Status status = Status::kDone;
  std::uint64_t cycles = 0;  // the clock when the run stopped
  std::string report;        // watchdog: every module's dump_state and channel occupancies
  bool done() const { return status == Status::kDone; }
};

class Kernel {
 public:
  explicit Kernel(KernelConfig config = {});
  ~Kernel();
  Kernel(const Kernel&) = delete;
  Kernel& operator=(const Kernel&) = delete;

  KernelConfig& config() { return config_; }
  std::uint64_t now() const { return cycle_; }
  Stats& stats() { return stats_; }
  const Stats& stats() const { return stats_; }

  // Runs until done() holds (checked before every cycle; it must depend on model state only, not
  // on the cycle number: use max_cycles for that), until max_cycles is reached, or until the
  // watchdog fires. Returns why it stopped.
  RunResult run(const std::function<bool()>& done, std::uint64_t max_cycles = kNever);
  // Like run(), but throws std::runtime_error (first line: why; then the report) unless done.
  std::uint64_t run_to_completion(const std::function<bool()>& done,
                                  std::uint64_t max_cycles = kNever);
  // Exactly one cycle, never skipping. Returns the progress made (module progress + channel
  // pushes and pops).
  int step();

  // The watchdog report for the current state.
  std::string state_report() const;

  // VCD trace of cycles [from, to] (inclusive) to `out`, which must outlive the kernel's runs;
  // finish_trace() writes the closing timestamp (call it before closing the stream).
  void trace_vcd(std::ostream& out, std::uint64_t from, std::uint64_t to);
  void finish_trace();

  // Idle cycles jumped over so far (a performance figure; deliberately not a statistic, since
  // statistics must not depend on skipping).
  std::uint64_t skipped_cycles() const { return skipped_; }
  std::uint64_t evaluated_cycles() const { return evaluated_; }
  std::uint64_t module_evaluations() const { return evaluations_; }
  // A VCD trace is set (it samples every channel and module every cycle: fast paths that serve
  // work without moving it through channels stay off).
  bool tracing() const { return tracer_ != nullptr; }

  // Kernel-owned construction: the object lives as long as the kernel (modules and channels may
  // also be owned elsewhere; they register themselves either way).
  template <class M, class... Args>
  M& make(Args&&... args) {
    auto m = std::make_unique<M>(*this, std::forward<Args>(args)...);
    M& ref = *m;
    owned_modules_.push_back(std::move(m));
    return ref;
  }
  template <class T>
  Channel<T>& make_channel(std::string name, int capacity, int latency = 1, int width = 1) {
    auto c = std::make_unique<Channel<T>>(*this, std::move(name), capacity, latency, width);
    Channel<T>& ref = *c;
    owned_channels_.push_back(std::move(c));
    return ref;
  }

  const std::vector<Module*>& modules() const { return modules_; }
  const std::vector<ChannelBase*>& channels() const { return channels_; }

 private:
  friend class Module;
  friend class ChannelBase;
  void add_module(Module* m);
  void add_channel(ChannelBase* c);
  std::uint64_t next_event() const;
  void skip_to(std::uint64_t target);
  int step_cycle();
  RunResult run_cycles(const std::function<bool()>& done, std::uint64_t max_cycles);
  void wake_all();
  void account(Module* m);
  void account_all();
  std::uint64_t idle_wakeup(const Module& m) const;

  KernelConfig config_;
  std::uint64_t cycle_ = 0;
  std::uint64_t progress_mark_ = 0;  // the cycle after the last one with progress
  std::uint64_t trace_from_ = 0;
  std::uint64_t skipped_ = 0, evaluated_ = 0, evaluations_ = 0;
  Stats stats_;
  std::vector<Module*> modules_;
  std::vector<Module*> order_;
  std::vector<Module*> awake_;  // the modules to commit in the current cycle
  // Per sleeping module (at Module::slot_, from 1; slot 0 takes the wake-ups of channel ends
  // that are undeclared or belong to modules that do not sleep): the earliest cycle it must be
  // evaluated in. Lowered by channel pushes and pops, set after evaluation.
  Schedule schedule_;
  std::vector<std::uint64_t> due_;     // the current cycle's due modules (Schedule::take)
  std::vector<std::uint64_t> always_;  // the modules that do not sleep (by slot, as due_)
  std::uint64_t moves_ = 0;            // channel pushes and pops so far
  std::vector<ChannelBase*> channels_;
  std::mt19937_64 rng_;
  std::unique_ptr<VcdTracer> tracer_;
  // Declared last: destroyed first, while the registry they registered with still exists.
  std::vector<std::unique_ptr<ChannelBase>> owned_channels_;
  std::vector<std::unique_ptr<Module>> owned_modules_;
};

}  // namespace saarcor::hw
