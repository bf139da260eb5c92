// The shape every DynRTP unit of the cycle model shares (paper section 3.1, Figure 2;
// docs/cycle-model.md; decisions D20, D25, D32): thread ids arrive on input paths (FIFO queues, one
// per path, served by a fixed priority), the unit fetches the item the thread's request names
// through its cache (one request per packet; a matrix is several row items), the thread waits for
// the data without blocking the unit, ready threads are issued in the order their data arrived, a
// request occupies the unit's issue slot for its steps, and after the pipeline depth the thread
// leaves on the path to the unit its next request names.
//
// What a thread computes is decided only by the thread program (units/thread_program.h): the unit
// calls ThreadTable::execute(t) once per request, at issue. Timing decides when, never what.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "hw/kernel.h"
#include "hw/ring.h"
#include "memif/cache.h"
#include "units/request_trace.h"
#include "units/thread_program.h"

namespace saarcor::units {

// A unit's slot in the arrays indexed by unit (kMaxUnits slots: Figure 2's units and added ones).
inline int unit_index(UnitId u) {
  return static_cast<int>(u);
}

// The threads of one DynRTP as the units see them (the thread program behind an interface, so the
// units are independent of the float format). A thread's request changes only when it executes
// or starts a packet, so the table keeps each thread's current request (the units read it several
// times per step: a plain array read, not a call).
class ThreadTable {
 public:
  virtual ~ThreadTable() = default;
  int size() const { return static_cast<int>(requests_.size()); }
  const Request& request(std::uint32_t thread) const { return requests_[thread]; }
  // Runs the thread's current request and stores its next one.
  virtual void execute(std::uint32_t thread) = 0;
  // The RGC hands thread `thread` primary packet `packet` (path a starts from here).
  virtual void start_primary(std::uint32_t thread, int packet) = 0;
  virtual int packets() const = 0;
  // A traced run (units/run_trace.h): the request thread `thread` executed last, as the trace
  // names it (packet, position, rays, kind, transactions). Empty when the run does not trace.
  virtual const TracedStep& traced(std::uint32_t /*thread*/) const {
    static const TracedStep kNothing;
    return kNothing;
  }
  // The memory accesses of the RGS request thread `thread` executed last (shading-bank reads,
  // frame-buffer writes; units/program_types.h RgsAccess). Empty for a table without them.
  virtual const std::vector<RgsAccess>& rgs_memory(std::uint32_t /*thread*/) const {
    static const std::vector<RgsAccess> kNone;
    return kNone;
  }

 protected:
  std::vector<Request> requests_;  // one per thread
};

// The ready queue, pipeline and free list hold thread ids, at most one entry per thread, so their
// capacity is the thread count.
using hw::Ring;

// A thread id on a path between units.
using ThreadToken = std::uint32_t;
using ThreadPath = hw::Channel<ThreadToken>;

// What a traced run observes of a thread's way through the units (units/run_trace.h writes the
// request trace and the Kanata log from it). Null in a run that traces nothing: every hook is one
// pointer test. Called from evaluate() with the current cycle, in the order the unit's script runs.
class UnitObserver {
 public:
  virtual ~UnitObserver() = default;
  // Thread t was pushed on the path towards unit `to`, its next request's unit.
  virtual void queued(std::uint64_t cycle, UnitId to, ThreadToken t) = 0;
  // `unit` took t from its input path and fetches `items` cache items (0: t is ready at once).
  virtual void accepted(std::uint64_t cycle, UnitId unit, ThreadToken t, int items) = 0;
  // t's last cache request went out.
  virtual void fetched(std::uint64_t cycle, ThreadToken t) = 0;
  // t's last cache response arrived: t waits for the issue slot.
  virtual void ready(std::uint64_t cycle, ThreadToken t) = 0;
  // t's request r was executed and issued for `steps` cycles; it leaves the pipeline at `done_at`,
  // or, chained (0), its next request on this unit issues right behind it.
  virtual void issued(std::uint64_t cycle, UnitId unit, ThreadToken t, const Request& r, int steps,
                      std::uint64_t done_at) = 0;
  // t left the pipeline: pushed on the path to its next unit (queued follows), or retired.
  virtual void left(std::uint64_t cycle, ThreadToken t) = 0;
  // The cache port of `unit` (the boundary record, units/boundary.h): a request pushed, a
  // response taken, a request held back because the cache's request queue was full.
  virtual void cache_request(std::uint64_t /*cycle*/, UnitId /*unit*/,
                             const memif::CacheRequest& /*r*/) {}
  virtual void cache_response(std::uint64_t /*cycle*/, UnitId /*unit*/,
                              const memif::CacheResponse& /*r*/) {}
  virtual void cache_blocked(std::uint64_t /*cycle*/, UnitId /*unit*/) {}
};

class CycleUnit : public hw::Module {
 public:
  // `cache` may be null (a unit that reads no scene data); `depth` = pipeline depth in cycles.
  CycleUnit(hw::Kernel& kernel, std::string name, UnitId id, ThreadTable& threads, int depth,
            memif::Cache* cache);

