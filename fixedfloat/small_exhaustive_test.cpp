// Exhaustive agreement of Float<4,5> with GNU MPFR: every operand pair for add, sub, mul, div and
// the compares (lt, le, eq, min, max), every operand for sqrt, in all four modes (
// docs/fixedfloat.md). A 10-bit format is small enough to try everything, and it has every kind of
// case fp24 has: ties, carries into the exponent, overflow, gradual underflow, flushing.
#include <gtest/gtest.h>

#include "fixedfloat/mpfr_oracle_test.h"

namespace saarcor::ff::testing {
namespace {

using F45 = Float<4, 5>;
constexpr std::uint32_t kEncodings = 1u << F45::kBits;
// The sanitizer build checks every a against a stride of b values.
constexpr std::uint32_t kStrideB = kCountDivisor > 1 ? 17 : 1;

class SmallExhaustive : public ::testing::TestWithParam<int> {};

void run_ops(const Mode& mode, const Op* ops, std::size_t n_ops) {
  const Format f = F45::kFormat;
  MpfrOracle oracle(f, mode);
  const FpUnit<F45> unit(mode);
  MismatchLog log(f, mode);
  std::uint64_t checked = 0;
  for (std::uint32_t a = 0; a < kEncodings; ++a) {
    for (std::uint32_t b = 0; b < kEncodings; b += kStrideB) {
      for (std::size_t i = 0; i < n_ops; ++i) {
        const Op op = ops[i];
        const std::uint32_t want = oracle.eval(op, a, b);
        log.check("inline", op, a, b, eval_unit(unit, op, a, b), want);
        log.check("runtime", op, a, b, eval_runtime(f, mode, op, a, b), want);
        ++checked;
      }
    }
  }
  EXPECT_EQ(log.count(), 0u) << "mismatches in " << checked << " checks";
  EXPECT_EQ(checked, std::uint64_t{kEncodings} * ((kEncodings + kStrideB - 1) / kStrideB) * n_ops);
}

TEST_P(SmallExhaustive, ArithmeticAgreesWithMpfr) {
  run_ops(kAllModes[GetParam()], kBinaryArith, std::size(kBinaryArith));
}

TEST_P(SmallExhaustive, ComparesAgreeWithMpfr) {
  run_ops(kAllModes[GetParam()], kCompares, std::size(kCompares));
}

TEST_P(SmallExhaustive, SqrtAgreesWithMpfr) {
  const Mode mode = kAllModes[GetParam()];
  const Format f = F45::kFormat;
  MpfrOracle oracle(f, mode);
  const FpUnit<F45> unit(mode);
  MismatchLog log(f, mode);
  for (std::uint32_t a = 0; a < kEncodings; ++a) {
    const std::uint32_t want = oracle.eval(Op::kSqrt, a, 0);
    log.check("inline", Op::kSqrt, a, 0, eval_unit(unit, Op::kSqrt, a, 0), want);
    log.check("runtime", Op::kSqrt, a, 0, eval_runtime(f, mode, Op::kSqrt, a, 0), want);
  }
  EXPECT_EQ(log.count(), 0u);
}

// The oracle itself must see the cases that make the test meaningful: check a few results that
// are known by hand, so a broken oracle cannot agree with a broken implementation.
TEST(SmallOracle, KnownResults) {
  const Format f = F45::kFormat;  // bias 7, emin -6, smallest subnormal 2^-11
  const std::uint32_t one = 7u << 5;
  const std::uint32_t min_normal = 1u << 5;
  const std::uint32_t max_finite = f.max_finite_bits();  // 1.11111 * 2^7 = 252
  {
    MpfrOracle o(f, kAllModes[0]);                                      // rne/flush
    EXPECT_EQ(o.eval(Op::kAdd, one, one), 8u << 5);                     // 1 + 1 = 2
    EXPECT_EQ(o.eval(Op::kAdd, max_finite, max_finite), f.inf_bits());  // overflow
    EXPECT_EQ(o.eval(Op::kMul, min_normal, 6u << 5), 0u);               // 2^-7: flushed
    EXPECT_EQ(o.eval(Op::kDiv, one, 0u), f.inf_bits());                 // 1/0 = inf
    EXPECT_EQ(o.eval(Op::kDiv, 0u, 0u), f.nan_bits());                  // 0/0 = NaN
    EXPECT_EQ(o.eval(Op::kSqrt, f.sign_mask(), 0u), f.sign_mask());     // sqrt(-0) = -0
    EXPECT_EQ(o.eval(Op::kLt, f.nan_bits(), one), 0u);                  // NaN compares false
    // 1 + 2^-6 is exactly halfway between 1 and 1 + 2^-5: ties to even gives 1.
    EXPECT_EQ(o.eval(Op::kAdd, one, 1u << 5), one);
  }
  {
    MpfrOracle o(f, kAllModes[1]);                          // rne/keep
    EXPECT_EQ(o.eval(Op::kMul, min_normal, 6u << 5), 16u);  // 2^-7 = 16 * 2^-11, subnormal
  }
  {
    MpfrOracle o(f, kAllModes[2]);                                    // rtz/flush
    EXPECT_EQ(o.eval(Op::kAdd, max_finite, max_finite), max_finite);  // truncation saturates
    EXPECT_EQ(o.eval(Op::kAdd, one, 1u << 5), one);
    EXPECT_EQ(o.eval(Op::kSub, one, 1u), one);  // the subnormal 2^-11 reads as zero
  }
  {
    MpfrOracle o(f, kAllModes[3]);                          // rtz/keep
    EXPECT_EQ(o.eval(Op::kSub, one, 1u), (6u << 5) | 31u);  // 1 - 2^-11 truncates to 1 - 2^-6
  }
}

// The harness must be able to fail: a unit in the wrong mode disagrees with the oracle on a large
// share of the pairs (truncation vs nearest-even, keep vs flush).
TEST(SmallOracle, HarnessDetectsAWrongMode) {
  const Format f = F45::kFormat;
  MpfrOracle oracle(f, kAllModes[0]);  // rne/flush
  const FpUnit<F45> truncating(kAllModes[2]);
  const FpUnit<F45> keeping(kAllModes[1]);
  std::uint64_t rounding_diffs = 0;
  std::uint64_t subnormal_diffs = 0;
  for (std::uint32_t a = 0; a < kEncodings; ++a) {
    for (std::uint32_t b = 0; b < kEncodings; b += 7) {
      const std::uint32_t want = oracle.eval(Op::kMul, a, b);
      rounding_diffs += eval_unit(truncating, Op::kMul, a, b) != want;
      subnormal_diffs += eval_unit(keeping, Op::kMul, a, b) != want;
    }
  }
  EXPECT_GT(rounding_diffs, 10'000u);
  EXPECT_GT(subnormal_diffs, 1'000u);
}

std::string mode_param_name(const ::testing::TestParamInfo<int>& info) {
  std::string s = mode_name(kAllModes[info.param]);
  s[3] = '_';
  return s;
}

INSTANTIATE_TEST_SUITE_P(Modes, SmallExhaustive, ::testing::Range(0, 4), mode_param_name);

}  // namespace
}  // namespace saarcor::ff::testing
