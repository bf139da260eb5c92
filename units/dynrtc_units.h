// The units of one DynRTP in the cycle model (paper section 3.1, Figure 2; docs/cycle-model.md):
// traversal, mailboxed list, transformation, intersection, and the ray source (the RGC/RGS in
// front of path a with the hit sink after path g). Each is a CycleUnit (units/cycle_unit.h) with
// its own cache, pipeline depth and rules; units/dynrtp.cpp wires them with the paths a-g.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "hw/cycle_marks.h"
#include "memif/memory_controller.h"
#include "units/cycle_unit.h"

namespace saarcor::units {

// Traversal unit (paths b, f in; c, g out): one packet-node step per cycle; kd-nodes through the
// traversal cache; the six faces of a box clip issue back to back (D29).
class TraversalUnit : public CycleUnit {
 public:
  TraversalUnit(hw::Kernel& k, std::string name, ThreadTable& t, int depth, memif::Cache& cache);

 protected:
  Fetch fetch(const Request& r) const override;
  bool chains(const Request& done, const Request& next) const override;
  // A request that ends in a pop leaves through the pop engine (units/traversal.cpp).
  bool hold(ThreadToken t) override;
  int extra() override;
  std::uint64_t extra_wakeup(std::uint64_t now) const override;

 private:
  struct Popping {
    std::uint64_t at;  // the cycle its request reaches the pipeline's last stage
    ThreadToken thread;
    int entries;  // stack entries still to read (the pop engine reads one per cycle)
  };
  std::deque<Popping> stage_;  // pops in the pipeline, in issue order
  std::deque<Popping> queue_;  // the pop engine's queue
};

// Mailboxed list unit (path c in, d out): one list entry per cycle through the list cache; the
// mailbox filter is part of the thread program's list step.
class ListUnit : public CycleUnit {
 public:
  ListUnit(hw::Kernel& k, std::string name, ThreadTable& t, int depth, memif::Cache& cache);

 protected:
  Fetch fetch(const Request& r) const override;
};

// Transformation unit (paths a, d in; b, e out): one matrix-vector step per cycle, n+1 or 2n steps
// per packet (D31); object and triangle matrices arrive as rows through the transformation cache
// (D32); ray generation takes its matrix from the RGS (no fetch).
class TransformationUnit : public CycleUnit {
 public:
  TransformationUnit(hw::Kernel& k, std::string name, ThreadTable& t, int depth,
                     memif::Cache& cache);

 protected:
  Fetch fetch(const Request& r) const override;
};

// Intersection unit (path e in, f out): one ray per cycle, P cycles per packet (D30).
class IntersectionUnit : public CycleUnit {
 public:
  IntersectionUnit(hw::Kernel& k, std::string name, ThreadTable& t, int depth);

 protected:
  Fetch fetch(const Request& r) const override;
};

// What each primary packet costs the chip in cycles, for sampled simulation (docs/sampling.md
// "Charged cycles"): every cycle is shared equally among the packets in flight then (handed out by
// the RGC, their thread not yet freed), so a packet is charged the sum of 1/n over the cycles of
// its residence, n the packets in flight in each. The charges of all packets add up to the cycles
// in which any packet was in flight; a window's packets are charged for exactly their own
// residence, whatever else shares the machine, where the span between two hand-outs would measure
// the packets in flight around them. Kept per event (hand-out, retirement), not per cycle.
class PacketCharges {
 public:
  // `packets`: the hand-outs (the RGC's ordinals); `threads`: the chip's thread ids.
  PacketCharges(int packets, int threads)
      : charge_(static_cast<std::size_t>(packets), 0.0),
        start_(static_cast<std::size_t>(threads), 0.0),
        ordinal_(static_cast<std::size_t>(threads), -1) {}

  void admit(ThreadToken t, int ordinal, std::uint64_t now) {
    advance(now);
    ++in_flight_;
    start_[t] = shared_;
    ordinal_[t] = ordinal;
  }
  void retire(ThreadToken t, std::uint64_t now) {
    advance(now);
    --in_flight_;
    charge_[static_cast<std::size_t>(ordinal_[t])] = shared_ - start_[t];
    ordinal_[t] = -1;
  }
  // By the RGC's ordinal (0 for a packet not yet retired).
  const std::vector<double>& charges() const { return charge_; }
  // The cycles up to the last event in which no packet was in flight (before the first hand-out).
  std::uint64_t empty_cycles() const { return empty_; }
  std::uint64_t last_event() const { return last_; }

