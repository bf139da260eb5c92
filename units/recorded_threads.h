// The thread table of the cycle model: one thread program per simulated thread, or programs
// recorded per packet and replayed (docs/cycle-model.md "Programs ahead of the simulation"):
// the record/replay machinery, apart from the DynRTP's assembly (units/dynrtp.cpp) and the chip
// that clocks it (testbench/chip.cpp).
#pragma once

#include <algorithm>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "units/cycle_unit.h"
#include "units/dynrtp.h"
#include "units/fast_datapath.h"
#include "units/functional_model.h"
#include "units/request_trace.h"
#include "units/run_trace.h"
#include "units/thread_program.h"

namespace saarcor::units {

// The thread table: one thread program per thread, all sharing the DynRTP's float units and the
// frame sink (their only shared state; both sum order-independently).
//
// Recorded programs (CycleRunOptions::programs; docs/cycle-model.md, "Programs ahead"): what a
// thread computes never depends on timing, and a packet's computation does not depend on the
// thread that runs it (the mailbox, stack and child packets start afresh with every primary
// packet, D28). So one program runs a packet's whole request sequence at once, as the functional
// model does, and records it; the simulated thread the RGC hands the packet replays it, and
// execute() is a copy. The same requests reach the units, so every figure and result is the same
// as with a program per thread (tested). kPacketFirst records a packet when the RGC hands it out;
// kAhead records the packets in the RGC's order on a second host thread.
template <class F, int kLanes>
class RecordedThreads final : public ThreadTable {
 public:
  // kAhead: at most `ahead` finished packets ahead of the simulation. `order`: the frame's
  // packets the RGC hands out, in its order (a sampled run's windows, testbench/sampling.h); empty:
  // every packet of the frame, in tiling order.
  RecordedThreads(const memif::MemoryImage& image, const FunctionalParams& params, int threads,
                  ProgramMode mode, int ahead, const RunTraceOptions& trace = {},
                  std::vector<int> order = {})
      : params_(params),
        order_(std::move(order)),
        units_(params.mode),
        mode_(mode),
        recorded_(mode != ProgramMode::kPerStep),
        max_ahead_(mode == ProgramMode::kAhead ? static_cast<std::size_t>(ahead) : 0) {
    w_ = static_cast<int>(image.registers().width);
    h_ = static_cast<int>(image.registers().height);
    tiling_ = packet_tiling(w_, h_, params.packet);
    for (int p : order_)
      if (p < 0 || p >= tiling_.count())
        throw std::logic_error("cycle model: packet " + std::to_string(p) + " of " +
                               std::to_string(tiling_.count()) + " in the RGC's order");
    sink_.reset(w_, h_,
                order_.empty() || order_.size() >= static_cast<std::size_t>(tiling_.count()));
    requests_.resize(static_cast<std::size_t>(threads));
    if (trace.any()) {
      tracing_ = true;
      capture_ = trace.trace != nullptr;
      trace_packet_ = trace.packet;
      traced_.resize(static_cast<std::size_t>(threads));
      per_step_.resize(static_cast<std::size_t>(threads));
    }
    if (!recorded_) {
      for (int i = 0; i < threads; ++i) {
        programs_.push_back(std::make_unique<ThreadProgram<F, kLanes, FastDatapath>>(
            image, params_, units_, sink_));
        requests_[static_cast<std::size_t>(i)] = programs_.back()->request();
      }
      return;
    }
    // Slots for every packet in flight (at most one per thread) and for the finished ones.
    slots_.resize(static_cast<std::size_t>(threads) + max_ahead_);
    for (std::size_t i = 0; i < slots_.size(); ++i)
      free_.push_back(i);
    cursor_.resize(static_cast<std::size_t>(threads));
    rgs_mem_.resize(static_cast<std::size_t>(threads));
    programs_.push_back(
        std::make_unique<ThreadProgram<F, kLanes, FastDatapath>>(image, params_, units_, sink_));
    for (int i = 0; i < threads; ++i)
      requests_[static_cast<std::size_t>(i)] = programs_.back()->request();
    if (mode_ == ProgramMode::kAhead) worker_ = std::thread([this] { run_ahead(); });
  }
  ~RecordedThreads() override { stop(); }
  RecordedThreads(const RecordedThreads&) = delete;
  RecordedThreads& operator=(const RecordedThreads&) = delete;

