// The inline fast paths of the float ops for a format known at compile time (DESIGN.md section 3).
// Float<E,M> and FpUnit call these; the runtime-format functions in format.h remain the general
// path every special case falls back to.
//
// Method (the same idea as format.cpp, with bit manipulation instead of frexp/ldexp/floor):
//   1. decode: a normal encoding becomes its exact binary64 magnitude by moving the exponent and
//      mantissa fields into binary64 position and re-biasing the exponent (one shift, one add);
//      signs are handled on the encodings (mul/div: sign xor; add: b's sign relative to a's);
//   2. the op runs once in binary64 (+, -, x, /, sqrt: correctly rounded to 53 bits; a product of
//      two significands of at most 24 bits is exact);
//   3. round: when the binary64 result lies in the target's normal exponent range, its 52-bit
//      fraction is cut to M bits with integer arithmetic on the bit pattern. A carry out of the
//      mantissa increments the exponent field, and a carry out of the largest finite value gives
//      exactly the infinity encoding. Nearest-even rounds the binary64 value with ties to even:
//      double rounding is innocuous because 53 >= 2(M+1)+2 for every supported format (Figueroa
//      1995; DESIGN.md section 3). Truncation needs the sign of the exact error only when the
//      binary64 value lies exactly on the target grid; only then is it computed (TwoSum for add,
//      a fused remainder for div and sqrt).
// Zeros, subnormals, inf, NaN and results outside the normal range take the general path in
// format.cpp (binary64 value + exact error sign, round_pack). The MPFR tests
// (fixedfloat/*_test.cpp) check the whole arrangement bit for bit.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

#include "fixedfloat/format.h"

