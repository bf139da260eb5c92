// The packet's binary64 images of encodings, shared by both datapaths (units/fast_datapath.h,
// units/reference_datapath.h): the exact value of an encoding, and the two-lane vectors the
// packet's segment bounds are kept, copied and compared in. Conversions here are exact and the
// compares are those of the encodings (a subnormal read as +-0 in flush mode, +-0 equal, NaN
// unordered), so nothing here rounds: the rounding ops of the units are units/datapath.h's
// (on encodings) and units/fast_paths.h's (on values, where they decide).
#pragma once

#include <bit>
#include <cstdint>

#include "fixedfloat/float.h"

namespace saarcor::units {

// The value of an encoding: exact, a subnormal read as +-0 in flush mode (as every op reads it).
template <class F>
[[gnu::always_inline]] inline double value_of(F x, ff::Subnormals s) {
  constexpr std::uint32_t kExpMax = F::kFormat.exp_field_max();
  const std::uint32_t e = (x.bits >> F::kManBits) & kExpMax;
  if (e - 1u < kExpMax - 1u) [[likely]]
    return ff::fast::decode_normal<F::kExpBits, F::kManBits>(x.bits);
  if ((x.bits & (F::kFormat.sign_mask() - 1u)) == 0) return x.sign() ? -0.0 : 0.0;
  return ff::decode(x.bits, F::kFormat, s);
}

// Two lanes in one SSE2 register (GCC/Clang vector extensions).
using V2d = double __attribute__((vector_size(16)));
using V2u = std::uint64_t __attribute__((vector_size(16)));
using V2i = std::int64_t __attribute__((vector_size(16)));

// Lane-wise select: c ? a : b for a compare result c (all ones or zero per lane).
[[gnu::always_inline]] inline V2d select2(V2i c, V2d a, V2d b) {
  const auto m = std::bit_cast<V2u>(c);
  return std::bit_cast<V2d>((m & std::bit_cast<V2u>(a)) | (~m & std::bit_cast<V2u>(b)));
}

// The lanes of a compare result as bits 0 and 1.
[[gnu::always_inline]] inline std::uint64_t mask2(V2i c) {
#if defined(__SSE2__) && (defined(__GNUC__) || defined(__clang__))
  return static_cast<std::uint64_t>(__builtin_ia32_movmskpd(std::bit_cast<V2d>(c)));
#else
  return static_cast<std::uint64_t>((c[0] & 1) | (c[1] & 2));
#endif
}

}  // namespace saarcor::units