  void execute(std::uint32_t t) override {
    if (recorded_) {
      Cursor& c = cursor_[t];
      if (tracing_) [[unlikely]]
        note_replayed(t);
      Slot& s = slots_[c.slot];
      // The RGS's accesses, copied out before the replay of a final step releases the slot.
      if (s.trace[c.next].unit == UnitId::kRgs) [[unlikely]] {
        const std::uint32_t begin = c.rgs == 0 ? 0 : s.mem_end[c.rgs - 1];
        rgs_mem_[t].assign(s.mem.begin() + begin, s.mem.begin() + s.mem_end[c.rgs]);
        ++c.rgs;
      }
      // The pop engine's cycles, read before the replay of a final step releases the slot.
      const std::uint16_t pops = s.pops[c.next + 1];
      replay(t, s.trace[++c.next]);
      requests_[t].pop_cycles = pops;
      return;
    }
    if (tracing_) [[unlikely]]
      return execute_traced(t);
    ThreadProgram<F, kLanes, FastDatapath>& p = *programs_[t];
    p.execute();
    // Returned straight into the table (guaranteed elision): a copy of the returned temporary
    // would reload a struct the callee has just written field by field (a store-forward stall).
    ::new (static_cast<void*>(&requests_[t])) Request(p.request());
  }
  // `ordinal`: the RGC's hand-out count, the packet order_ names there.
  void start_primary(std::uint32_t t, int ordinal) override {
    const int packet = packet_at(ordinal);
    if (mode_ == ProgramMode::kPacketFirst) {
      Cursor& c = cursor_[t];
      c = {free_.back(), 0, 0};
      free_.pop_back();
      record(slots_[c.slot], *programs_[0], packet);
      replay(t, slots_[c.slot].trace[0]);
      return;
    }
    if (mode_ == ProgramMode::kAhead) {
      Cursor& c = cursor_[t];
      c = {take(packet), 0, 0};
      // The trace was written on the other core: pull all of it towards this one now, while the
      // thread's first requests wait in the units (its entries are read one per step later).
      const std::vector<Step>& trace = slots_[c.slot].trace;
      const char* bytes = reinterpret_cast<const char*>(trace.data());
      for (std::size_t b = 0; b < trace.size() * sizeof(Step); b += 64)
        __builtin_prefetch(bytes + b);
      replay(t, trace[0]);
      return;
    }
    programs_[t]->start_primary(packet_pixels(tiling_, w_, h_, packet));
    ::new (static_cast<void*>(&requests_[t])) Request(programs_[t]->request());
    if (tracing_) per_step_[t] = {packet, 0};
  }
  const TracedStep& traced(std::uint32_t t) const override {
    return tracing_ ? traced_[t] : ThreadTable::traced(t);
  }
  const std::vector<RgsAccess>& rgs_memory(std::uint32_t t) const override {
    return recorded_ ? rgs_mem_[t] : programs_[t]->rgs_memory();
  }
  int packets() const override {
    return order_.empty() ? tiling_.count() : static_cast<int>(order_.size());
  }
  // The packet the RGC hands out `ordinal`-th.
  int packet_at(int ordinal) const {
    return order_.empty() ? ordinal : order_[static_cast<std::size_t>(ordinal)];
  }
  // The rays thread `t`'s current request concerns (for the watchdog's thread report; the units
  // never read it, so a replayed request carries it only in its slot).
  std::uint64_t mask(std::uint32_t t) const {
    if (!recorded_) return requests_[t].mask;
    const Cursor& c = cursor_[t];
    return slots_[c.slot].masks[c.next];
  }

  // Waits for the program thread (it has run every packet once the RGC has retired them all) and
  // rethrows what it threw; the units and the sink are then complete.
  void finish() {
    stop();
    if (error_) std::rethrow_exception(error_);
  }

  PipelineUnits<F>& units() { return units_; }
  FrameSink& sink() { return sink_; }
  const FunctionalParams& params() const { return params_; }

