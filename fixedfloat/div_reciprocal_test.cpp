// fast::div_reciprocal (division by a precomputed binary64 reciprocal, fixedfloat/ops.h) against
// the general op_div (itself checked against MPFR in fp24_mpfr_test.cpp and
// small_exhaustive_test.cpp): every significand pair of a 10-bit-mantissa format at several
// exponent offsets (the midpoint-distance argument depends only on the significands and on where
// the quotient lands in the range), 10 million random fp24 pairs, random pairs of the widest
// formats (e7m23, e8m23: the smallest margin, 2^-52 against 2^-49), and an edge list, in both
// rounding modes and both subnormal modes.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "fixedfloat/float.h"
#include "fixedfloat/mpfr_oracle_test.h"

namespace saarcor::ff::testing {
namespace {

template <int E, int M>
std::uint32_t via_reciprocal(std::uint32_t a, std::uint32_t b, const fast::Rounder<E, M>& r) {
  // The caller computes the reciprocal only for a normal divisor; anything else must not be used.
  const double inv = fast::is_normal<E, M>(b) ? fast::reciprocal<E, M>(b) : 12345.0;
  return fast::div_reciprocal<E, M>(a, b, inv, r);
}

const Mode kModes[] = {{Rounding::kNearestEven, Subnormals::kFlush},
                       {Rounding::kNearestEven, Subnormals::kKeep},
                       {Rounding::kTowardZero, Subnormals::kFlush},
                       {Rounding::kTowardZero, Subnormals::kKeep}};

// Counts mismatches and reports the first few.
template <int E, int M>
struct Checker {
  static constexpr Format kF{E, M};
  Mode mode;
  fast::Rounder<E, M> r{mode};
  std::uint64_t bad = 0;
  void check(std::uint32_t a, std::uint32_t b) {
    const std::uint32_t got = via_reciprocal<E, M>(a, b, r);
    const std::uint32_t want = op_div(a, b, kF, mode);
    if (got == want) return;
    if (++bad <= 5)
      ADD_FAILURE() << format_name(kF) << " " << bit_groups(a, kF) << " / " << bit_groups(b, kF)
                    << ": " << bit_groups(got, kF) << ", want " << bit_groups(want, kF);
  }
};

TEST(DivReciprocal, EverySignificandPairOfE7M10) {
  constexpr int E = 7, M = 10;
  const int step = static_cast<int>(kCountDivisor);  // fewer pairs in the sanitizer build
  for (const Mode& mode : kModes) {
    Checker<E, M> c{mode};
    // Exponent fields of dividend and divisor: quotients near 1, at the top of the range
    // (overflow to infinity) and at the bottom (the smallest normal, the flush threshold).
    const std::uint32_t fields[][2] = {{63, 63}, {63, 62}, {126, 63}, {125, 62}, {2, 63}, {1, 63}};
    for (const auto& f : fields)
      for (std::uint32_t ma = 0; ma < (1u << M); ma += static_cast<std::uint32_t>(step))
        for (std::uint32_t mb = 0; mb < (1u << M); ++mb) {
          const std::uint32_t a = (f[0] << M) | ma, b = (f[1] << M) | mb;
          c.check(a, b);
          c.check(a | (1u << (E + M)), b);
        }
    EXPECT_EQ(c.bad, 0u);
  }
}

template <int E, int M>
std::uint64_t random_pairs(const Mode& mode, std::uint64_t n, std::uint64_t seed) {
  Checker<E, M> c{mode};
  OperandGen gen(Format{E, M}, seed);
  std::mt19937_64 rng(seed);
  for (std::uint64_t i = 0; i < n; ++i) {
    const auto [a, b] = gen.pair();
    c.check(a, b);
    // Normal operands with quotients inside the range, the case the fast path accepts.
    constexpr std::uint32_t kMan = (1u << M) - 1u;
    constexpr auto kBias = static_cast<std::uint32_t>((1 << (E - 1)) - 1);
    const std::uint64_t u = rng();
    const auto fa = static_cast<std::uint32_t>(kBias - 8u + (u >> 60));
    const auto fb = static_cast<std::uint32_t>(kBias - 8u + ((u >> 56) & 15u));
    c.check((fa << M) | (static_cast<std::uint32_t>(u) & kMan) |
                (static_cast<std::uint32_t>(u >> 55) & 1u) << (E + M),
            (fb << M) | (static_cast<std::uint32_t>(u >> 24) & kMan));
  }
  return c.bad;
}

TEST(DivReciprocal, TenMillionRandomFp24PairsNearestEven) {
  EXPECT_EQ((random_pairs<7, 16>(Mode{}, 10'000'000 / kCountDivisor, 77)), 0u);
}

TEST(DivReciprocal, RandomPairsEveryModeAndWideFormats) {
  const std::uint64_t n = 1'000'000 / kCountDivisor;
  for (const Mode& mode : kModes) {
    EXPECT_EQ((random_pairs<7, 16>(mode, n, 78)), 0u);
    EXPECT_EQ((random_pairs<7, 23>(mode, n, 79)), 0u);
    EXPECT_EQ((random_pairs<8, 23>(mode, n, 80)), 0u);
    EXPECT_EQ((random_pairs<7, 10>(mode, n, 81)), 0u);
  }
}

TEST(DivReciprocal, EdgeOperands) {
  constexpr int E = 7, M = 16;
  const Format f = fp24::kFormat;
  const std::uint32_t sign = f.sign_mask();
  const std::vector<std::uint32_t> v = {0u,
                                        1u,
                                        (1u << M) - 1u,
                                        1u << M,
                                        (1u << M) + 1u,
                                        f.one_bits() - 1u,
                                        f.one_bits(),
                                        f.one_bits() + 1u,
                                        f.one_bits() | f.man_mask(),
                                        f.max_finite_bits() - 1u,
                                        f.max_finite_bits(),
                                        f.inf_bits(),
                                        f.nan_bits()};
  for (const Mode& mode : kModes) {
    Checker<E, M> c{mode};
    for (std::uint32_t a : v)
      for (std::uint32_t b : v)
        for (std::uint32_t s : {0u, sign}) {
          c.check(a | s, b);
          c.check(a, b | s);
        }
    EXPECT_EQ(c.bad, 0u);
  }
}

// The check can fail: a reciprocal rounded the wrong way is caught.
TEST(DivReciprocal, CheckerSeesAWrongReciprocal) {
  constexpr int E = 7, M = 16;
  const fast::Rounder<E, M> r{Mode{}};
  int differ = 0;
  std::mt19937 rng(5);
  for (int i = 0; i < 10000; ++i) {
    const std::uint32_t a = fp24::one().bits | (rng() & 0xFFFFu);
    const std::uint32_t b = fp24::one().bits | (rng() & 0xFFFFu);
    const double off = fast::reciprocal<E, M>(b) * (1.0 + 0x1p-20);
    if (fast::div_reciprocal<E, M>(a, b, off, r) != op_div(a, b, fp24::kFormat, Mode{})) ++differ;
  }
  EXPECT_GT(differ, 0);
}

}  // namespace
}  // namespace saarcor::ff::testing
