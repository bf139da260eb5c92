// The inline fast paths of the float ops for a format known at compile time (docs/fixedfloat.md).
// Float<E,M> and FpUnit call these; the runtime-format functions in format.h remain the general
// path every special case falls back to.
//
// Method (the same idea as format.cpp, with bit manipulation instead of frexp/ldexp/floor):
//   1. decode: an encoding becomes an exact, power-of-two-scaled binary64 value by moving its
//      exponent and mantissa fields into binary64 position and setting (or keeping) the binary64
//      exponent bits above them, so that the all-ones field lands on binary64 inf/NaN where that
//      helps (signed_decode for add/sub, the fill bits for mul/div);
//   2. the op runs once in binary64 (+, -, x, /, sqrt: correctly rounded to 53 bits; a product of
//      two significands of at most 24 bits is exact);
//   3. round: the binary64 bit pattern is rounded to M fraction bits with integer arithmetic (one
//      constant adds half - 1 and removes the exponent offset and the lowest accepted field, plus
//      the lowest kept bit for ties to even). A carry out of the mantissa increments the exponent
//      field, and a carry out of the largest finite value gives exactly the infinity encoding.
//      Double rounding is innocuous because 53 >= 2(M+1)+2 for every supported format (Figueroa
//      1995; docs/fixedfloat.md). One unsigned compare of the rounded field against a span from
//      the Rounder accepts the result: the span is empty for truncation, so the nearest-even
//      path needs no test of the mode.
// Nearest-even add/sub test no operand at all (see add_nearest for why zeros, subnormals, inf and
// NaN cannot pass wrongly); mul/div test the exponent fields (one or two instructions each).
// Truncation needs the sign of the exact error only when the binary64 value lies exactly on the
// target grid; only then is it computed (TwoSum for add, a fused remainder for div and sqrt), in
// the *_checked paths. Whatever the fast paths do not accept goes out of line to the *_rest
// functions and from there, for zeros, subnormals, inf, NaN and results outside the normal range,
// to the general path in format.cpp (binary64 value + exact error sign, round_pack). The MPFR
// tests (fixedfloat/*_test.cpp) check the whole arrangement bit for bit.
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

  // The fill bits: the kFill binary64 exponent bits above the target's E. Setting them makes the
  // binary64 exponent field e + kFillBias, so the all-ones field (inf, NaN) maps exactly onto
  // binary64 inf/NaN. The signed decode of the nearest-even add (signed_decode_bits): b << kTop
  // puts the sign at bit 63, an arithmetic shift by kFill copies it into the fill bits, and
  // or-ing kFillMask sets them for both signs. mul/div shift by kShift, which moves the sign
  // into the fill bits, where the or erases it.
  static constexpr int kTop = 63 - E - M;
  static constexpr int kFill = 11 - E;
  static constexpr std::uint64_t kFillMask = ((std::uint64_t{1} << kFill) - 1u) << (52 + E);
  static constexpr std::uint64_t kFillBias = 2048u - (1u << E);
  // Smallest exponent field of a sum the nearest-even add accepts: then every operand whose
  // exponent field is 0 (read as 2^emin * 1.f by the signed decode) is below a quarter ulp of the
  // sum and cannot change it, exactly like the zero it stands for (see add_nearest).
  static constexpr std::uint32_t kAddLowField = M + 3;
  static constexpr bool kAddNearest = kAddLowField < kExpMax;
  // Exponent offset of the product of a magnitude decoded with field e (scale 2^(bias-1023)) and
  // one decoded with field e + kFillBias: the product's binary64 field is e + kMulBias (e: the
  // product's biased exponent in the target format).
  static constexpr std::uint64_t kMulBias = kFillBias + kBias - 1023u;

  // Decodes for mul/div written so that their constants are small (x86-64 immediates instead of
  // 64-bit constants held in registers): the fill bits set before the shift (the sign bit is one
  // of them), the magnitude as a 32-bit shift that drops the sign followed by a 64-bit one.
  static std::uint64_t filled_bits(std::uint32_t b) {
    return (static_cast<std::uint64_t>(b) | (kFillMask >> kShift)) << kShift;
  }
  static std::uint64_t magnitude_bits_unbiased(std::uint32_t b) {
    return static_cast<std::uint64_t>(b << (32 - E - M)) << (kShift - (32 - E - M));
  }
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