 private:
  // A request as the units see it (the mask apart): 8 bytes instead of a Request's 24, so a
  // packet's trace, written on the program thread's core and read on the simulation's, is a
  // third of the cache lines to move.
  struct Step {
    UnitId unit;
    Phase phase;
    std::uint16_t steps;
    std::uint32_t item;
  };
  static_assert(sizeof(Step) == 8);
  // One packet's request sequence, from the request after start_primary to the final kDone, and
  // each request's ray mask beside it.
  struct Slot {
    std::vector<Step> trace;
    std::vector<std::uint64_t> masks;
    // Beside each request: the pop engine's cycles of the request before it (Request::pop_cycles).
    std::vector<std::uint16_t> pops;
    int packet = -1;
    // A traced run: per executed request, the packet's kind and (with the request trace) the
    // transactions.
    std::vector<RayKind> kinds;
    std::vector<std::string> txns;
    // The RGS requests' memory accesses, request after request; mem_end[k] ends the k-th's.
    std::vector<RgsAccess> mem;
    std::vector<std::uint32_t> mem_end;
  };
  // After program `p` executed request `r`: an RGS request's accesses into the slot.
  static void note_memory(Slot& s, const ThreadProgram<F, kLanes, FastDatapath>& p,
                          const Request& r) {
    if (r.unit != UnitId::kRgs) return;
    const std::vector<RgsAccess>& m = p.rgs_memory();
    s.mem.insert(s.mem.end(), m.begin(), m.end());
    s.mem_end.push_back(static_cast<std::uint32_t>(s.mem.size()));
  }
  // Runs packet `packet` on program `p` and records its request sequence into `s`.
  void record(Slot& s, ThreadProgram<F, kLanes, FastDatapath>& p, int packet) {
    s.packet = packet;
    s.trace.clear();
    s.masks.clear();
    s.pops.clear();
    s.mem.clear();
    s.mem_end.clear();
    p.start_primary(packet_pixels(tiling_, w_, h_, packet));
    if (tracing_) [[unlikely]]
      return record_traced(s, p);
    for (;;) {
      const Request& r = p.request();
      s.trace.push_back(step_of(r));
      s.masks.push_back(r.mask);
      s.pops.push_back(r.pop_cycles);
      if (p.done()) break;
      p.execute();
      if (r.unit == UnitId::kRgs) [[unlikely]]
        note_memory(s, p, r);
    }
  }
  static Step step_of(const Request& r) {
    if (r.steps < 0 || r.steps > 0xffff)
      throw std::logic_error("cycle model: a request of " + std::to_string(r.steps) +
                             " steps does not fit a trace entry");
    return {r.unit, r.phase, static_cast<std::uint16_t>(r.steps), r.item};
  }

  // ---- a traced run (units/run_trace.h) ----------------------------------------------------
  // record() with each request's kind and, for the request trace, its transactions (the tap is
  // set only around this packet's steps, so an untraced run never sees it).
  void record_traced(Slot& s, ThreadProgram<F, kLanes, FastDatapath>& p) {
    s.kinds.clear();
    s.txns.clear();
    const bool capture = capture_ && (trace_packet_ < 0 || trace_packet_ == s.packet);
    units_.tap = capture ? &tap_ : nullptr;
    for (;;) {
      const Request& r = p.request();
      s.trace.push_back(step_of(r));
      s.masks.push_back(r.mask);
      s.pops.push_back(r.pop_cycles);
      if (p.done()) break;
      s.kinds.push_back(p.kind());
      tap_.begin();
      p.execute();
      note_memory(s, p, r);
      s.txns.push_back(capture ? tap_.take() : std::string());
    }
    units_.tap = nullptr;
  }
  // The request thread t executes is its slot's entry `next`: what the trace says of it (moved
  // out before the slot can be released to the program thread).
  void note_replayed(std::uint32_t t) {
    const Cursor& c = cursor_[t];
    Slot& s = slots_[c.slot];
    TracedStep& n = traced_[t];
    n.packet = s.packet;
    n.seq = static_cast<std::uint32_t>(c.next);
    n.mask = s.masks[c.next];
    n.kind = s.kinds[c.next];
    n.txn = std::move(s.txns[c.next]);
  }
  // execute() of a program per thread, with the trace's view of the request.
  void execute_traced(std::uint32_t t) {
    ThreadProgram<F, kLanes, FastDatapath>& p = *programs_[t];
    TracedStep& n = traced_[t];
    PerStep& ps = per_step_[t];
    n.packet = ps.packet;
    n.seq = ps.seq++;
    n.mask = requests_[t].mask;
    n.kind = p.kind();
    const bool capture = capture_ && (trace_packet_ < 0 || trace_packet_ == ps.packet);
    units_.tap = capture ? &tap_ : nullptr;
    tap_.begin();
    p.execute();
    n.txn = capture ? tap_.take() : std::string();
    units_.tap = nullptr;
    requests_[t] = p.request();
  }
  void replay(std::uint32_t t, const Step& s) {
    Request& r = requests_[t];
    r.unit = s.unit;
    r.phase = s.phase;
    r.item = s.item;
    r.steps = s.steps;
    r.pop_cycles = 0;
    if (s.unit == UnitId::kNone) release(cursor_[t].slot);
  }
  struct Cursor {
    std::size_t slot = 0, next = 0;
    std::uint32_t rgs = 0;  // RGS requests replayed so far (index into the slot's mem_end)
  };
  struct PerStep {  // kPerStep: each thread's packet and its next request's position
    int packet = -1;
    std::uint32_t seq = 0;
  };

