// Clocked modules of the simulation kernel (docs/hw.md; STYLE.md habits 1-2, ChampSim's
// operable): one unit shape for every piece of hardware.
//
// A cycle is two phases. evaluate(): read only state committed at the end of the previous cycle
// (own registers via Reg::get, input channels via can_pop/peek/pop, output channels via
// can_push/push) and stage writes; return how much progress was made. commit(): make the staged
// register writes visible (channels are committed by the kernel). The result of a cycle must not
// depend on the order in which modules are evaluated; Reg and Channel make that hold by
// construction as long as modules share state only through them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hw/channel.h"
#include "hw/stats.h"

namespace saarcor::hw {

class Kernel;

class Module {
 public:
  // Registers the module with the kernel; it is evaluated in registration order unless the kernel
  // shuffles. Modules and channels must outlive the kernel's runs and dumps.
  Module(Kernel& kernel, std::string name);
  virtual ~Module() = default;
  Module(const Module&) = delete;
  Module& operator=(const Module&) = delete;

  const std::string& name() const { return name_; }

  // One cycle's combinational work. Returns the progress made: > 0 whenever any state changed
  // (item moved, register staged with a new value, counter advanced). 0 means "this cycle changed
  // nothing"; the kernel's idle skip and watchdog rely on it being truthful.
  virtual int evaluate() = 0;
  // Makes staged register writes visible. Called after all evaluate()s for every module that
  // made progress (one that made none staged nothing). (The default does nothing and tells the
  // kernel so: it is then not called again. The same holds for skipped(); an override must not
  // call the base version.)
  virtual void commit() { commit_is_noop_ = true; }
  // One or more lines for the watchdog report: what the module holds and what it waits for.
  virtual std::string dump_state() const { return {}; }
  // Earliest cycle > now at which evaluate() could make progress if no channel changes, given
  // that it made none in cycle now (internal timers, e.g. a memory latency). kNever: only a
  // channel change can wake it. The default (now + 1) is always safe but disables idle skipping.
  virtual std::uint64_t next_wakeup(std::uint64_t now) const { return now + 1; }
  // Called when the kernel skipped `cycles` idle cycles after the last evaluated one; those
  // cycles would each have repeated the last one exactly (progress 0). A module that counts
  // something per cycle in evaluate() adds it here, so statistics do not depend on skipping.
  // busy/stall cycles are kept by the kernel already.
  virtual void skipped(std::uint64_t /*cycles*/) { skipped_is_noop_ = true; }

  // The earliest cycle > now at which state that the run's done() test or the figures read
  // changes without any module being evaluated (a fast path's completion cycles, e.g. memif's
  // lanes): the idle skip jumps no further than that. Asked only of modules that declared one
  // (bound_idle_skip) and only when a cycle made no progress.
  virtual std::uint64_t skip_bound(std::uint64_t /*now*/) const { return kNever; }

  // Kernel-kept per-module statistics: <name>.busy_cycles, <name>.stall_cycles (the registry's
  // counters, for readers that keep a reference instead of looking them up by name; brought up to
  // date when a run returns).
  bool busy() const { return last_progress_ > 0; }
  bool stalled() const { return stalled_; }
  const Counter& busy_counter() const { return *busy_stat_; }
  const Counter& stall_counter() const { return *stall_stat_; }
  // Whether the module sleeps between events (see sleep_when_idle).
  bool sleeps() const { return sleeps_; }

 protected:
  // Opt-in event scheduling: the module promises that its evaluate() depends only on its own
  // state, on time through next_wakeup(), and on the channels it declared with consumes() and
  // produces() (each of its channels, every end it touches). The kernel then evaluates it only in
  // cycles where something it depends on may have changed: the cycle after it made progress, an
  // item pushed to one of its inputs becoming visible, a pop freeing room in one of its outputs
  // that was full, its next_wakeup(), and the first cycle of every run()/step(). (So a producer
  // may look at its outputs only through can_push()/push(): their occupancy is not an event.)
  // Skipped cycles would have repeated its last idle cycle exactly, so every figure is the same as
  // evaluating every cycle (KernelConfig::idle_skip = false evaluates every module every cycle: the
  // reference).
  void sleep_when_idle() { sleeps_ = true; }
  // This module pops from `c` (its one consumer) / pushes into `c` (its one producer). Throws
  // std::logic_error if another module already holds that end.
  void consumes(ChannelBase& c);
  void produces(ChannelBase& c);

  // Marks this cycle as a stall: the module has work but is blocked (full output, no credit).
  void stall() { stalled_ = true; }
  // Fast paths (work served in closed form, without the evaluations the stepped model spends on
  // it) book the busy and stall cycles that work stands for: cycles counted here are on top of
  // the kernel's count of evaluated and repeated cycles, so the caller counts only cycles the
  // kernel does not (a busy cycle in which evaluate() made no progress, a stall cycle that was
  // neither evaluated as stalled nor repeated from a stalled evaluation).
  // `unstall`: cycles the kernel counted (or is about to count, for the cycle being evaluated) as
  // stalled that the work served stands for progress in.
  void count_cycles(std::uint64_t busy, std::uint64_t stall, std::uint64_t unstall = 0) {
    busy_count_ += busy;
    stall_count_ += stall;
    stall_count_ -= unstall;  // (the kernel's count is added first, or in this cycle)
  }
  // Counts the cycles since the module's last evaluation now, as the kernel would before its next
  // evaluation (repeats of the last one, then skipped()); nothing if it was evaluated in this
  // cycle already. For a fast path that books cycles as they pass (count_cycles).
  void account_now();
  // The module overrides skip_bound().
  void bound_idle_skip() { bounds_skip_ = true; }
  Kernel& kernel() const { return *kernel_; }
  Stats& stats() const;
  std::uint64_t now() const { return *now_; }

 private:
  friend class Kernel;
  friend class ChannelBase;
  // What the kernel touches every evaluation comes first (one cache line with the vtable pointer).
  const std::uint64_t* now_;
  // Event scheduling: evaluated in cycle c only if the kernel's wake cycle at slot_ is <= c;
  // cycles before accounted_ have their busy/stall statistics and skipped() counted (the rest are
  // counted lazily on waking).
  std::uint64_t accounted_ = 0;
  std::size_t slot_ = 0;
  // busy/stall cycles not yet handed to the registry (Kernel::account_all does).
  std::uint64_t busy_count_ = 0, stall_count_ = 0;
  int last_progress_ = 0;
  bool stalled_ = false;
  bool sleeps_ = false;
  bool bounds_skip_ = false;
  bool skipped_is_noop_ = false;  // set by the default skipped(): the kernel stops calling it
  bool commit_is_noop_ = false;   // set by the default commit(): the kernel stops calling it
  Kernel* kernel_;
  std::vector<ChannelBase*> inputs_;  // consumed channels: their front items wake the module
  Counter* busy_stat_ = nullptr;
  Counter* stall_stat_ = nullptr;
  std::string name_;
};

// A register inside a module: get() returns the value committed last cycle, set() stages the next
// value, commit() (called from the owning module's commit()) makes it current.
template <class T>
class Reg {
 public:
  explicit Reg(T init = T{}) : cur_(init), next_(init) {}
  const T& get() const { return cur_; }
  void set(const T& v) { next_ = v; }
  T& next() { return next_; }  // stage a partial update of a struct register
  void commit() { cur_ = next_; }

 private:
  T cur_, next_;
};

}  // namespace saarcor::hw