  // Inputs in priority order (the first non-empty path is served, D25).
  void add_input(ThreadPath* path) {
    if (input_count_ == kMaxUnits) throw std::logic_error(name() + ": more input paths than units");
    consumes(*path);
    input_[input_count_++] = path;
  }
  // The path towards unit `to` (also a path back into this unit: the unit's own loop).
  void set_output(UnitId to, ThreadPath* path) {
    produces(*path);
    outputs_[unit_index(to)] = path;
  }

  // Every hook of the unit reports to `o` (null: none, the default).
  void set_observer(UnitObserver* o) { observer_ = o; }
  UnitId id() const { return id_; }
  int depth() const { return depth_; }
  std::uint64_t issue_cycles() const { return issued_->value; }
  std::uint64_t requests_served() const { return served_->value; }
  // The same counts as the registry's counters (<name>.issue_cycles, <name>.requests).
  const hw::Counter& issue_counter() const { return *issued_; }
  const hw::Counter& served_counter() const { return *served_; }
  // Threads inside the unit (fetching, waiting for data, ready, issuing, in the pipeline).
  int occupancy() const { return inside_; }

  int evaluate() override;
  std::string dump_state() const override;
  std::uint64_t next_wakeup(std::uint64_t now) const override;

 protected:
  // The items of the unit's cache a request needs: `count` consecutive items from `first`.
  struct Fetch {
    std::uint32_t first = 0;
    int count = 0;
  };
  virtual Fetch fetch(const Request& r) const = 0;
  // Whether the thread's next request, on this unit again, issues right behind the current one
  // without a pipeline round trip (the faces of a box clip; RGS phases).
  virtual bool chains(const Request& /*done*/, const Request& /*next*/) const { return false; }
  // Called when a thread's request is `kDone` after this unit (only the RGS frees threads).
  virtual void retire(ThreadToken /*thread*/) {}
  // Extra work of the cycle after the shared steps (the RGS admits packets here; a unit that
  // overrides it sets has_extra_).
  virtual int extra() { return 0; }
  virtual std::uint64_t extra_wakeup(std::uint64_t /*now*/) const { return hw::kNever; }
  // Called at issue, after the thread's request executed: true if the unit keeps the thread
  // outside the pipeline (the RGS, while its memory accesses are served) and lets it go with
  // leave() itself.
  virtual bool hold(ThreadToken /*thread*/) { return false; }
  // Thread t leaves the unit: on the path to its next request's unit, or retired when it is done.
  // False (nothing changed) if that path is full.
  bool leave(ThreadToken t);

  // The cycle, as a script (evaluate() calls these in this order).
  int deliver();  // threads whose pipeline latency elapsed leave on their next path
  int issue();    // the issue slot: one step of the current request, or the next ready thread
  int receive();  // one cache response: its thread becomes ready when all its items arrived
  int accept(ThreadPath* from);  // one thread from `from` (null while fetching); one request out

  ThreadTable& threads_;
  std::array<ThreadPath*, kMaxUnits> outputs_{};
  int inside_ = 0;
  bool has_extra_ = false;
  UnitObserver* observer_ = nullptr;

 private:
  struct InFlight {
    std::uint64_t done_at;
    ThreadToken thread;
  };
  // The first input path (in priority order) with a thread to take; null if none.
  ThreadPath* waiting_input() const {
    for (int i = 0; i < input_count_; ++i)
      if (input_[i]->can_pop()) return input_[i];
    return nullptr;
  }

  UnitId id_;
  int depth_;
  memif::Cache* cache_;
  hw::Channel<memif::CacheRequest>* cache_requests_ = nullptr;
  hw::Channel<memif::CacheResponse>* cache_responses_ = nullptr;
  std::array<ThreadPath*, kMaxUnits> input_{};  // in priority order (inline: scanned every cycle)
  int input_count_ = 0;
  // Fetch stage: the thread whose cache requests are being sent.
  bool fetching_ = false;
  ThreadToken fetch_thread_ = 0;
  std::uint32_t fetch_next_ = 0;
  int fetch_left_ = 0;
  std::vector<int> waiting_;  // per thread: cache responses still expected
  int waiting_threads_ = 0;
  Ring<ThreadToken> ready_;
  // Issue slot.
  int steps_left_ = 0;
  bool chained_ = false;
  ThreadToken chain_thread_ = 0;
  Ring<InFlight> pipeline_;
  std::uint64_t deliver_at_ = hw::kNever;  // the pipeline's front done_at, kNever when empty
  hw::Counter* issued_;
  hw::Counter* served_;
};

// (Inline: every unit's deliver() runs it for each thread it lets go.)
inline bool CycleUnit::leave(ThreadToken t) {
  const Request& next = threads_.request(t);
  if (next.unit == UnitId::kNone) {
    --inside_;
    if (observer_ != nullptr) [[unlikely]]
      observer_->left(now(), t);
    retire(t);
    return true;
  }
  ThreadPath* out = outputs_[unit_index(next.unit)];
  if (out == nullptr)
    throw std::logic_error(name() + ": no path to the " + unit_name(next.unit) + " unit");
  if (!out->can_push()) return false;
  out->push(t);
  if (observer_ != nullptr) [[unlikely]] {
    observer_->left(now(), t);
    observer_->queued(now(), next.unit, t);
  }
  --inside_;
  return true;
}

}  // namespace saarcor::units