  // The program thread: packets in the RGC's order, each into a free slot, at most max_ahead_
  // finished packets ahead of the simulation. The slots in flight (<= threads) and the finished
  // ones (< max_ahead_ when a slot is taken) never exhaust the pool, so this thread waits only
  // while max_ahead_ packets are finished and the simulation only while none is: never both.
  void run_ahead() {
    try {
      ThreadProgram<F, kLanes, FastDatapath>& p = *programs_[0];
      const int total = packets();
      for (int k = 0; k < total; ++k) {
        std::size_t id;
        {
          std::unique_lock<std::mutex> lock(mutex_);
          if (finished_.size() >= max_ahead_) {
            // Full: sleep until half of the window is taken (one wake-up per half window, not
            // one per packet).
            programs_waiting_ = true;
            to_programs_.wait(lock,
                              [&] { return stopping_ || finished_.size() <= max_ahead_ / 2; });
            programs_waiting_ = false;
          }
          if (stopping_) return;
          id = free_.back();
          free_.pop_back();
        }
        record(slots_[id], p, packet_at(k));
        {
          const std::lock_guard<std::mutex> lock(mutex_);
          finished_.push_back(id);
        }
        to_simulation_.notify_one();
      }
    } catch (...) {
      {
        const std::lock_guard<std::mutex> lock(mutex_);
        error_ = std::current_exception();
      }
      to_simulation_.notify_one();
    }
  }

  // The slot of `packet`, the next in order, once the program thread has finished it; rethrows
  // the program thread's error when that packet can no longer come.
  std::size_t take(int packet) {
    std::size_t id;
    bool wake = false;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      to_simulation_.wait(lock, [&] { return !finished_.empty() || error_; });
      if (finished_.empty()) {
        lock.unlock();
        finish();  // rethrows
      }
      id = finished_.front();
      finished_.pop_front();
      wake = programs_waiting_ && finished_.size() <= max_ahead_ / 2;
    }
    if (wake) to_programs_.notify_one();
    if (slots_[id].packet != packet)
      throw std::logic_error("cycle model: the RGC asked for packet " + std::to_string(packet) +
                             ", the program thread ran packet " +
                             std::to_string(slots_[id].packet));
    return id;
  }

  void release(std::size_t slot) {
    if (mode_ != ProgramMode::kAhead) {  // no other host thread
      free_.push_back(slot);
      return;
    }
    const std::lock_guard<std::mutex> lock(mutex_);
    free_.push_back(slot);
  }

  void stop() {
    if (!worker_.joinable()) return;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    to_programs_.notify_one();
    worker_.join();
  }

  FunctionalParams params_;
  std::vector<int> order_;  // the RGC's packets in order; empty: all, in tiling order
  PipelineUnits<F> units_;
  FrameSink sink_;
  PacketTiling tiling_;
  int w_ = 0, h_ = 0;
  ProgramMode mode_;
  bool recorded_;  // kPacketFirst or kAhead: the simulated threads replay recorded packets
  std::size_t max_ahead_ = 0;
  std::vector<std::unique_ptr<ThreadProgram<F, kLanes, FastDatapath>>> programs_;
  std::vector<Slot> slots_;
  std::vector<Cursor> cursor_;
  std::vector<std::vector<RgsAccess>> rgs_mem_;  // recorded: each thread's last RGS accesses
  std::mutex mutex_;                             // guards the slot lists and the flags below
  std::condition_variable to_programs_, to_simulation_;
  std::vector<std::size_t> free_;
  std::deque<std::size_t> finished_;  // in packet order
  bool stopping_ = false;
  bool programs_waiting_ = false;  // the program thread sleeps on a full window
  std::exception_ptr error_;
  std::thread worker_;
  // A traced run: the request each thread executed last, as the trace names it.
  bool tracing_ = false;
  bool capture_ = false;  // the request trace: the tap captures the transactions
  int trace_packet_ = -1;
  std::vector<TracedStep> traced_;
  std::vector<PerStep> per_step_;
  TraceTap<F> tap_;
};

}  // namespace saarcor::units
