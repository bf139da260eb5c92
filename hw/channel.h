// Registered channels of the simulation kernel (DESIGN.md section 8; STYLE.md: SystemC's
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
// One producer and one consumer per channel; the kernel commits all channels after all modules
// evaluated.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace saarcor::hw {

class Kernel;
class Module;
struct Counter;

inline constexpr std::uint64_t kNever = std::numeric_limits<std::uint64_t>::max();

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
  int occupancy() const { return count_; }
  bool empty() const { return count_ == 0; }
  bool valid() const { return count_ > 0 && ready_at_[head_] <= *now_; }  // consumer may pop
  bool ready() const { return count_ < capacity_; }                       // producer may push
  // Cycle at which the front item becomes poppable; kNever when empty.
  std::uint64_t front_ready_cycle() const { return count_ > 0 ? ready_at_[head_] : kNever; }

  bool can_push() const { return count_ + pushes_ < capacity_ && pushes_ < width_; }
  // (The hottest test of a model: one compare against a cached cycle, see pop_ready_.)
  bool can_pop() const { return pop_ready_ <= *now_; }

  // Applies this cycle's pushes and pops (waking the declared consumer when pushed items become
  // visible and the declared producer when a pop frees room); returns how many there were.
  // Kernel only.
  int commit();
  Module* producer() const { return producer_; }
  Module* consumer() const { return consumer_; }
  std::uint64_t total_pushes() const;

 protected:
  int slot(int k) const { return (head_ + k) & mask_; }
  // Checks and books a push, returns its slot.
  int reserve_push() {
    if (!can_push()) misuse("push while !can_push() (full, or port width used up)");
    const int s = slot(count_ + pushes_);
    ready_at_[static_cast<std::size_t>(s)] = *now_ + static_cast<std::uint64_t>(latency_);
    ++pushes_;
    mark_dirty();
    return s;
  }
  // Checks and books a pop, returns its slot.
  int reserve_pop() {
    if (!can_pop()) misuse("pop while !can_pop() (empty, not yet visible, or width used up)");
    const int s = slot(pops_);
    ++pops_;
    // The next item, if committed and visible; a slot past the committed items is empty (kNever)
    // or holds an item pushed in this cycle (visible later), so no count test is needed.
    pop_ready_ = pops_ < width_ ? ready_at_[static_cast<std::size_t>(slot(pops_))] : kNever;
    mark_dirty();
    return s;
  }
  int front_slot() const {
    if (!can_pop()) misuse("peek while !can_pop()");
    return slot(pops_);
  }
  void mark_dirty() {
    if (!dirty_) {
      dirty_ = true;
      dirty_list_->push_back(this);
    }
  }
  [[noreturn, gnu::cold, gnu::noinline]] void misuse(const char* what) const;
  inline int commit_now();  // commit(), inlined into the kernel's cycle (defined in kernel.cpp)

  // Hot fields first (what push, pop and commit touch share the first two cache lines).
  // The cycle from which can_pop() holds: the next item's ready cycle, kNever when there is none
  // or the port width is used up. Kept on pop and commit.
  std::uint64_t pop_ready_ = kNever;
  const std::uint64_t* now_;
  // Per slot: the cycle its item becomes poppable; kNever for an empty slot. Slots are a power of
  // two (>= capacity, which alone limits the occupancy) so that a slot is an index mask.
  std::vector<std::uint64_t> ready_at_;
  int mask_ = 0;
  int head_ = 0, count_ = 0, pushes_ = 0, pops_ = 0;
  int capacity_, latency_, width_;
  bool dirty_ = false;
  std::vector<ChannelBase*>* dirty_list_;
  // Where commit() posts wake-ups: the kernel's per-module wake cycles, at the declared ends'
  // slots (slot 0 is a sink for undeclared ends).
  std::vector<std::uint64_t>* wakes_;
  std::size_t producer_slot_ = 0, consumer_slot_ = 0;
  // Statistics (owned by the kernel's registry; the counts since the last flush_stats() are kept
  // here, in the lines commit() touches anyway).
  std::uint64_t pending_pushes_ = 0;
  int max_count_ = 0;
  // Occupancy integrated over time.
  std::uint64_t occupancy_area_ = 0;
  std::uint64_t last_change_ = 0;
  // Cold.
  void flush_stats();
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

  void push(T item) { items_[static_cast<std::size_t>(reserve_push())] = std::move(item); }
  // Books a push and returns its slot to be filled in place (an item built field by field is
  // not copied once more on the way in).
  T& push_slot() { return items_[static_cast<std::size_t>(reserve_push())]; }
  const T& peek() const { return items_[static_cast<std::size_t>(front_slot())]; }
  T pop() { return std::move(items_[static_cast<std::size_t>(reserve_pop())]); }
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
