// Test support of fixedfloat/ and of rtl/: seeded operands in the manner of TestFloat, for the
// oracle tests (MPFR, Verilated RTL) that check every float operator. Header-only, std only.
#pragma once

#include <algorithm>
#include <cstdint>
#include <iterator>
#include <random>
#include <utility>

#include "fixedfloat/format.h"

namespace saarcor::ff::testing {

// Seeded operand generator in the manner of TestFloat: a mix of uniform encodings, operands with
// nearby exponents (cancellation, ties, carries), exponents at the ends of the range (overflow,
// underflow, subnormals) and special mantissa patterns.
class OperandGen {
 public:
  OperandGen(const Format& f, std::uint64_t seed) : f_(f), rng_(seed) {}

  std::uint32_t any() { return static_cast<std::uint32_t>(rng_()) & f_.bits_mask(); }

  // A second operand related to the first.
  std::pair<std::uint32_t, std::uint32_t> pair() {
    const std::uint32_t kind = static_cast<std::uint32_t>(rng_() % 16);
    std::uint32_t a = kind < 12 ? any() : edgy();
    std::uint32_t b;
    if (kind < 5) {
      b = any();
    } else if (kind < 11) {
      // Exponent within the significand width of a's (either sign): cancellation and ties.
      const int ea = static_cast<int>((a >> f_.man_bits) & f_.exp_field_max());
      const int span = f_.man_bits + 3;
      int eb = ea + static_cast<int>(rng_() % (2 * span + 1)) - span;
      eb = std::clamp(eb, 0, static_cast<int>(f_.exp_field_max()));
      b = (static_cast<std::uint32_t>(rng_()) & f_.sign_mask()) |
          (static_cast<std::uint32_t>(eb) << f_.man_bits) | mantissa();
    } else {
      b = edgy();
    }
    if (rng_() % 2) std::swap(a, b);
    return {a, b};
  }

 private:
  std::uint32_t mantissa() {
    switch (rng_() % 6) {
      case 0:
        return 0;
      case 1:
        return f_.man_mask();
      case 2:
        return static_cast<std::uint32_t>(rng_() % 4);
      case 3:
        return f_.man_mask() - static_cast<std::uint32_t>(rng_() % 4);
      case 4:
        return (1u << (f_.man_bits - 1)) ^ static_cast<std::uint32_t>(rng_() % 3);
      default:
        return static_cast<std::uint32_t>(rng_()) & f_.man_mask();
    }
  }
  // Exponent fields at the ends of the range (0 and all-ones included).
  std::uint32_t edgy() {
    const std::uint32_t top = f_.exp_field_max();
    const std::uint32_t choices[] = {
        0, 1, 2, 3, top - 3, top - 2, top - 1, top, static_cast<std::uint32_t>(f_.bias())};
    const std::uint32_t e = choices[rng_() % std::size(choices)];
    return (static_cast<std::uint32_t>(rng_()) & f_.sign_mask()) | (e << f_.man_bits) | mantissa();
  }

  Format f_;
  std::mt19937_64 rng_;
};

}  // namespace saarcor::ff::testing