 private:
  void advance(std::uint64_t now) {
    if (in_flight_ > 0)
      shared_ += static_cast<double>(now - last_) / in_flight_;
    else
      empty_ += now - last_;
    last_ = now;
  }
  std::vector<double> charge_;
  std::vector<double> start_;  // by thread: the running share when its packet was handed out
  std::vector<int> ordinal_;   // by thread: its packet's ordinal, -1 when free
  double shared_ = 0;          // sum over cycles of 1 / packets in flight
  int in_flight_ = 0;
  std::uint64_t last_ = 0, empty_ = 0;
};

// The ray generation controller (paper section 3: it "schedules screen-space pixels", the dynamic
// load balancing between DynRTPs): the frame's packets in order, to whichever pipeline asks for
// one in a cycle it is granted. The grant goes round robin, one pipeline per cycle (D44; with one
// pipeline every cycle is granted, as in the prototype), so a cycle hands out at most one packet
// and only the granted pipeline changes the count: what every pipeline sees does not depend on
// the order the kernel evaluates them in.
class RayGenerationController {
 public:
  RayGenerationController(int packets, int pipelines) : packets_(packets), pipelines_(pipelines) {}

  bool granted(int pipeline, std::uint64_t cycle) const {
    return pipelines_ == 1 ||  // (no division on the prototype's path)
           cycle % static_cast<std::uint64_t>(pipelines_) == static_cast<std::uint64_t>(pipeline);
  }
  // The first cycle after `now` granted to `pipeline`.
  std::uint64_t next_grant(int pipeline, std::uint64_t now) const {
    if (pipelines_ == 1) return now + 1;
    const auto n = static_cast<std::uint64_t>(pipelines_);
    const std::uint64_t c = now + 1;
    return c + (static_cast<std::uint64_t>(pipeline) + n - c % n) % n;
  }
  // Whether packets are left as `pipeline` sees them in cycle `now`: the granted pipeline sees
  // its own hand-out at once, the others the count the cycle began with.
  bool packets_left(int pipeline, std::uint64_t now) const {
    const int handed = granted(pipeline, now) || taken_at_ != now ? next_ : next_ - 1;
    return handed < packets_;
  }
  int take(std::uint64_t now) {
    taken_at_ = now;
    return next_++;
  }
  bool all_handed_out() const { return next_ == packets_; }
  int handed_out() const { return next_; }  // packets taken so far (the next one's ordinal)
  int packets() const { return packets_; }
  // Sampled simulation: where the RaySources report each packet's hand-out and retirement (null:
  // nowhere, the default).
  void set_charges(PacketCharges* c) { charges_ = c; }
  PacketCharges* charges() const { return charges_; }

 private:
  PacketCharges* charges_ = nullptr;
  int packets_;
  int pipelines_;
  int next_ = 0;
  std::uint64_t taken_at_ = hw::kNever;
};

// The RGS's two memory ports (memif::MemorySystem::shading_port / frame_port): uncached reads of
// the shading bank, writes into the frame-buffer banks, each under its own bandwidth client.
struct RgsPorts {
  memif::MemoryController::Port* shading = nullptr;
  memif::MemoryController::Port* frame = nullptr;
  std::uint16_t shading_client = 0, frame_client = 0;
  std::uint64_t lane_window = 0;  // the controller's lane window, when the ports are lanes
};

// The ray generation and shading unit of one DynRTP with the RGC's admission (path g in, a out):
// in a cycle the RGC grants it, a new primary packet goes to a free thread of this pipeline;
// returning packets run their RGS phases and the finished packet frees its thread. An RGS request
// that touches memory (the thread program lists its accesses: units/program_types.h RgsAccess)
// keeps its thread: the shading-bank reads go out one per cycle on the shading port in dependent
// waves (record and light, material, texels; a wave queues behind the reads already waiting and
// goes out back to back), the shading takes `depth` cycles after the last
// word arrived, then the finished pixels go to the frame port one word per cycle, and the thread
// leaves (or is freed) as its last write goes out. A request without accesses takes `depth`
// cycles after its issue cycle, as every unit's. The pipeline's threads are `count` consecutive
// ids from `first` in the shared table. Exact-cycle tests: units/unit_timing_test.cpp
// (UnitTimingRaySource.*, UnitTimingRgs.*).
class RaySource : public CycleUnit {
 public:
  RaySource(hw::Kernel& k, std::string name, ThreadTable& t, int depth,
            RayGenerationController& rgc, int pipeline, ThreadToken first, int count,
            RgsPorts ports = {});

