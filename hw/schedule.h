// The kernel's schedule of module evaluations (docs/hw.md "Event scheduling"): for every module
// the earliest cycle it must be evaluated in, and a timing wheel of bit masks so that a cycle
// finds its due modules without looking at the others (a cycle evaluates about 4 of 24 modules on
// the room frame; a scan over all wake cycles cost more than the evaluations' bookkeeping).
//
// Wakes only lower a module's wake cycle (they come from channel pushes and pops at any point of
// a cycle, and from the kernel after the module's own evaluation); a cycle's due modules have
// their wake cycle cleared when the cycle takes them, so everything posted during the cycle is
// kept. A bit whose module was since woken earlier is stale: take() drops it (the wake cycle no
// longer matches), so every module is evaluated exactly at its wake cycles, as with the scan.
// Wakes further ahead than the wheel's span wait in the wake cycle alone and enter the wheel when
// the clock comes within the span.
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace saarcor::hw {

// "No cycle": never due, never visible (the kernel's and the channels' sentinel too).
inline constexpr std::uint64_t kNever = std::numeric_limits<std::uint64_t>::max();

class Schedule {
 public:
  static constexpr std::uint64_t kSpan = 64;  // cycles ahead held in the wheel (a power of two)

  // Slot 0 is a sink for the wakes of undeclared channel ends: it is never due.
  Schedule() { resize(1); }

  // Room for slots 0 .. slots-1 (new slots are not scheduled).
  void resize(std::size_t slots) {
    const std::size_t words = (slots + 63) / 64;
    if (words != words_) {
      std::vector<std::uint64_t> wheel(kSpan * words, 0);
      for (std::size_t b = 0; b < kSpan; ++b)
        for (std::size_t w = 0; w < words_; ++w)
          wheel[b * words + w] = wheel_[b * words_ + w];
      wheel_ = std::move(wheel);
      words_ = words;
    }
    wake_.resize(slots, kNever);
    wake_[0] = 0;  // the sink: nothing is ever lower, so it is never posted
  }
  std::size_t words() const { return words_; }

  // Slot `slot` must be evaluated in cycle `at` (>= now) at the latest.
  void wake(std::size_t slot, std::uint64_t at, std::uint64_t now) {
    if (at >= wake_[slot]) return;
    wake_[slot] = at;
    if (at - now < kSpan) {
      wheel_[(at & (kSpan - 1)) * words_ + slot / 64] |= std::uint64_t{1} << (slot % 64);
    } else {
      far_ = std::min(far_, at);
    }
  }

  // The modules due in cycle `now` (called once per evaluated cycle, in increasing cycles): their
  // bits in `due` (words() words), their wake cycles cleared.
  void take(std::uint64_t now, std::uint64_t* due) {
    if (far_ < now + kSpan) enter_far(now);
    std::uint64_t* bucket = &wheel_[(now & (kSpan - 1)) * words_];
    for (std::size_t w = 0; w < words_; ++w) {
      std::uint64_t bits = bucket[w], keep = 0;
      bucket[w] = 0;
      while (bits != 0) {
        const std::size_t slot = w * 64 + static_cast<std::size_t>(std::countr_zero(bits));
        const std::uint64_t bit = bits & (~bits + 1);
        bits ^= bit;
        if (wake_[slot] == now) {
          wake_[slot] = kNever;
          keep |= bit;
        }
      }
      due[w] = keep;
    }
  }

  // The earliest cycle >= now at which slot `slot` is due (kNever: not scheduled).
  std::uint64_t wake_cycle(std::size_t slot) const { return wake_[slot]; }
  // Unschedules `slot` (its wheel bit becomes stale).
  void cancel(std::size_t slot) { wake_[slot] = kNever; }

 private:
  // Puts the far wakes that came within the span into the wheel.
  void enter_far(std::uint64_t now) {
    far_ = kNever;
    for (std::size_t slot = 1; slot < wake_.size(); ++slot) {
      const std::uint64_t at = wake_[slot];
      if (at == kNever) continue;
      if (at - now < kSpan) {
        wheel_[(at & (kSpan - 1)) * words_ + slot / 64] |= std::uint64_t{1} << (slot % 64);
      } else {
        far_ = std::min(far_, at);
      }
    }
  }

  std::vector<std::uint64_t> wake_;   // per slot: its wake cycle, kNever when not scheduled
  std::vector<std::uint64_t> wheel_;  // kSpan buckets of words_ words: bucket = cycle % kSpan
  std::size_t words_ = 0;
  std::uint64_t far_ = kNever;  // the earliest wake not (yet) in the wheel
};

}  // namespace saarcor::hw
