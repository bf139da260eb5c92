// The mailbox of the mailboxed list unit (paper section 3.1: "omitting objects that have already
// been visited by the same ray"; docs/cycle-model.md; decision D28): per thread the last `capacity`
// ids, each with the mask of the packet's rays that have visited it, FIFO replacement, cleared when
// a new packet starts. Since a bottom-level tree is traversed over the ray's whole interval
// (D29), skipping a visited object never changes a result; evicting an entry only costs a revisit.
#pragma once

#include <cstdint>
#include <vector>

namespace saarcor::units {

class Mailbox {
 public:
  explicit Mailbox(int capacity = 8) : capacity_(capacity < 0 ? 0 : capacity) {
    ids_.assign(static_cast<std::size_t>(capacity_), 0);
    masks_.assign(static_cast<std::size_t>(capacity_), 0);
  }

  void clear() {
    size_ = 0;
    head_ = 0;
  }

  // The rays of `mask` that still have to visit `id`; records them as visitors.
  std::uint64_t filter(std::uint32_t id, std::uint64_t mask) {
    if (capacity_ == 0) return mask;
    for (int i = 0; i < size_; ++i) {
      const auto k = static_cast<std::size_t>(slot(i));
      if (ids_[k] == id) {
        const std::uint64_t todo = mask & ~masks_[k];
        masks_[k] |= mask;
        return todo;
      }
    }
    // New id: FIFO replacement of the oldest entry when full.
    std::size_t k;
    if (size_ < capacity_) {
      k = static_cast<std::size_t>(slot(size_));
      ++size_;
    } else {
      k = static_cast<std::size_t>(head_);
      head_ = (head_ + 1) % capacity_;
    }
    ids_[k] = id;
    masks_[k] = mask;
    return mask;
  }

  int capacity() const { return capacity_; }
  int size() const { return size_; }

 private:
  int slot(int i) const { return (head_ + i) % capacity_; }

  int capacity_ = 8;
  int size_ = 0;
  int head_ = 0;  // oldest entry
  std::vector<std::uint32_t> ids_;
  std::vector<std::uint64_t> masks_;
};

}  // namespace saarcor::units