namespace saarcor::ff::fast {

template <int E, int M>
struct Layout {
  static_assert(E >= 2 && E <= 8 && M >= 1 && M <= 23, "format outside the supported range");
  static constexpr Format kFormat{E, M};
  static constexpr int kBias = (1 << (E - 1)) - 1;
  static constexpr std::uint32_t kExpMax = (1u << E) - 1u;
  static constexpr std::uint32_t kSign = 1u << (E + M);
  static constexpr std::uint32_t kMag = kSign - 1u;
  static constexpr int kShift = 52 - M;  // binary64 fraction bits below the target's mantissa
  static constexpr std::uint64_t kRebias = static_cast<std::uint64_t>(1023 - kBias) << 52;
  // Magnitude bit patterns of binary64 values in the target's normal binades:
  // [2^emin, 2^(emax+1)) <=> [kLow, kLow + kSpan).
  static constexpr std::uint64_t kLow = static_cast<std::uint64_t>(1023 + 1 - kBias) << 52;
  static constexpr std::uint64_t kSpan = static_cast<std::uint64_t>(kExpMax - 1u) << 52;
  static constexpr std::uint64_t kLowBits = (std::uint64_t{1} << kShift) - 1u;
  static constexpr std::uint64_t kHalf = std::uint64_t{1} << (kShift - 1);
};

// True for normal encodings (exponent field neither 0 nor all ones): adding one to the exponent
// field wraps the all-ones field to 0, so normal <=> (field + 1) mod 2^E >= 2, i.e. some bit of
// (field + 1) above the lowest is set.
template <int E, int M>
inline bool is_normal(std::uint32_t b) {
  using L = Layout<E, M>;
  return ((b + (1u << M)) & ((L::kExpMax - 1u) << M)) != 0;
}
template <int E, int M>
inline bool both_normal(std::uint32_t a, std::uint32_t b) {
  return is_normal<E, M>(a) & is_normal<E, M>(b);
}

// Bit pattern of the exact binary64 magnitude of a normal encoding.
template <int E, int M>
inline std::uint64_t magnitude_bits(std::uint32_t b) {
  using L = Layout<E, M>;
  return (static_cast<std::uint64_t>(b & L::kMag) << L::kShift) + L::kRebias;
}

// Exact binary64 value of a normal encoding.
template <int E, int M>
inline double decode_normal(std::uint32_t b) {
  using L = Layout<E, M>;
  const std::uint64_t sign = static_cast<std::uint64_t>(b & L::kSign) << (63 - E - M);
  return std::bit_cast<double>(magnitude_bits<E, M>(b) | sign);
}

// Exact binary64 value of any encoding (subnormals read as +-0 in flush mode).
template <int E, int M>
inline double decode(std::uint32_t b, Subnormals s) {
  if (is_normal<E, M>(b)) [[likely]]
    return decode_normal<E, M>(b);
  return ff::decode(b, Layout<E, M>::kFormat, s);
}

// The general paths, called with the mode by value: passing a reference to a member of the
// caller's FpUnit would let that object escape, and the compiler would then reload the unit's
// fields on every op instead of keeping them in registers.
template <int E, int M>
[[gnu::noinline]] std::uint32_t slow_add(std::uint32_t a, std::uint32_t b, Mode m) {
  return op_add(a, b, Layout<E, M>::kFormat, m);
}
template <int E, int M>
[[gnu::noinline]] std::uint32_t slow_mul(std::uint32_t a, std::uint32_t b, Mode m) {
  return op_mul(a, b, Layout<E, M>::kFormat, m);
}
template <int E, int M>
[[gnu::noinline]] std::uint32_t slow_div(std::uint32_t a, std::uint32_t b, Mode m) {
  return op_div(a, b, Layout<E, M>::kFormat, m);
}
template <int E, int M>
[[gnu::noinline]] std::uint32_t slow_sqrt(std::uint32_t a, Mode m) {
  return op_sqrt(a, Layout<E, M>::kFormat, m);
}
template <int E, int M>
[[gnu::noinline]] std::uint32_t slow_round(double v, int dir, Mode m) {
  return round_pack(v, dir, Layout<E, M>::kFormat, m);
}

// A Mode with the constant of the common rounding case precomputed: for a binary64 magnitude |v|
// in the target's normal range, nearest-even gives the rounded exponent|mantissa field as
// (bits(|v|) + add + lsb) >> (52 - M), with add = half - 1 - rebias and lsb the lowest kept bit
// (a tie then rounds to even). Double rounding (binary64, then M+1 bits) is innocuous for +, -, x,
// /, sqrt whenever 53 >= 2(M+1)+2 (Figueroa 1995), which holds for every supported format (M <=
// 23), so nearest-even never needs the exact error. Truncation does: a binary64 value exactly on
// the target grid may stand for an exact result just below it.
template <int E, int M>
struct Rounder {
  using L = Layout<E, M>;
  Mode mode;
  std::uint64_t add;
  // Width of the range of kept bits (bits(|v|) >> (52 - M)) that the nearest-even path takes:
  // the whole normal range for nearest-even, empty for truncation (which then takes its own
  // branch), so the common path needs no test of the mode.
  std::uint64_t nearest_span;
  constexpr explicit Rounder(const Mode& m)
      : mode(m),
        add(L::kHalf - 1u - L::kRebias),
        nearest_span(m.rounding == Rounding::kNearestEven ? (L::kSpan >> L::kShift) : 0u) {}
};

// Truncation of a magnitude exactly on the grid; d is the sign of (exact magnitude - |v|). The
// step down may leave the normal range, into the largest subnormal (flushed in flush mode).
template <int E, int M>
inline std::uint32_t truncate_on_grid(std::uint64_t mag, const Mode& mode, int d) {
  using L = Layout<E, M>;
  auto q = static_cast<std::uint32_t>((mag - L::kRebias) >> L::kShift);
  if (d < 0) {
    --q;
    if ((q >> M) == 0 && mode.subnormals == Subnormals::kFlush) return 0u;
  }
  return q;
}

// Rounds the binary64 magnitude with bit pattern `mag` into Float<E,M> and attaches `sign` (the
// result's sign bit in encoding position). dir_fn() returns the sign of (exact magnitude - |v|);
// it is called only for truncation of a value on the grid, or on the general path.
template <int E, int M, class DirFn, class SlowFn>
inline std::uint32_t round_mag(std::uint64_t mag, std::uint32_t sign, const Rounder<E, M>& r,
                               DirFn dir_fn, SlowFn slow_fn) {
  using L = Layout<E, M>;
  // The kept bits (exponent and the top M fraction bits) decide the range; their constants fit in
  // 32 bits, which keeps the common path free of 64-bit immediates.
  const std::uint64_t kept = mag >> L::kShift;
  const std::uint64_t offset = kept - (L::kLow >> L::kShift);
  if (offset < r.nearest_span) [[likely]] {
    // Nearest-even in the normal range. A carry out of the mantissa increments the exponent
    // field; a carry out of the largest finite value gives exactly the infinity encoding.
    return sign | static_cast<std::uint32_t>((mag + r.add + (kept & 1u)) >> L::kShift);
  }
  if (offset < (L::kSpan >> L::kShift) && r.mode.rounding == Rounding::kTowardZero) {
    if ((mag & L::kLowBits) != 0)
      return sign | static_cast<std::uint32_t>((mag - L::kRebias) >> L::kShift);
    return sign | truncate_on_grid<E, M>(mag, r.mode, dir_fn());
  }
  return slow_fn();
}

// round_mag with the general round_pack as the way out of the normal range.
template <int E, int M, class DirFn>
inline std::uint32_t round_mag(std::uint64_t mag, std::uint32_t sign, const Rounder<E, M>& r,
                               DirFn dir_fn) {
  return round_mag<E, M>(mag, sign, r, dir_fn, [&] {
    const double v = std::bit_cast<double>(mag | (sign ? (std::uint64_t{1} << 63) : 0u));
    return slow_round<E, M>(v, sign ? -dir_fn() : dir_fn(), r.mode);
  });
}

// Splits a signed binary64 result into its magnitude bits and the encoding's sign bit.
template <int E, int M>
inline std::uint64_t split_sign(double v, std::uint32_t* sign) {
  const std::uint64_t u = std::bit_cast<std::uint64_t>(v);
  *sign = static_cast<std::uint32_t>(u >> (63 - E - M)) & Layout<E, M>::kSign;
  return u & 0x7FFF'FFFF'FFFF'FFFFull;
}

inline int sign_of(double x) {
  return (x > 0.0) - (x < 0.0);
}

template <int E, int M>
inline std::uint32_t add(std::uint32_t a, std::uint32_t b, const Rounder<E, M>& r) {
  using L = Layout<E, M>;
  if (both_normal<E, M>(a, b)) [[likely]] {
    // |a| + (+-|b|) with b's sign relative to a's: the sum's sign flips a's sign when negative.
    const std::uint64_t rel = static_cast<std::uint64_t>((a ^ b) & L::kSign) << (63 - E - M);
    const double s = std::bit_cast<double>(magnitude_bits<E, M>(a)) +
                     std::bit_cast<double>(magnitude_bits<E, M>(b) | rel);
    const std::uint64_t u = std::bit_cast<std::uint64_t>(s);
    const std::uint32_t sign = (static_cast<std::uint32_t>(u >> (63 - E - M)) ^ a) & L::kSign;
    return round_mag<E, M>(
        u & 0x7FFF'FFFF'FFFF'FFFFull, sign, r,
        [&] {
          // TwoSum (Knuth): the exact error of the binary64 addition, as seen by the magnitude. The
          // operands are decoded again here so the common path need not keep them live.
          const double x = std::bit_cast<double>(magnitude_bits<E, M>(a));
          const double y = std::bit_cast<double>(magnitude_bits<E, M>(b) | rel);
          const double bb = s - x;
          const int d = sign_of((x - (s - bb)) + (y - bb));
          return (u >> 63) ? -d : d;
        },
        // Out of the normal range (overflow, cancellation to zero or below the smallest normal):
        // the general path, which also gives exact cancellation its +0.
        [&] { return slow_add<E, M>(a, b, r.mode); });
  }
  return slow_add<E, M>(a, b, r.mode);
}

template <int E, int M>
inline std::uint32_t sub(std::uint32_t a, std::uint32_t b, const Rounder<E, M>& r) {
  return add<E, M>(a, b ^ Layout<E, M>::kSign, r);
}

template <int E, int M>
inline std::uint32_t mul(std::uint32_t a, std::uint32_t b, const Rounder<E, M>& r) {
  if (both_normal<E, M>(a, b)) [[likely]] {
    // Two significands of at most 24 bits: the binary64 product of the magnitudes is exact.
    const double p = std::bit_cast<double>(magnitude_bits<E, M>(a)) *
                     std::bit_cast<double>(magnitude_bits<E, M>(b));
    return round_mag<E, M>(std::bit_cast<std::uint64_t>(p), (a ^ b) & Layout<E, M>::kSign, r,
                           [] { return 0; });
  }
  return slow_mul<E, M>(a, b, r.mode);
}

template <int E, int M>
inline std::uint32_t div(std::uint32_t a, std::uint32_t b, const Rounder<E, M>& r) {
  if (both_normal<E, M>(a, b)) [[likely]] {
    const double x = std::bit_cast<double>(magnitude_bits<E, M>(a));
    const double y = std::bit_cast<double>(magnitude_bits<E, M>(b));
    const double q = x / y;
    // x - q*y is exact in one fused operation and has the sign of x/y - q (y > 0).
    return round_mag<E, M>(std::bit_cast<std::uint64_t>(q), (a ^ b) & Layout<E, M>::kSign, r,
                           [&] { return sign_of(std::fma(-q, y, x)); });
  }
  return slow_div<E, M>(a, b, r.mode);
}

template <int E, int M>
inline std::uint32_t sqrt(std::uint32_t a, const Rounder<E, M>& r) {
  if (is_normal<E, M>(a) && !(a & Layout<E, M>::kSign)) [[likely]] {
    const double x = std::bit_cast<double>(magnitude_bits<E, M>(a));
    const double s = std::sqrt(x);
    return round_mag<E, M>(std::bit_cast<std::uint64_t>(s), 0u, r,
                           [&] { return sign_of(std::fma(-s, s, x)); });
  }
  return slow_sqrt<E, M>(a, r.mode);
}

template <int E, int M>
inline bool lt(std::uint32_t a, std::uint32_t b, const Mode& m) {
  return decode<E, M>(a, m.subnormals) < decode<E, M>(b, m.subnormals);
}
template <int E, int M>
inline bool le(std::uint32_t a, std::uint32_t b, const Mode& m) {
  return decode<E, M>(a, m.subnormals) <= decode<E, M>(b, m.subnormals);
}
template <int E, int M>
inline bool eq(std::uint32_t a, std::uint32_t b, const Mode& m) {
  return decode<E, M>(a, m.subnormals) == decode<E, M>(b, m.subnormals);
}

// The value a comparator/mux passes on: in flush mode a subnormal operand leaves as signed zero.
template <int E, int M>
inline std::uint32_t flushed(std::uint32_t b, const Mode& m) {
  using L = Layout<E, M>;
  if (m.subnormals == Subnormals::kFlush && ((b >> M) & L::kExpMax) == 0) return b & L::kSign;
  return b;
}
template <int E, int M>
inline std::uint32_t min(std::uint32_t a, std::uint32_t b, const Mode& m) {
  return flushed<E, M>(lt<E, M>(b, a, m) ? b : a, m);
}
template <int E, int M>
inline std::uint32_t max(std::uint32_t a, std::uint32_t b, const Mode& m) {
  return flushed<E, M>(lt<E, M>(a, b, m) ? b : a, m);
}

template <int E, int M>
inline std::uint32_t from_double(double v, const Mode& m) {
  std::uint32_t sign;
  const std::uint64_t mag = split_sign<E, M>(v, &sign);
  return round_mag<E, M>(mag, sign, Rounder<E, M>(m), [] { return 0; });
}

}  // namespace saarcor::ff::fast
