// Registered channels of the simulation kernel (docs/hw.md; STYLE.md: SystemC's
// sc_fifo, ChampSim's channel): bounded FIFOs with a latency, valid/ready handshake and
// back-pressure, whose semantics make a design independent of module evaluation order.
//
// Contract (what each call may change, and when the other side sees it):
//   * An item pushed in cycle c can be popped in cycle c + latency at the earliest (latency >= 1:
//     nothing written in a cycle is readable in the same cycle).
//   * can_push() in cycle c depends only on the state committed at the end of cycle c-1 and on
//     this cycle's own pushes: a slot freed by a pop in cycle c is reusable in cycle c+1 (the
//     ready signal is registered). So an item occupies its slot from its push cycle through its pop
//     cycle, latency + 1 cycles at least: capacity >= latency + 1 sustains one item per cycle.
//   * can_pop()/peek()/pop() see only items committed before this cycle whose latency has
//     elapsed, in FIFO order. Pops take effect for the producer at the next cycle.
//   * At most `width` pushes and `width` pops per cycle (the port width).
//   * Misuse (push when !can_push, peek/pop when !can_pop) throws std::logic_error naming the
//     channel: it is a model bug, never bad input.
// One producer and one consumer per channel.
//
// The channel keeps this contract without a commit phase: every item carries the cycle it becomes
// visible, and the pushes and pops of the current cycle are counted apart from the committed
// occupancy, so what either end sees cannot depend on whether the other end was evaluated first
// in the cycle (a commit of every channel that moved cost a third of the kernel's cycle).
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "hw/schedule.h"

namespace saarcor::hw {

class Kernel;
class Module;
struct Counter;

class ChannelBase {
 public:
  ChannelBase(Kernel& kernel, std::string name, int capacity, int latency, int width);
  virtual ~ChannelBase() = default;
  ChannelBase(const ChannelBase&) = delete;
  ChannelBase& operator=(const ChannelBase&) = delete;

  const std::string& name() const { return name_; }
  int capacity() const { return capacity_; }
  int latency() const { return latency_; }
  int width() const { return width_; }

  // Committed state (as of the start of the current cycle); what VCD traces and watchdog dumps.
  int occupancy() const {
    return static_cast<int>(tail_ - head_) - pushes_in(*now_) + pops_in(*now_);
  }
  bool empty() const { return occupancy() == 0; }
  bool valid() const {  // consumer may pop
    const std::uint64_t front = head_ - static_cast<std::uint64_t>(pops_in(*now_));
    return occupancy() > 0 && ready_at_[front & mask_] <= *now_;
  }
  bool ready() const { return occupancy() < capacity_; }  // producer may push
  // Cycle at which the current front item (possibly one pushed in this cycle) becomes poppable;
  // kNever when empty.
  std::uint64_t front_ready_cycle() const {
    return tail_ != head_ ? ready_at_[head_ & mask_] : kNever;
  }

  // Cycle from which the producer may push: kNever while full (a pop wakes the producer then).
  std::uint64_t push_ready_cycle() const { return push_ready_; }

  // (The hottest tests of a model: one compare against a cached cycle each, see pop_ready_.)
  bool can_push() const { return push_ready_ <= *now_; }
  bool can_pop() const { return pop_ready_ <= *now_; }

  // A fast path that serves this channel's items without moving them (memif's lanes: the
  // controller computes each request's cycles when it is pushed) books each push and pop here in
  // the cycle it stands for, so the channel's statistics (pushes, occupancy, largest occupancy)
  // are those of the stepped model. `occupancy` is the committed occupancy at the end of the push
  // cycle. Neither wakes a module: the fast path's owner knows its cycles.
  // (Several at once: their count, the sum of their cycles, the largest occupancy.)
  void book_pushes(std::uint64_t n, std::uint64_t cycles, std::uint64_t occupancy) {
    tail_ += n;
    push_cycles_ += cycles;
    max_count_ = std::max(max_count_, occupancy);
  }
  void book_pops(std::uint64_t n, std::uint64_t cycles) {
    head_ += n;
    pop_cycles_ += cycles;
  }

  Module* producer() const { return producer_; }
  Module* consumer() const { return consumer_; }
  std::uint64_t total_pushes() const { return tail_; }

