// UnitFp against ff::FpUnit: the same bits and the same counts on every operand class; RawFp
// (with and without the zero shortcuts) and division by a Divisor give the same bits.
#include "units/unit_fp.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace saarcor::units {
namespace {

template <class F>
void check_same(ff::Mode mode) {
  ff::OpCounts ca, cb;
  const ff::FpUnit<F> ref(mode, &ca);
  const UnitFp<F> fast(mode, &cb);
  const RawFp<F> raw(mode);
  const RawFp<F, false> direct(mode);
  const ff::FpUnit<F> plain(mode);  // uncounted reference for the uncounted units
  const std::uint32_t sign = F::kFormat.sign_mask();
  std::vector<std::uint32_t> v = {0u,
                                  sign,
                                  1u,  // smallest subnormal
                                  sign | 1u,
                                  F::one().bits,
                                  F::one().bits | sign,
                                  F::one().bits + 1u,
                                  F::max_finite().bits,
                                  F::infinity().bits,
                                  F::infinity().bits | sign,
                                  F::nan().bits,
                                  1u << F::kManBits,  // smallest normal
                                  (1u << F::kManBits) | sign};
  std::mt19937 rng(12345);
  for (int i = 0; i < 200; ++i)
    v.push_back(rng() & F::kFormat.bits_mask());
  for (std::uint32_t a : v)
    for (std::uint32_t b : v) {
      const F x = F::from_bits(a), y = F::from_bits(b);
      ASSERT_EQ(fast.add(x, y).bits, ref.add(x, y).bits) << a << " + " << b;
      ASSERT_EQ(fast.sub(x, y).bits, ref.sub(x, y).bits) << a << " - " << b;
      ASSERT_EQ(fast.mul(x, y).bits, ref.mul(x, y).bits) << a << " * " << b;
      ASSERT_EQ(fast.div(x, y).bits, ref.div(x, y).bits) << a << " / " << b;
      ASSERT_EQ(fast.add(x, x.neg()).bits, ref.add(x, x.neg()).bits) << a << " - itself";
      const F want_div = plain.div(x, y);
      ASSERT_EQ(raw.div(x, RawFp<F>::divisor(y)).bits, want_div.bits) << a << " / r " << b;
      ASSERT_EQ(raw.add(x, y).bits, plain.add(x, y).bits) << a << " + " << b;
      ASSERT_EQ(raw.mul(x, y).bits, plain.mul(x, y).bits) << a << " * " << b;
      ASSERT_EQ(raw.div(x, y).bits, want_div.bits) << a << " / " << b;
      ASSERT_EQ(raw.lt(x, y), ff::op_lt(a, b, F::kFormat, mode)) << a << " < " << b;
      ASSERT_EQ(raw.min(x, y).bits, ff::op_min(a, b, F::kFormat, mode)) << a << " min " << b;
      ASSERT_EQ(direct.add(x, y).bits, plain.add(x, y).bits) << a << " + " << b;
      ASSERT_EQ(direct.sub(x, y).bits, plain.sub(x, y).bits) << a << " - " << b;
      ASSERT_EQ(direct.mul(x, y).bits, plain.mul(x, y).bits) << a << " * " << b;
      ASSERT_EQ(direct.div(x, y).bits, want_div.bits) << a << " / " << b;
      ASSERT_EQ(direct.div(x, RawFp<F>::divisor(y)).bits, want_div.bits) << a << " / r " << b;
    }
  EXPECT_EQ(ca, cb);
}

TEST(UnitFp, SameBitsAndCountsAsFpUnit) {
  for (ff::Rounding r : {ff::Rounding::kNearestEven, ff::Rounding::kTowardZero})
    for (ff::Subnormals s : {ff::Subnormals::kFlush, ff::Subnormals::kKeep}) {
      check_same<ff::fp24>({r, s});
      check_same<ff::Float<7, 10>>({r, s});
      check_same<ff::fp32>({r, s});
    }
}

}  // namespace
}  // namespace saarcor::units
