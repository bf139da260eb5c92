// Binary32 neighbours and outward rounding from binary64, for the kd-tree builder's conservative
// bounds: a straddling triangle's clipped piece is bounded in binary64 and its box rounded outward
// to binary32, so the box the tree stores still encloses the piece (docs/kdtree.md).
#pragma once

#include <bit>
#include <cstdint>
#include <limits>

namespace saarcor::host {

// Neighbours of a finite binary32 value (inline: libm's nextafter is a call).
inline float float_next_down(float f) {
  const std::uint32_t u = std::bit_cast<std::uint32_t>(f);
  if (f == 0.0f) {
    return -std::numeric_limits<float>::denorm_min();
  }
  return std::bit_cast<float>(f > 0.0f ? u - 1u : u + 1u);
}
inline float float_next_up(float f) {
  return -float_next_down(-f);
}
// Rounding a binary64 value outward to binary32, without a branch (a straddler's clip rounds 12
// bounds, about half of them in each direction at random: as branches they cost a fifth of the
// clip). Up: where the nearest binary32 value lies below d, one step up in the bit pattern, +1 on
// a positive value's magnitude bits and -1 on a negative one's (-0 never lies below d, and +0
// steps to the smallest subnormal). Down is up mirrored (round to nearest is symmetric).
inline float float_up(double d) {
  const float f = static_cast<float>(d);
  const std::uint32_t u = std::bit_cast<std::uint32_t>(f);
  const std::uint32_t step = static_cast<std::uint32_t>(static_cast<std::int32_t>(u) >> 31) | 1u;
  const std::uint32_t below = 0u - static_cast<std::uint32_t>(static_cast<double>(f) < d);
  return std::bit_cast<float>(u + (step & below));
}
inline float float_down(double d) {
  return -float_up(-d);
}

}  // namespace saarcor::host
