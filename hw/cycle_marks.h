// One bit per cycle over a sliding window of cycles: where a unit's work is computed in closed
// form instead of being stepped (a memory controller's lanes, the RGS's requests planned ahead
// through them; docs/memif.md "Lanes"), the cycles it will make progress or stall in are marked
// when they are planned and counted as the kernel's time passes them, so its busy and stall
// cycles are the ones the stepped unit would have counted.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <vector>

#include "hw/schedule.h"

namespace saarcor::hw {

// Cycle c's bit sits at c mod window (a power of two of at least 64 cycles). The owner keeps
// every mark within one window of the first cycle it has not yet taken, so no two marked cycles
// share a bit; that check is the owner's, which knows its first cycle.
class CycleMarks {
 public:
  CycleMarks() = default;
  explicit CycleMarks(std::uint64_t window) : words_(window / 64, 0), mask_(window - 1) {}

  std::uint64_t window() const { return mask_ + 1; }
  bool empty() const { return words_.empty(); }

  // Marks cycle c; true when it was not marked already.
  bool mark(std::uint64_t c) {
    std::uint64_t& w = word(c);
    const std::uint64_t bit = std::uint64_t{1} << (c & 63);
    const bool added = (w & bit) == 0;
    w |= bit;
    return added;
  }
  // Marks cycles [from, to).
  void mark(std::uint64_t from, std::uint64_t to) {
    for (std::uint64_t c = from; c < to;) {
      const std::uint64_t len = span(c, to);
      word(c) |= bits(c, len);
      c += len;
    }
  }
  // Whether cycle c was marked; its mark cleared.
  bool take(std::uint64_t c) {
    std::uint64_t& w = word(c);
    const std::uint64_t bit = std::uint64_t{1} << (c & 63);
    const bool marked = (w & bit) != 0;
    w &= ~bit;
    return marked;
  }
  // The marked cycles among [from, to) counted and cleared (at most one window from `from`:
  // nothing lies beyond it).
  std::uint64_t take(std::uint64_t from, std::uint64_t to) {
    to = std::min(to, from + mask_ + 1);
    std::uint64_t n = 0;
    for (std::uint64_t c = from; c < to;) {
      const std::uint64_t len = span(c, to);
      const std::uint64_t m = bits(c, len);
      std::uint64_t& w = word(c);
      // (The marks are a few per word: counted one by one, as the build's target has no popcount
      // instruction and std::popcount becomes a library call.)
      for (std::uint64_t x = w & m; x != 0; x &= x - 1) {
        ++n;
      }
      w &= ~m;
      c += len;
    }
    return n;
  }
  // The first marked cycle in [from, to) (at most one window from `from`), kNever if none.
  std::uint64_t next(std::uint64_t from, std::uint64_t to) const {
    to = std::min(to, from + mask_ + 1);
    for (std::uint64_t c = from; c < to;) {
      const std::uint64_t len = span(c, to);
      const std::uint64_t w = (word(c) & bits(c, len)) >> (c & 63);
      if (w != 0) {
        return c + static_cast<std::uint64_t>(std::countr_zero(w));
      }
      c += len;
    }
    return kNever;
  }

 private:
  std::uint64_t& word(std::uint64_t c) { return words_[(c >> 6) & (words_.size() - 1)]; }
  const std::uint64_t& word(std::uint64_t c) const {
    return words_[(c >> 6) & (words_.size() - 1)];
  }
  // The cycles from c to the end of c's word or to `to`, whichever comes first.
  static std::uint64_t span(std::uint64_t c, std::uint64_t to) {
    return std::min<std::uint64_t>(64 - (c & 63), to - c);
  }
  // The bits of `len` cycles from c, within c's word.
  static std::uint64_t bits(std::uint64_t c, std::uint64_t len) {
    return (len == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << len) - 1) << (c & 63);
  }

  std::vector<std::uint64_t> words_;
  std::uint64_t mask_ = 0;
};

}  // namespace saarcor::hw
