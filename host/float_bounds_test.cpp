// Outward rounding to binary32 (host/float_bounds.h) against std::nextafter: float_up(d) is the
// least binary32 value >= d and float_down(d) the greatest <= d, bit for bit (signed zeros
// included), at every kind of binary32 value and the binary64 values next to it.
#include "host/float_bounds.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

namespace saarcor::host {
namespace {

// The reference: round to nearest, then one step with the C library where that went the wrong
// way.
float reference_up(double d) {
  float f = static_cast<float>(d);
  if (static_cast<double>(f) < d) {
    f = std::nextafter(f, std::numeric_limits<float>::infinity());
  }
  return f;
}
float reference_down(double d) {
  float f = static_cast<float>(d);
  if (static_cast<double>(f) > d) {
    f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  }
  return f;
}

void expect_both(double d) {
  ASSERT_EQ(std::bit_cast<std::uint32_t>(float_up(d)),
            std::bit_cast<std::uint32_t>(reference_up(d)))
      << "float_up(" << d << ")";
  ASSERT_EQ(std::bit_cast<std::uint32_t>(float_down(d)),
            std::bit_cast<std::uint32_t>(reference_down(d)))
      << "float_down(" << d << ")";
  ASSERT_GE(static_cast<double>(float_up(d)), d);
  ASSERT_LE(static_cast<double>(float_down(d)), d);
}

// Each binary32 value f, and the binary64 values just below and above it and halfway to its
// neighbours (where round to nearest ties).
void expect_around(float f) {
  const double x = f;
  const double inf = std::numeric_limits<double>::infinity();
  for (double d : {x, std::nextafter(x, inf), std::nextafter(x, -inf),
                   0.5 * (x + static_cast<double>(float_next_up(f))),
                   0.5 * (x + static_cast<double>(float_next_down(f)))}) {
    expect_both(d);
  }
}

TEST(FloatBounds, NeighboursOfEdgeValues) {
  const float max = std::numeric_limits<float>::max();
  const float min = std::numeric_limits<float>::min();
  const float tiny = std::numeric_limits<float>::denorm_min();
  for (float f : {0.0f, -0.0f, tiny, -tiny, 2 * tiny, -2 * tiny, min, -min,
                  std::nextafter(min, 0.0f), -std::nextafter(min, 0.0f), 1.0f, -1.0f, 0.1f, -0.1f,
                  std::nextafter(max, 0.0f), -std::nextafter(max, 0.0f)}) {
    expect_around(f);
  }
  // Beyond the largest finite value: outward is infinity, inward the largest value.
  const double above = 1.5 * static_cast<double>(max);
  EXPECT_EQ(float_up(above), std::numeric_limits<float>::infinity());
  EXPECT_EQ(float_down(above), max);
  EXPECT_EQ(float_down(-above), -std::numeric_limits<float>::infinity());
  EXPECT_EQ(float_up(-above), -max);
  // Zero's neighbours step into the subnormals.
  EXPECT_EQ(float_next_up(0.0f), tiny);
  EXPECT_EQ(float_next_down(0.0f), -tiny);
  EXPECT_EQ(float_next_down(-0.0f), -tiny);
}

TEST(FloatBounds, RandomValuesOfEveryMagnitude) {
  std::mt19937_64 rng(11);
  for (int i = 0; i < 200000; ++i) {
    // Random bit patterns cover every exponent (NaNs and infinities skipped) ...
    const auto f = std::bit_cast<float>(static_cast<std::uint32_t>(rng()));
    if (std::isfinite(f)) {
      expect_around(f);
    }
    // ... and random binary64 values within binary32's range land between its values.
    const double d = std::ldexp(std::uniform_real_distribution<double>(-1.0, 1.0)(rng),
                                static_cast<int>(rng() % 280) - 150);
    expect_both(d);
  }
}

}  // namespace
}  // namespace saarcor::host