 protected:
  // This cycle's pushes / pops so far (the counts belong to op_cycle_).
  int pushes_in(std::uint64_t now) const { return op_cycle_ == now ? pushes_now_ : 0; }
  int pops_in(std::uint64_t now) const { return op_cycle_ == now ? pops_now_ : 0; }
  // The first push or pop of a cycle closes the last cycle that had any: its final occupancy is
  // a committed one (the largest is a statistic), and the port counts start again.
  void open_cycle(std::uint64_t now) {
    if (op_cycle_ == now) return;
    // (A cycle that pushed no more than it popped cannot have raised the largest occupancy.)
    if (pushes_now_ > pops_now_) max_count_ = std::max(max_count_, tail_ - head_);
    op_cycle_ = now;
    pushes_now_ = pops_now_ = 0;
  }
  // Checks and books a push, returns its slot. The consumer is woken for the cycle the item
  // becomes visible.
  std::size_t reserve_push() {
    if (!can_push()) misuse("push while !can_push() (full, or port width used up)");
    const std::uint64_t now = *now_;
    open_cycle(now);
    const std::uint64_t at = now + static_cast<std::uint64_t>(latency_);
    const std::size_t s = tail_ & mask_;
    ready_at_[s] = at;
    if (tail_ == head_) pop_ready_ = at;  // the new front (never poppable in this cycle)
    ++tail_;
    ++pushes_now_;
    // Full even after this cycle's pops: until a pop; full counting the slots this cycle's pops
    // free next cycle, or the port width used up: until the next cycle.
    const int count = static_cast<int>(tail_ - head_);
    if (count >= capacity_) {
      push_ready_ = kNever;
    } else if (pushes_now_ == width_ || count + pops_now_ >= capacity_) {
      push_ready_ = now + 1;
    }
    push_cycles_ += now;
    ++*moves_;
    schedule_->wake(consumer_slot_, at, now);
    return s;
  }
  // Checks and books a pop, returns its slot. A producer sees its output only through can_push(),
  // which a pop turns from false to true only when the channel was full (the port width is reset
  // by the cycle itself, and a producer that filled it in this cycle is evaluated next cycle
  // anyway): only then is it woken, for the next cycle (a freed slot is reusable from then on).
  std::size_t reserve_pop() {
    if (!can_pop()) misuse("pop while !can_pop() (empty, not yet visible, or width used up)");
    const std::uint64_t now = *now_;
    open_cycle(now);
    if (push_ready_ == kNever) {  // full: the freed slot is the producer's next cycle
      push_ready_ = now + 1;
      schedule_->wake(producer_slot_, now + 1, now);
    }
    const std::size_t s = head_ & mask_;
    ++head_;
    ++pops_now_;
    pop_cycles_ += now;
    ++*moves_;
    // The next item, if there is one: one pushed in this cycle is visible later anyway; with the
    // port width used up, not before the next cycle.
    if (head_ == tail_) {
      pop_ready_ = kNever;
    } else {
      const std::uint64_t r = ready_at_[head_ & mask_];
      pop_ready_ = pops_now_ < width_ ? r : std::max(r, now + 1);
    }
    return s;
  }
  std::size_t front_slot() const {
    if (!can_pop()) misuse("peek while !can_pop()");
    return head_ & mask_;
  }
  [[noreturn, gnu::cold, gnu::noinline]] void misuse(const char* what) const;

  // Hot fields first (what push and pop touch share the first two cache lines).
  // The cycle from which can_pop() holds: the front item's ready cycle, kNever when there is none,
  // at least the next cycle when the port width is used up.
  std::uint64_t pop_ready_ = kNever;
  // The cycle from which can_push() holds: kNever while full, the next cycle when this cycle's
  // pushes used up the port width or the room left after this cycle's pops.
  std::uint64_t push_ready_ = 0;
  const std::uint64_t* now_;
  // Per slot: the cycle its item becomes poppable. Slots are a power of two (>= capacity, which
  // alone limits the occupancy) so that a slot is an index mask of the running counts.
  std::vector<std::uint64_t> ready_at_;
  std::uint64_t head_ = 0, tail_ = 0;  // items popped, items pushed (slot: & mask_)
  std::uint64_t mask_ = 0;
  std::uint64_t op_cycle_ = kNever;  // the last cycle with a push or pop; its counts:
  int pushes_now_ = 0, pops_now_ = 0;
  int capacity_, latency_, width_;
  Schedule* schedule_;
  std::uint64_t* moves_;  // the kernel's count of pushes and pops (a cycle's channel activity)
  std::size_t producer_slot_ = 0, consumer_slot_ = 0;  // 0: an undeclared end (the sink)
  // Statistics: the sums of the push and pop cycles give the occupancy integrated over time (an
  // item adds pop cycle - push cycle), the largest committed occupancy is kept by open_cycle().
  std::uint64_t push_cycles_ = 0, pop_cycles_ = 0;
  std::uint64_t max_count_ = 0;
  // Cold.
  void flush_stats();
  std::uint64_t flushed_pushes_ = 0;
  Counter* pushes_stat_ = nullptr;
  Counter* max_occupancy_stat_ = nullptr;
  Module* producer_ = nullptr;  // declared ends (Module::produces/consumes); null: not declared
  Module* consumer_ = nullptr;
  std::string name_;

  friend class Kernel;
  friend class Module;
};

template <class T>
class Channel : public ChannelBase {
 public:
  // capacity >= 1, latency >= 1, width >= 1, else std::logic_error.
  Channel(Kernel& kernel, std::string name, int capacity, int latency = 1, int width = 1)
      : ChannelBase(kernel, std::move(name), capacity, latency, width),
        items_(static_cast<std::size_t>(mask_) + 1) {}

  void push(T item) { items_[reserve_push()] = std::move(item); }
  // Books a push and returns its slot to be filled in place (an item built field by field is
  // not copied once more on the way in).
  T& push_slot() { return items_[reserve_push()]; }
  const T& peek() const { return items_[front_slot()]; }
  T pop() { return std::move(items_[reserve_pop()]); }
  // pop() for a consumer that has read what it needs through peek(): the item is not copied.
  void drop() { (void)reserve_pop(); }

 private:
  std::vector<T> items_;
};

// A fully pipelined datapath of fixed depth (e.g. an fp divider, 8 cycles): one issue per cycle,
// each result poppable `depth` cycles after its issue. Elastic: when results are not taken the
// pipeline fills and refuses issue (back-pressure) instead of losing results. Capacity depth + 1
// keeps one issue per cycle when results are popped as soon as they are ready.
template <class T>
class Pipeline : public Channel<T> {
 public:
  Pipeline(Kernel& kernel, std::string name, int depth)
      : Channel<T>(kernel, std::move(name), depth + 1, depth, 1) {}
  int depth() const { return this->latency(); }
};

}  // namespace saarcor::hw
