// A FIFO of bounded size in a power-of-two ring: the hardware's small queues (a unit's ready
// queue and free list, a memory bank's request queue and reads in flight, an MSHR's waiting
// requests, a cache's filled misses) have a fixed depth, so they never allocate after
// construction and their items sit side by side in memory.
#pragma once

#include <cstddef>
#include <vector>

namespace saarcor::hw {

// Holds at most `capacity` items (rounded up to a power of two); the owner never pushes more
// (its queue depth is the bound).
template <class T>
class Ring {
 public:
  explicit Ring(int capacity = 1) {
    std::size_t n = 1;
    while (n < static_cast<std::size_t>(capacity))
      n *= 2;
    items_.resize(n);
    mask_ = n - 1;
  }
  bool empty() const { return head_ == tail_; }
  std::size_t size() const { return tail_ - head_; }
  const T& front() const { return items_[head_ & mask_]; }
  T& front() { return items_[head_ & mask_]; }
  const T& operator[](std::size_t k) const { return items_[(head_ + k) & mask_]; }
  // The new back item's slot, to be written in place (it holds whatever it last held): a request
  // or response is then built field by field where it waits, as the hardware writes a queue
  // entry, instead of being assembled elsewhere and copied in.
  T& push_slot() { return items_[tail_++ & mask_]; }
  void push_back(const T& v) { push_slot() = v; }
  void pop_front() { ++head_; }
  void clear() { head_ = tail_ = 0; }

 private:
  std::vector<T> items_;
  std::size_t mask_ = 0, head_ = 0, tail_ = 0;
};

}  // namespace saarcor::hw
