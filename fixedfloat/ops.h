// The inline fast paths of the float ops for a format known at compile time (DESIGN.md section 3).
// Float<E,M> and FpUnit call these; the runtime-format functions in format.h remain the general
// path every special case falls back to.
//
// Method (the same as format.cpp, only with bit manipulation instead of frexp/ldexp/floor):
//   1. decode: a normal encoding becomes its exact binary64 value by moving the exponent/mantissa
//      fields into binary64 position and re-biasing the exponent (one shift, one add);
//   2. the op runs once in binary64 (+, -, x, /, sqrt: correctly rounded to 53 bits);
//   3. round: when the binary64 result lies in the target's normal exponent range, its 52-bit
//      fraction is cut to M bits with integer arithmetic on the bit pattern. A carry out of the
//      mantissa increments the exponent field, and a carry out of the largest finite value gives
//      exactly the infinity encoding. Only when the discarded bits are exactly a tie (nearest
//      even) or exactly zero (truncation) does the sign of the exact error decide, and only then
//      is it computed (TwoSum for add, a fused remainder for div and sqrt; products of two
//      significands of at most 24 bits are exact in binary64, so mul never needs it).
// Zeros, subnormals, inf, NaN and results outside the normal range take the general path. The
// MPFR tests (fixedfloat/*_test.cpp) check the whole arrangement bit for bit.
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

// True for normal encodings (exponent field neither 0 nor all ones).
template <int E, int M>
inline bool is_normal(std::uint32_t b) {
  using L = Layout<E, M>;
  return ((b >> M) & L::kExpMax) - 1u < L::kExpMax - 1u;
}

// Exact binary64 value of a normal encoding.
template <int E, int M>
inline double decode_normal(std::uint32_t b) {
  using L = Layout<E, M>;
  const std::uint64_t mag = static_cast<std::uint64_t>(b & L::kMag) << L::kShift;
  const std::uint64_t sign = static_cast<std::uint64_t>(b & L::kSign) << (63 - E - M);
  return std::bit_cast<double>((mag + L::kRebias) | sign);
}

// Exact binary64 value of any encoding (subnormals read as +-0 in flush mode).
template <int E, int M>
inline double decode(std::uint32_t b, Subnormals s) {
  if (is_normal<E, M>(b)) [[likely]]
    return decode_normal<E, M>(b);
  return ff::decode(b, Layout<E, M>::kFormat, s);
}

// Rounds v into Float<E,M>. dir_fn() returns the sign of (exact result - v); it is called only
// when the discarded bits leave the rounding undecided, or on the general path.
template <int E, int M, class DirFn>
inline std::uint32_t round(double v, const Mode& mode, DirFn dir_fn) {
  using L = Layout<E, M>;
  const std::uint64_t u = std::bit_cast<std::uint64_t>(v);
  const std::uint64_t mag = u & 0x7FFF'FFFF'FFFF'FFFFull;
  if (mag - L::kLow < L::kSpan) [[likely]] {
    const std::uint32_t sign = static_cast<std::uint32_t>(u >> 63) << (E + M);
    const std::uint64_t t = mag - L::kRebias;  // target exponent field | 52-bit fraction
    const std::uint64_t low = t & L::kLowBits;
    if (mode.rounding == Rounding::kNearestEven) {
      if (low != L::kHalf) [[likely]]
        return sign | static_cast<std::uint32_t>((t + L::kHalf) >> L::kShift);
      // v is exactly halfway: the exact result's side decides, ties go to even.
      const int d = (u >> 63) ? -dir_fn() : dir_fn();
      const auto q = static_cast<std::uint32_t>(t >> L::kShift);
      return sign | (q + ((d > 0 || (d == 0 && (q & 1u))) ? 1u : 0u));
    }
    auto q = static_cast<std::uint32_t>(t >> L::kShift);
    if (low != 0) [[likely]]
      return sign | q;
    // v sits on the grid: truncation steps one down if the exact magnitude is just below it. The
    // borrow may leave the normal range, into the largest subnormal.
    const int d = (u >> 63) ? -dir_fn() : dir_fn();
    if (d < 0) {
      --q;
      if ((q >> M) == 0 && mode.subnormals == Subnormals::kFlush) return sign;
    }
    return sign | q;
  }
  return round_pack(v, dir_fn(), L::kFormat, mode);
}

inline int sign_of(double x) {
  return (x > 0.0) - (x < 0.0);
}

template <int E, int M>
inline std::uint32_t add(std::uint32_t a, std::uint32_t b, const Mode& m) {
  if (is_normal<E, M>(a) && is_normal<E, M>(b)) [[likely]] {
    const double x = decode_normal<E, M>(a);
    const double y = decode_normal<E, M>(b);
    const double s = x + y;
    return round<E, M>(s, m, [&] {
      // TwoSum (Knuth): the exact error of the binary64 addition.
      const double bb = s - x;
      return sign_of((x - (s - bb)) + (y - bb));
    });
  }
  return op_add(a, b, Layout<E, M>::kFormat, m);
}

template <int E, int M>
inline std::uint32_t sub(std::uint32_t a, std::uint32_t b, const Mode& m) {
  return add<E, M>(a, b ^ Layout<E, M>::kSign, m);
}

template <int E, int M>
inline std::uint32_t mul(std::uint32_t a, std::uint32_t b, const Mode& m) {
  if (is_normal<E, M>(a) && is_normal<E, M>(b)) [[likely]] {
    // Two significands of at most 24 bits: the binary64 product is exact.
    const double p = decode_normal<E, M>(a) * decode_normal<E, M>(b);
    return round<E, M>(p, m, [] { return 0; });
  }
  return op_mul(a, b, Layout<E, M>::kFormat, m);
}

template <int E, int M>
inline std::uint32_t div(std::uint32_t a, std::uint32_t b, const Mode& m) {
  if (is_normal<E, M>(a) && is_normal<E, M>(b)) [[likely]] {
    const double x = decode_normal<E, M>(a);
    const double y = decode_normal<E, M>(b);
    const double q = x / y;
    // x - q*y is exact in one fused operation; x/y - q has its sign times sign(y).
    return round<E, M>(q, m, [&] { return sign_of(std::fma(-q, y, x)) * sign_of(y); });
  }
  return op_div(a, b, Layout<E, M>::kFormat, m);
}

template <int E, int M>
inline std::uint32_t sqrt(std::uint32_t a, const Mode& m) {
  if (is_normal<E, M>(a) && !(a & Layout<E, M>::kSign)) [[likely]] {
    const double x = decode_normal<E, M>(a);
    const double r = std::sqrt(x);
    return round<E, M>(r, m, [&] { return sign_of(std::fma(-r, r, x)); });
  }
  return op_sqrt(a, Layout<E, M>::kFormat, m);
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
  return round<E, M>(v, m, [] { return 0; });
}

}  // namespace saarcor::ff::fast