// A Mode with the mode-dependent limits of the fast paths precomputed. For a binary64 magnitude
// |v| in the target's normal range, nearest-even gives the rounded exponent|mantissa field as
// (bits(|v|) + half - 1 - rebias + lsb) >> (52 - M), with lsb the lowest kept bit (a tie then
// rounds to even). Double rounding (binary64, then M+1 bits) is innocuous for +, -, x, /, sqrt
// whenever 53 >= 2(M+1)+2 (Figueroa 1995), which holds for every supported format (M <= 23), so
// nearest-even never needs the exact error. Truncation does: a binary64 value exactly on the
// target grid may stand for an exact result just below it.
//
// The spans are the widths of the ranges that the nearest-even paths accept: the whole range for
// nearest-even, empty for truncation (which then takes its own branch), so the common path needs
// no test of the mode. The struct is kept small (16 bytes) so that a compiler can hold a unit in
// registers and fold a mode it knows.
template <int E, int M>
struct Rounder {
  using L = Layout<E, M>;
  Mode mode;
  // round_mag: kept bits (bits(|v|) >> (52 - M)) from the smallest normal's on.
  std::uint32_t nearest_span;
  // Rounded exponent|mantissa fields from the lowest accepted one up to the infinity encoding:
  // add_nearest (from field kAddLowField), mul and div (from field 1).
  std::uint32_t add_span;
  std::uint32_t rounded_span;
  constexpr explicit Rounder(const Mode& m)
      : mode(m),
        nearest_span(m.rounding == Rounding::kNearestEven
                         ? static_cast<std::uint32_t>(L::kSpan >> L::kShift)
                         : 0u),
        add_span(m.rounding == Rounding::kNearestEven && L::kAddNearest
                     ? ((L::kExpMax - L::kAddLowField) << M) + 1u
                     : 0u),
        rounded_span(m.rounding == Rounding::kNearestEven ? ((L::kExpMax - 1u) << M) + 1u : 0u) {}
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
    constexpr std::uint64_t kAdd = L::kHalf - 1u - L::kRebias;
    return sign | static_cast<std::uint32_t>((mag + kAdd + (kept & 1u)) >> L::kShift);
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

// Both operands normal: the binary64 sum, rounded by round_mag (which also has truncation's
// in-range branch); everything else on the general path.
template <int E, int M>
inline std::uint32_t add_checked(std::uint32_t a, std::uint32_t b, const Rounder<E, M>& r) {
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

// Exact binary64 value, scaled by 2^(kFillBias + bias - 1023), of a normal encoding; an infinity
// or NaN becomes binary64 inf or NaN, and a zero or subnormal becomes +-2^emin * 1.f (scaled).
template <int E, int M>
inline std::uint64_t signed_decode_bits(std::uint32_t b) {
  using L = Layout<E, M>;
  const auto top = static_cast<std::int64_t>(static_cast<std::uint64_t>(b) << L::kTop);
  return static_cast<std::uint64_t>(top >> L::kFill) | L::kFillMask;
}
// signed_decode_bits of two operands. With GCC/Clang vector extensions on a little-endian machine
// both go through one 128-bit register (x86-64: two loads into it, one shift per direction, one
// or): fewer instructions than two scalar decodes and two moves into floating-point registers.
// The arithmetic right shift works on the upper 32-bit half of each 64-bit lane, which holds the
// whole shifted encoding as long as M <= 20 (then no bit crosses into the lower half).
#if defined(__GNUC__)
#define SAARCOR_FF_VECTOR_DECODE 1
#endif
struct DecodedPair {
  double x, y;
};
template <int E, int M>
inline DecodedPair signed_decode_pair(std::uint32_t a, std::uint32_t b) {
  using L = Layout<E, M>;
#if defined(SAARCOR_FF_VECTOR_DECODE)
  if constexpr (M <= 20 && std::endian::native == std::endian::little) {
    using U64x2 = std::uint64_t __attribute__((vector_size(16)));
    using I32x4 = std::int32_t __attribute__((vector_size(16)));
    U64x2 v = {a, b};
    v <<= L::kTop;
    v = std::bit_cast<U64x2>(std::bit_cast<I32x4>(v) >> L::kFill) | L::kFillMask;
    return {std::bit_cast<double>(v[0]), std::bit_cast<double>(v[1])};
  }
#endif
  return {std::bit_cast<double>(signed_decode_bits<E, M>(a)),
          std::bit_cast<double>(signed_decode_bits<E, M>(b))};
}

// The encoding back from signed_decode_bits.
template <int E, int M>
inline std::uint32_t signed_encode(double x) {
  using L = Layout<E, M>;
  const auto u = std::bit_cast<std::uint64_t>(x);
  return (static_cast<std::uint32_t>(u >> L::kShift) & L::kMag) |
         (static_cast<std::uint32_t>(u >> L::kTop) & L::kSign);
}
// What the nearest-even add leaves (truncation, sums out of its range, NaN results), from its
// decoded operands. Out of line, with the mode by value, so the common path stays short and the
// unit does not escape.
template <int E, int M>
[[gnu::noinline]] std::uint32_t add_rest(double x, double y, Mode m) {
  return add_checked<E, M>(signed_encode<E, M>(x), signed_encode<E, M>(y), Rounder<E, M>(m));
}

// The nearest-even add without a test of its operands. Both are decoded with signed_decode_bits
// and added once in binary64; the sum is rounded to the target's precision by integer arithmetic on
// its bit pattern (ties to even, a mantissa carry bumps the exponent, the largest finite value
// carries into exactly the infinity encoding) and accepted when the rounded exponent field lies in
// [M+3, all ones]:
//   - normal operands: as in add_checked (double rounding is innocuous, Figueroa 1995);
//   - an operand with exponent field 0 (zero or subnormal, in either subnormal mode) decodes as
//     some x with |x| < 2^emin. An accepted sum is at least 2^(emin+M+2), so the other operand y
//     is at least that large too (a sum of two operands below it stays below it) and |x| is less
//     than a quarter ulp of y: y + x rounds to y, the same as y + 0 or y + subnormal. Both
//     roundings see precision-(M+1) operands, so Figueroa's theorem covers the binary64 step here
//     as well;
//   - inf and NaN operands give binary64 inf (the infinity encoding, correct) or NaN (a rounded
//     field above all ones: rejected);
//   - overflow: a binary64 sum that overflows is beyond the target's overflow threshold, and its
//     infinity rounds to the infinity encoding; smaller sums carry into it by rounding;
//   - sums below the range, exact zeros (whose rounded field wraps around far above the range) and
//     truncation (add_span = 0) go to add_rest.
// kSub: a - b, as x - y on the decoded operands (the same binary64 operation as x + (-y)).
template <int E, int M, bool kSub>
inline std::uint32_t add_nearest(std::uint32_t a, std::uint32_t b, const Rounder<E, M>& r) {
  using L = Layout<E, M>;
  // The sum's bit pattern doubled drops its sign. One constant adds half - 1 at the rounding
  // position and removes the exponent offset kFillBias and the lowest accepted field, so q is the
  // rounded exponent|mantissa field minus its lowest accepted value (wrapping around far above the
  // range for exponents below it, exact zeros included).
  constexpr std::uint64_t kLow = std::uint64_t{L::kAddLowField} << M;
  constexpr std::uint64_t kRound =
      (std::uint64_t{1} << L::kShift) - 1u - (L::kFillBias << 53) - (kLow << (L::kShift + 1));
  const auto [x, y] = signed_decode_pair<E, M>(a, b);
  const double s = kSub ? x - y : x + y;
  const std::uint64_t u = std::bit_cast<std::uint64_t>(s);
  const std::uint64_t q = (u + u + kRound + ((u >> L::kShift) & 1u)) >> (L::kShift + 1);
  if (q < r.add_span) [[likely]]
    return static_cast<std::uint32_t>(q + kLow + ((u >> 63) << (E + M)));
  // The operands go out decoded (in floating-point registers, where they already are) so that the
  // common path need not keep the encodings live.
  return add_rest<E, M>(x, kSub ? -y : y, r.mode);
}

template <int E, int M>
inline std::uint32_t add(std::uint32_t a, std::uint32_t b, const Rounder<E, M>& r) {
  if constexpr (Layout<E, M>::kAddNearest) {
    return add_nearest<E, M, false>(a, b, r);
  } else {
    return add_checked<E, M>(a, b, r);
  }
}

template <int E, int M>
inline std::uint32_t sub(std::uint32_t a, std::uint32_t b, const Rounder<E, M>& r) {
  if constexpr (Layout<E, M>::kAddNearest) {
    return add_nearest<E, M, true>(a, b, r);
  } else {
    return add_checked<E, M>(a, b ^ Layout<E, M>::kSign, r);
  }
}

template <int E, int M>
inline std::uint32_t mul_checked(std::uint32_t a, std::uint32_t b, const Rounder<E, M>& r) {
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
[[gnu::noinline]] std::uint32_t mul_rest(std::uint32_t a, std::uint32_t b, Mode m) {
  return mul_checked<E, M>(a, b, Rounder<E, M>(m));
}

// The nearest-even mul. a must be normal and b's exponent field nonzero; a's magnitude is decoded
// with its exponent field unchanged (scale 2^(bias-1023)), b's with the field raised by kFillBias
// (its sign bit lands in the or-ed fill bits and vanishes; an infinity or NaN becomes binary64
// inf/NaN, whose product rounds far above the range and is rejected). The product of two
// significands of at most 24 bits is exact, so one rounding of its bit pattern gives the result;
// a rounded field in [1, all ones] is accepted (all ones: the overflow to infinity).
template <int E, int M>
inline std::uint32_t mul(std::uint32_t a, std::uint32_t b, const Rounder<E, M>& r) {
  using L = Layout<E, M>;
  // Rounding constant (half - 1), the product's exponent offset and the lowest accepted field (1):
  // q is the rounded exponent|mantissa field minus 1 << M (wrapping around far above the range
  // for products below it).
  constexpr std::uint64_t kLow = std::uint64_t{1} << M;
  constexpr std::uint64_t kRound = L::kHalf - 1u - (L::kMulBias << 52) - (kLow << L::kShift);
  if (is_normal<E, M>(a) && (b & (L::kExpMax << M)) != 0) [[likely]] {
    const std::uint32_t sign = (a ^ b) & L::kSign;
    const double x = std::bit_cast<double>(L::magnitude_bits_unbiased(a));
    const double y = std::bit_cast<double>(L::filled_bits(b));
    const std::uint64_t t = std::bit_cast<std::uint64_t>(x * y);
    const std::uint64_t q = (t + kRound + ((t >> L::kShift) & 1u)) >> L::kShift;
    if (q < r.rounded_span) [[likely]]
      return static_cast<std::uint32_t>(q + kLow) + sign;
    // The operands again from their decoded magnitudes and the product's sign (the result depends
    // on the signs only through it), so the common path need not keep the encodings live.
    return mul_rest<E, M>(
        static_cast<std::uint32_t>(std::bit_cast<std::uint64_t>(x) >> L::kShift) | sign,
        static_cast<std::uint32_t>(std::bit_cast<std::uint64_t>(y) >> L::kShift) & L::kMag, r.mode);
  }
  return mul_rest<E, M>(a, b, r.mode);
}

template <int E, int M>
inline std::uint32_t div_checked(std::uint32_t a, std::uint32_t b, const Rounder<E, M>& r) {
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
[[gnu::noinline]] std::uint32_t div_rest(std::uint32_t a, std::uint32_t b, Mode m) {
  return div_checked<E, M>(a, b, Rounder<E, M>(m));
}

// The nearest-even div. Both exponent fields must be nonzero; both magnitudes are decoded with the
// field raised by kFillBias (sign bits vanish in the fill bits, inf/NaN become binary64 inf/NaN),
// so the binary64 quotient is unscaled. It is rounded once more like the product in mul (double
// rounding is innocuous for division too); an infinite, NaN or zero quotient (from inf or NaN
// operands) rounds far outside the accepted range [1, all ones].
template <int E, int M>
inline std::uint32_t div(std::uint32_t a, std::uint32_t b, const Rounder<E, M>& r) {
  using L = Layout<E, M>;
  constexpr std::uint64_t kLow = std::uint64_t{1} << M;
  constexpr std::uint64_t kDivBias = 1023u - L::kBias;
  constexpr std::uint64_t kRound = L::kHalf - 1u - (kDivBias << 52) - (kLow << L::kShift);
  constexpr std::uint32_t kExpField = L::kExpMax << M;
  if ((a & kExpField) != 0 && (b & kExpField) != 0) [[likely]] {
    const std::uint32_t sign = (a ^ b) & L::kSign;
    const double x = std::bit_cast<double>(L::filled_bits(a));
    const double y = std::bit_cast<double>(L::filled_bits(b));
    const std::uint64_t t = std::bit_cast<std::uint64_t>(x / y);
    const std::uint64_t q = (t + kRound + ((t >> L::kShift) & 1u)) >> L::kShift;
    if (q < r.rounded_span) [[likely]]
      return static_cast<std::uint32_t>(q + kLow) + sign;
    return div_rest<E, M>(
        (static_cast<std::uint32_t>(std::bit_cast<std::uint64_t>(x) >> L::kShift) & L::kMag) | sign,
        static_cast<std::uint32_t>(std::bit_cast<std::uint64_t>(y) >> L::kShift) & L::kMag, r.mode);
  }
  return div_rest<E, M>(a, b, r.mode);
}

// Division by a divisor whose binary64 reciprocal inv_b = 1 / |b| is known (b normal; computed once
// for many dividends, as the traversal unit's d = (split - O) / D with D fixed per level): the
// quotient's magnitude as the binary64 product |a| * inv_b, rounded as in div. For nearest-even
// this is the correctly rounded quotient whenever it is accepted: with A, B the integer
// significands (M+1 bits) the exact quotient A/B is a nonzero integer over B * 2^(M+1) (or 2^(M+2))
// away from every rounding midpoint (a midpoint has M+2 significant bits ending in 1, and A * 2^k =
// B * odd is impossible for B < 2^(M+1)), i.e. more than 2^-(2M+3) relative, while |a| * inv_b is
// within 2^-52 (two binary64 roundings) of A/B. 2^-52 < 2^-49 = 2^-(2*23+3), so for every supported
// format the product lies on the same side of every midpoint as the exact quotient and rounds to
// the same encoding (the range limits, overflow to infinity and the flush threshold included,
// since they are decided by the rounded value). Truncation (rounded_span = 0), operands that are
// not normal and quotients outside the range take the exact div_rest. Tested against op_div in
// fixedfloat/div_reciprocal_test.cpp.
template <int E, int M>
inline double reciprocal(std::uint32_t b) {
  return 1.0 / std::bit_cast<double>(magnitude_bits<E, M>(b));
}
template <int E, int M>
inline std::uint32_t div_reciprocal(std::uint32_t a, std::uint32_t b, double inv_b,
                                    const Rounder<E, M>& r) {
  using L = Layout<E, M>;
  constexpr std::uint64_t kLow = std::uint64_t{1} << M;
  constexpr std::uint64_t kRound = L::kHalf - 1u - L::kRebias - (kLow << L::kShift);
  if (both_normal<E, M>(a, b)) [[likely]] {
    const std::uint32_t sign = (a ^ b) & L::kSign;
    const double x = std::bit_cast<double>(magnitude_bits<E, M>(a));
    const std::uint64_t t = std::bit_cast<std::uint64_t>(x * inv_b);
    const std::uint64_t q = (t + kRound + ((t >> L::kShift) & 1u)) >> L::kShift;
    if (q < r.rounded_span) [[likely]]
      return static_cast<std::uint32_t>(q + kLow) + sign;
  }
  return div_rest<E, M>(a, b, r.mode);
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

// Compares on the encodings, without decoding: the magnitude bits order like the magnitude (for
// every non-NaN encoding), so sign ? -magnitude : magnitude orders like the value, with -0 and +0
// both 0. In flush mode a subnormal magnitude reads as 0 first. NaN compares false.
template <int E, int M>
inline std::int32_t order_key(std::uint32_t b, Subnormals s) {
  using L = Layout<E, M>;
  std::uint32_t mag = b & L::kMag;
  if (s == Subnormals::kFlush && mag < (1u << M)) mag = 0;
  const auto k = static_cast<std::int32_t>(mag);
  return (b & L::kSign) != 0 ? -k : k;
}
template <int E, int M>
inline bool no_nan(std::uint32_t a, std::uint32_t b) {
  using L = Layout<E, M>;
  constexpr std::uint32_t kInf = L::kExpMax << M;
  return ((a & L::kMag) <= kInf) & ((b & L::kMag) <= kInf);
}
template <int E, int M>
inline bool lt(std::uint32_t a, std::uint32_t b, const Mode& m) {
  // Both conditions are evaluated and combined with a bitwise AND, as the comparator's two
  // signals are: no branch on the operands.
  const bool ordered = no_nan<E, M>(a, b);
  const bool less = order_key<E, M>(a, m.subnormals) < order_key<E, M>(b, m.subnormals);
  return ordered & less;
}
template <int E, int M>
inline bool le(std::uint32_t a, std::uint32_t b, const Mode& m) {
  const bool ordered = no_nan<E, M>(a, b);
  const bool less_equal = order_key<E, M>(a, m.subnormals) <= order_key<E, M>(b, m.subnormals);
  return ordered & less_equal;
}
template <int E, int M>
inline bool eq(std::uint32_t a, std::uint32_t b, const Mode& m) {
  const bool ordered = no_nan<E, M>(a, b);
  const bool equal = order_key<E, M>(a, m.subnormals) == order_key<E, M>(b, m.subnormals);
  return ordered & equal;
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
