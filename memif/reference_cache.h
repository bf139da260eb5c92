// A plain cache simulation for the tests (decision D20): lines of one item, set = index mod sets,
// LRU, fills are instant. Used as the reference the cycle-level Cache's counters must match on
// the same request sequence. Test-only header.
#pragma once

#include <cstdint>
#include <vector>

namespace saarcor::memif::testing {

class ReferenceCache {
 public:
  ReferenceCache(int items, int ways)
      : ways_(ways),
        sets_(items / ways),
        tag_(static_cast<std::size_t>(items), ~0ull),
        age_(static_cast<std::size_t>(items), 0) {}
  // True on a hit.
  bool access(std::uint32_t index) {
    const std::size_t first =
        (index % static_cast<std::uint32_t>(sets_)) * static_cast<std::size_t>(ways_);
    ++clock_;
    std::size_t victim = first;
    for (std::size_t w = first; w < first + static_cast<std::size_t>(ways_); ++w) {
      if (tag_[w] == index) {
        age_[w] = clock_;
        ++hits;
        return true;
      }
      if (age_[w] < age_[victim]) victim = w;
    }
    tag_[victim] = index;
    age_[victim] = clock_;
    ++misses;
    return false;
  }
  std::uint64_t hits = 0, misses = 0;

 private:
  int ways_, sets_;
  std::vector<std::uint64_t> tag_, age_;
  std::uint64_t clock_ = 0;
};

}  // namespace saarcor::memif::testing