  // Every thread of this pipeline free (checked between cycles).
  bool idle() const { return free_ == count_; }
  std::uint64_t packets_retired() const { return retired_->value; }
  std::uint64_t packets_admitted() const { return admitted_->value; }
  const hw::Counter& admitted_counter() const { return *admitted_; }

 protected:
  Fetch fetch(const Request& r) const override;
  bool chains(const Request& done, const Request& next) const override;
  void retire(ThreadToken thread) override;
  int extra() override;
  std::uint64_t extra_wakeup(std::uint64_t now) const override;
  bool hold(ThreadToken thread) override;
  int evaluate() override;
  void skipped(std::uint64_t cycles) override;

 private:
  // A thread the RGS keeps while its request's accesses are served. It waits in one of four
  // FIFOs at a time: its wave's reads to issue (reading_), its shading (shading_, in order of
  // `due`), its pixels to write (writing_), its path out (leaving_).
  struct Held {
    // The reads, then the writes, as the program lists them: the thread table's own list, which
    // stays put while the thread is held (its next request executes only after it left).
    const std::vector<RgsAccess>* access = nullptr;
    std::size_t reads = 0;  // access[0, reads) are reads
    std::size_t next = 0;   // the next access to issue
    int outstanding = 0;    // reads issued and not answered
    std::uint64_t due = 0;  // the cycle its shading is done
  };
  Held& held(ThreadToken t) { return held_[t - first_]; }
  const Held& held(ThreadToken t) const { return held_[t - first_]; }
  int admit();
  int receive_shading();
  int issue_read();
  int write_and_leave();
  void shade(ThreadToken t, Held& h) {
    h.due = now() + static_cast<std::uint64_t>(depth());
    shading_.push_back(t);
  }
  // Pushes the thread's next access in cycle `at` (now, or later through a lane); returns the
  // cycle a lane's read response becomes visible.
  std::uint64_t issue_access(memif::MemoryController::Port& port, std::uint16_t client,
                             ThreadToken t, Held& h, std::uint64_t at);
  // Lanes (docs/memif.md "Lanes"): with its ports served in closed form, the RGS knows in which
  // cycles a wave's reads and a packet's writes go out and its responses arrive, and pushes them
  // ahead (up to kPlan at a time) instead of being evaluated in each of those cycles. The
  // cycles it would have made progress in only through them are marked (virtual_) and counted
  // as busy, not stalled, as they pass (evaluate, skipped); it is evaluated where the stepped
  // RGS acts on them: a wave's last response, the next wave's first read, a packet's last write.
  static constexpr int kPlan = 16;
  struct Wave {
    ThreadToken thread;
    std::uint32_t reads;
    std::uint64_t last;  // the cycle its last response becomes visible
  };
  void mark_virtual(std::uint64_t cycle);
  [[noreturn, gnu::cold, gnu::noinline]] void beyond_window() const;
  // A port's request side, through its lane when it has one (docs/memif.md "Lanes").
  static bool can_push(const memif::MemoryController::Port& port) {
    return port.lane != nullptr ? port.lane->can_push() : port.requests.can_push();
  }
  static std::uint64_t push_ready_cycle(const memif::MemoryController::Port& port) {
    return port.lane != nullptr ? port.lane->push_ready_cycle() : port.requests.push_ready_cycle();
  }

  RayGenerationController& rgc_;
  int pipeline_;
  ThreadToken first_;
  int count_;
  Ring<ThreadToken> free_list_;
  int free_;
  RgsPorts ports_;
  std::vector<Held> held_;  // by thread (minus first_)
  Ring<ThreadToken> reading_, shading_, writing_, leaving_;
  int active_ = 0;    // held threads
  Ring<Wave> waves_;  // through a lane: the waves sent and not answered, in order
  // Through a lane: the first cycle the read / write port is free of planned pushes.
  std::uint64_t read_free_at_ = 0, write_free_at_ = 0;
  hw::CycleMarks virtual_;  // the cycles of planned pushes and responses, from virtual_from_ on
  std::uint64_t virtual_from_ = 0, virtual_marked_ = 0;
  hw::Counter* retired_;
  hw::Counter* admitted_;
  hw::Counter* reads_;
  hw::Counter* writes_;
};

}  // namespace saarcor::units
