// fp24 (Float<7,16>, the paper's 24-bit format) against GNU MPFR (docs/fixedfloat.md):
// seeded random operand pairs (10 million per op in the default mode, 1 million per op in each
// other mode), a hand-written edge list in every mode, and sqrt over all 2^24 encodings in every
// mode. Each op/mode is its own test case so ctest spreads them over the cores.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "fixedfloat/mpfr_oracle_test.h"

namespace saarcor::ff::testing {
namespace {

const Format kF = fp24::kFormat;

std::uint64_t run_random(Op op, const Mode& mode, std::uint64_t pairs, std::uint64_t seed) {
  MpfrOracle oracle(kF, mode);
  const FpUnit<fp24> unit(mode);
  MismatchLog log(kF, mode);
  OperandGen gen(kF, seed);
  for (std::uint64_t i = 0; i < pairs; ++i) {
    const auto [a, b] = gen.pair();
    const std::uint32_t want = oracle.eval(op, a, b);
    log.check("inline", op, a, b, eval_unit(unit, op, a, b), want);
    log.check("runtime", op, a, b, eval_runtime(kF, mode, op, a, b), want);
  }
  return log.count();
}

class Fp24RandomDefault : public ::testing::TestWithParam<Op> {};

TEST_P(Fp24RandomDefault, TenMillionPairsAgreeWithMpfr) {
  const std::uint64_t pairs = 10'000'000 / kCountDivisor;
  EXPECT_EQ(run_random(GetParam(), Mode{}, pairs, 1000 + static_cast<int>(GetParam())), 0u);
}

std::string op_param_name(const ::testing::TestParamInfo<Op>& info) {
  return op_name(info.param);
}

INSTANTIATE_TEST_SUITE_P(Ops, Fp24RandomDefault, ::testing::ValuesIn(kAllOps), op_param_name);

class Fp24RandomOtherModes : public ::testing::TestWithParam<int> {};

TEST_P(Fp24RandomOtherModes, OneMillionPairsPerOpAgreeWithMpfr) {
  const Mode mode = kAllModes[GetParam()];
  const std::uint64_t pairs = 1'000'000 / kCountDivisor;
  for (Op op : kAllOps) {
    EXPECT_EQ(run_random(op, mode, pairs, 2000 + 16 * GetParam() + static_cast<int>(op)), 0u)
        << op_name(op);
  }
}

std::string mode_param_name(const ::testing::TestParamInfo<int>& info) {
  std::string s = mode_name(kAllModes[info.param]);
  s[3] = '_';
  return s;
}

INSTANTIATE_TEST_SUITE_P(Modes, Fp24RandomOtherModes, ::testing::Range(1, 4), mode_param_name);

// Hand-written edge operands, each paired with every other in every op and mode.
std::vector<std::uint32_t> edge_list() {
  const std::uint32_t one = kF.one_bits();    // 0x3f0000
  const std::uint32_t min_normal = 1u << 16;  // 2^-62
  const std::uint32_t max_finite = kF.max_finite_bits();
  std::vector<std::uint32_t> v = {
      0u,                            // +0
      kF.inf_bits(),                 // +inf
      kF.nan_bits(),                 // NaN
      kF.inf_bits() | 1u,            // NaN with another payload
      max_finite,                    // largest
      max_finite - 1u,               //
      min_normal,                    // smallest normal
      min_normal + 1u,               //
      min_normal - 1u,               // largest subnormal
      1u,                            // smallest subnormal
      0x8000u,                       // a subnormal with one bit: half the smallest normal
      one,                           // 1.0
      one + 1u,                      // 1 + ulp
      one - 1u,                      // 1 - ulp/2 (below the binade)
      one | 0x8000u,                 // 1.5
      (one + (1u << 16)),            // 2.0
      (one + (17u << 16)),           // 2^17: more than the significand width above 1
      (one - (17u << 16)),           // 2^-17: more than the significand width below 1
      (one + (40u << 16)),           // far apart exponents
      (one - (40u << 16)),           //
      (one - (1u << 16)) | 0xFFFFu,  // 2 - ulp, halved: 1 - ulp/2
      (one - (16u << 16)),           // 2^-16: ulp(1), tie partner of 1 at 2^-17
      (0x7Du << 16),                 // 2^62: squares overflow
      (0x7Eu << 16) | 0x8000u,       // 1.5 * 2^63: just above the overflow threshold when doubled
      (0x1Fu << 16),                 // 2^-32: squares land right on the smallest normal
      (0x1Eu << 16) | 0xFFFFu,       // just below 2^-32: squares just underflow
      (0x20u << 16) | 0x5555u,       //
      0x155555u,                     // a mantissa 0101...
      0x2AAAAAu & kF.bits_mask(),
  };
  const std::size_t n = v.size();
  for (std::size_t i = 0; i < n; ++i)
    v.push_back(v[i] | kF.sign_mask());
  return v;
}

class Fp24Edges : public ::testing::TestWithParam<int> {};

TEST_P(Fp24Edges, EveryPairOfEdgeOperandsAgreesWithMpfr) {
  const Mode mode = kAllModes[GetParam()];
  MpfrOracle oracle(kF, mode);
  const FpUnit<fp24> unit(mode);
  MismatchLog log(kF, mode);
  const auto edges = edge_list();
  for (std::uint32_t a : edges) {
    for (std::uint32_t b : edges) {
      for (Op op : kAllOps) {
        const std::uint32_t want = oracle.eval(op, a, b);
        log.check("inline", op, a, b, eval_unit(unit, op, a, b), want);
        log.check("runtime", op, a, b, eval_runtime(kF, mode, op, a, b), want);
      }
    }
  }
  EXPECT_EQ(log.count(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Modes, Fp24Edges, ::testing::Range(0, 4), mode_param_name);

// A few results that pin down the edge cases by hand (independent of MPFR).
TEST(Fp24Known, EdgeResultsByHand) {
  const FpUnit<fp24> rne;
  const FpUnit<fp24> rtz(Mode{Rounding::kTowardZero, Subnormals::kFlush});
  const FpUnit<fp24> keep(kIeeeMode);
  const fp24 one = fp24::one();
  const fp24 max = fp24::max_finite();
  EXPECT_EQ(one.bits, 0x3F0000u);
  EXPECT_EQ(rne.add(max, max).bits, 0x7F0000u);  // overflow: +inf
  EXPECT_EQ(rtz.add(max, max).bits, max.bits);   // truncation saturates
  EXPECT_EQ(rne.div(one, fp24::zero()).bits, 0x7F0000u);
  EXPECT_EQ(rne.div(one.neg(), fp24::zero()).bits, 0xFF0000u);
  EXPECT_TRUE(rne.div(fp24::zero(), fp24::zero()).is_nan());
  EXPECT_TRUE(rne.sub(fp24::infinity(), fp24::infinity()).is_nan());
  EXPECT_TRUE(rne.sqrt(one.neg()).is_nan());
  // 1 + 2^-17 is a tie: even (1.0) wins; 1 + 3*2^-17 rounds up to 1 + 2^-15... via even.
  const fp24 half_ulp = fp24::from_bits(0x3F0000u - (17u << 16));
  EXPECT_EQ(rne.add(one, half_ulp).bits, one.bits);
  EXPECT_EQ(rne.add(fp24::from_bits(0x3F0001u), half_ulp).bits, 0x3F0002u);
  // Smallest normal * 0.5: subnormal, flushed (sign kept) or kept.
  const fp24 min_normal = fp24::from_bits(0x010000u);
  const fp24 half = fp24::from_bits(0x3E0000u);
  EXPECT_EQ(rne.mul(min_normal, half).bits, 0u);
  EXPECT_EQ(rne.mul(min_normal.neg(), half).bits, 0x800000u);
  EXPECT_EQ(keep.mul(min_normal, half).bits, 0x008000u);
  // Subnormal inputs read as zero in flush mode.
  EXPECT_TRUE(rne.eq(fp24::from_bits(0x000001u), fp24::zero()));
  EXPECT_FALSE(keep.eq(fp24::from_bits(0x000001u), fp24::zero()));
  // -0 == +0, NaN compares false, min/max are a comparator and a multiplexer.
  EXPECT_TRUE(rne.eq(fp24::zero().neg(), fp24::zero()));
  EXPECT_FALSE(rne.eq(fp24::nan(), fp24::nan()));
  EXPECT_EQ(rne.min(fp24::zero(), fp24::zero().neg()).bits, 0u);
  EXPECT_EQ(rne.min(one, fp24::nan()).bits, one.bits);
  EXPECT_TRUE(rne.min(fp24::nan(), one).is_nan());
}

// sqrt over all 2^24 encodings in every mode, in two halves per mode (positive and negative).
class Fp24SqrtExhaustive : public ::testing::TestWithParam<std::tuple<int, int>> {};

TEST_P(Fp24SqrtExhaustive, AllEncodingsAgreeWithMpfr) {
  const Mode mode = kAllModes[std::get<0>(GetParam())];
  const std::uint32_t sign = std::get<1>(GetParam()) ? kF.sign_mask() : 0u;
  MpfrOracle oracle(kF, mode);
  const FpUnit<fp24> unit(mode);
  MismatchLog log(kF, mode);
  const std::uint32_t step = kCountDivisor > 1 ? 97 : 1;
  std::uint64_t checked = 0;
  for (std::uint32_t m = 0; m < (1u << 23); m += step) {
    const std::uint32_t a = sign | m;
    const std::uint32_t want = oracle.eval(Op::kSqrt, a, 0);
    log.check("inline", Op::kSqrt, a, 0, eval_unit(unit, Op::kSqrt, a, 0), want);
    log.check("runtime", Op::kSqrt, a, 0, eval_runtime(kF, mode, Op::kSqrt, a, 0), want);
    ++checked;
  }
  EXPECT_EQ(log.count(), 0u);
  EXPECT_EQ(checked, ((1u << 23) + step - 1) / step);
}

std::string sqrt_param_name(const ::testing::TestParamInfo<std::tuple<int, int>>& info) {
  std::string s = mode_name(kAllModes[std::get<0>(info.param)]);
  s[3] = '_';
  return s + (std::get<1>(info.param) ? "_negative" : "_positive");
}

INSTANTIATE_TEST_SUITE_P(Modes, Fp24SqrtExhaustive,
                         ::testing::Combine(::testing::Range(0, 4), ::testing::Range(0, 2)),
                         sqrt_param_name);

}  // namespace
}  // namespace saarcor::ff::testing
