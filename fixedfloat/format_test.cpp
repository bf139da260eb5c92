// Conversions, the binary32 self-check, packing and op counters (docs/fixedfloat.md and
// docs/memory-image.md): Float<8,23> in kIeeeMode against the machine's binary32, fp24 -> binary32
// -> fp24 and fp24 -> binary64 over all 2^24 encodings, binary64 and integer -> format against
// MPFR, pack_row/unpack_row, OpCounts, and the small helpers (parse_format, bit_groups).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <random>

#include "fixedfloat/mpfr_oracle_test.h"
#include "fixedfloat/pack.h"

namespace saarcor::ff::testing {
namespace {

// --- Float<8,23> against the host's binary32 -------------------------------------------------

float host_float(std::uint32_t b) {
  return std::bit_cast<float>(b);
}
std::uint32_t host_bits(float f) {
  return std::bit_cast<std::uint32_t>(f);
}

// The same expression in host binary32 (round to nearest even, subnormals kept).
std::uint32_t host_eval(Op op, std::uint32_t a, std::uint32_t b) {
  const float x = host_float(a);
  const float y = host_float(b);
  switch (op) {
    case Op::kAdd:
      return host_bits(x + y);
    case Op::kSub:
      return host_bits(x - y);
    case Op::kMul:
      return host_bits(x * y);
    case Op::kDiv:
      return host_bits(x / y);
    case Op::kSqrt:
      return host_bits(std::sqrt(x));
    case Op::kLt:
      return x < y ? 1u : 0u;
    case Op::kLe:
      return x <= y ? 1u : 0u;
    case Op::kEq:
      return x == y ? 1u : 0u;
    case Op::kMin:
      return y < x ? b : a;
    case Op::kMax:
      return x < y ? b : a;
  }
  return 0;
}

class Binary32 : public ::testing::TestWithParam<Op> {};

TEST_P(Binary32, TenMillionPairsBitIdenticalToHostFloat) {
  const Op op = GetParam();
  const Format f = fp32::kFormat;
  const FpUnit<fp32> unit(kIeeeMode);
  MismatchLog log(f, kIeeeMode);
  OperandGen gen(f, 3000 + static_cast<int>(op));
  const std::uint64_t pairs = 10'000'000 / kCountDivisor;
  std::uint64_t nan_results = 0;
  for (std::uint64_t i = 0; i < pairs; ++i) {
    auto [a, b] = gen.pair();
    if (op == Op::kSqrt && i % 4 != 0) a &= ~f.sign_mask();  // mostly roots of positive values
    std::uint32_t want = host_eval(op, a, b);
    const bool is_arith =
        op == Op::kAdd || op == Op::kSub || op == Op::kMul || op == Op::kDiv || op == Op::kSqrt;
    // The model has one NaN (no payloads): any host NaN stands for it.
    if (is_arith && std::isnan(host_float(want))) {
      want = f.nan_bits();
      ++nan_results;
    }
    log.check("inline", op, a, b, eval_unit(unit, op, a, b), want);
    if (i % 8 == 0) log.check("runtime", op, a, b, eval_runtime(f, kIeeeMode, op, a, b), want);
  }
  EXPECT_EQ(log.count(), 0u);
  EXPECT_LT(nan_results, pairs / 4);  // the operands are not mostly NaN
}

std::string op_param_name(const ::testing::TestParamInfo<Op>& info) {
  return op_name(info.param);
}

INSTANTIATE_TEST_SUITE_P(Ops, Binary32, ::testing::ValuesIn(kAllOps), op_param_name);

// --- conversions ---------------------------------------------------------------------------

TEST(Fp24Conversions, AllEncodingsRoundTripThroughBinary32AndBinary64) {
  const Format f = fp24::kFormat;
  std::uint64_t bad32 = 0;
  std::uint64_t bad64 = 0;
  for (Subnormals s : {Subnormals::kFlush, Subnormals::kKeep}) {
    const Mode m{Rounding::kNearestEven, s};
    for (std::uint32_t a = 0; a < (1u << 24); ++a) {
      const fp24 x = fp24::from_bits(a);
      const double ref = ref_value(a, f, s);
      const double d = x.to_double(s);
      const bool nan = std::isnan(ref);
      if (!(nan ? std::isnan(d)
                : std::bit_cast<std::uint64_t>(d) == std::bit_cast<std::uint64_t>(ref))) {
        if (++bad64 <= 5) ADD_FAILURE() << "to_double " << bit_groups(a, f);
      }
      // fp24 -> binary32 -> fp24 gives back the encoding (flushed in flush mode; one NaN).
      const std::uint32_t want = nan ? f.nan_bits() : ref_flushed(a, f, m);
      const std::uint32_t back = fp24::from_float(x.to_float(s), m).bits;
      if (back != want || (!nan && static_cast<double>(x.to_float(s)) != d)) {
        if (++bad32 <= 5) ADD_FAILURE() << "binary32 round trip " << bit_groups(a, f);
      }
    }
  }
  EXPECT_EQ(bad32, 0u);
  EXPECT_EQ(bad64, 0u);
}

// binary64 -> format rounds once: against MPFR on random doubles around the format's range.
TEST(Conversions, FromDoubleAgreesWithMpfr) {
  std::mt19937_64 rng(4000);
  for (const Format& f : {fp24::kFormat, Float<4, 5>::kFormat}) {
    for (const Mode& m : kAllModes) {
      MpfrOracle oracle(f, m);
      mpfr_t r;
      mpfr_init2(r, f.man_bits + 1);
      const mpfr_rnd_t rnd = m.rounding == Rounding::kNearestEven ? MPFR_RNDN : MPFR_RNDZ;
      std::uint64_t bad = 0;
      for (int i = 0; i < 200'000 / static_cast<int>(kCountDivisor); ++i) {
        // Random binary64 bit patterns with exponents a little beyond the format's range.
        const int e = static_cast<int>(rng() % (2 * f.bias() + 2 * f.man_bits + 10)) - f.bias() -
                      f.man_bits - 5;
        std::uint64_t u =
            (rng() & 0x800F'FFFF'FFFF'FFFFull) | (static_cast<std::uint64_t>(1023 + e) << 52);
        if (i % 4 == 0) u &= ~((std::uint64_t{1} << (52 - f.man_bits - 1)) - 1);  // ties
        const double v = std::bit_cast<double>(u);
        int t = mpfr_set_d(r, v, rnd);
        mpfr_subnormalize(r, t, rnd);
        std::uint32_t want = ref_encode(mpfr_get_d(r, MPFR_RNDN), f);
        if (m.subnormals == Subnormals::kFlush && ref_is_subnormal(want, f)) want &= f.sign_mask();
        const std::uint32_t got = from_double(v, f, m);
        const std::uint32_t got_inline = f == fp24::kFormat ? fp24::from_double(v, m).bits : got;
        if (got != want || got_inline != want) {
          if (++bad <= 5)
            ADD_FAILURE() << format_name(f) << " " << mode_name(m) << " from_double(" << v
                          << ") got " << bit_groups(got, f) << " want " << bit_groups(want, f);
        }
      }
      mpfr_clear(r);
      EXPECT_EQ(bad, 0u);
    }
  }
}

TEST(Conversions, FromIntAgreesWithMpfr) {
  std::mt19937_64 rng(4100);
  const Format f = fp24::kFormat;
  for (const Mode& m : kAllModes) {
    MpfrOracle oracle(f, m);
    mpfr_t r;
    mpfr_init2(r, f.man_bits + 1);
    const mpfr_rnd_t rnd = m.rounding == Rounding::kNearestEven ? MPFR_RNDN : MPFR_RNDZ;
    std::vector<std::int64_t> values = {0,
                                        1,
                                        -1,
                                        65535,
                                        65536,
                                        131071,
                                        131072,
                                        131073,  // a tie at 17 significant bits + 1
                                        131075,
                                        -131075,
                                        std::numeric_limits<std::int64_t>::max(),
                                        std::numeric_limits<std::int64_t>::min()};
    for (int i = 0; i < 100'000; ++i) {
      const int bits = static_cast<int>(rng() % 63);
      values.push_back(static_cast<std::int64_t>(rng() >> (63 - bits)) * (rng() % 2 ? 1 : -1));
    }
    for (std::int64_t v : values) {
      int t = mpfr_set_sj(r, v, rnd);
      t = mpfr_subnormalize(r, t, rnd);
      const std::uint32_t want = ref_encode(mpfr_get_d(r, MPFR_RNDN), f);
      ASSERT_EQ(from_int(v, f, m), want) << v << " " << mode_name(m);
      ASSERT_EQ(fp24::from_int(v, m).bits, want) << v;
    }
    mpfr_clear(r);
  }
}

TEST(Conversions, ToIntTruncatesAndSaturates) {
  const Mode m{};
  EXPECT_EQ(fp24::from_double(2.75).to_int(), 2);
  EXPECT_EQ(fp24::from_double(-2.75).to_int(), -2);
  EXPECT_EQ(fp24::from_double(0.5).to_int(), 0);
  EXPECT_EQ(fp24::from_int(131072).to_int(), 131072);
  EXPECT_EQ(fp24::from_double(1e12).to_int(), std::numeric_limits<std::int32_t>::max());
  EXPECT_EQ(fp24::from_double(-1e12).to_int(), std::numeric_limits<std::int32_t>::min());
  EXPECT_EQ(fp24::infinity().to_int(), std::numeric_limits<std::int32_t>::max());
  EXPECT_EQ(fp24::infinity().neg().to_int(), std::numeric_limits<std::int32_t>::min());
  EXPECT_EQ(fp24::nan().to_int(), 0);
  // Every fp24 integer up to 2^17 converts both ways exactly.
  for (std::int32_t i = -(1 << 17); i <= (1 << 17); ++i) {
    ASSERT_EQ(fp24::from_int(i, m).to_int(m), i);
  }
  // Int conversion of every encoding: truncation of the exact value, saturated.
  for (std::uint32_t a = 0; a < (1u << 24); a += 7) {
    const double v = ref_value(a, fp24::kFormat, Subnormals::kFlush);
    std::int32_t want = 0;
    if (!std::isnan(v)) {
      const double t = std::trunc(v);
      want = t >= 2147483647.0    ? std::numeric_limits<std::int32_t>::max()
             : t <= -2147483648.0 ? std::numeric_limits<std::int32_t>::min()
                                  : static_cast<std::int32_t>(t);
    }
    ASSERT_EQ(fp24::from_bits(a).to_int(m), want) << bit_groups(a, fp24::kFormat);
  }
}

// --- packing --------------------------------------------------------------------------------

TEST(Pack, FourFp24FillThreeWordsInBitStreamOrder) {
  const Format f = fp24::kFormat;
  EXPECT_EQ(row_words(f), 3);
  EXPECT_EQ(row_words(fp32::kFormat), 4);
  const auto w = pack_row({0x111111u, 0x222222u, 0x333333u, 0x444444u}, f);
  EXPECT_EQ(w[0], 0x22111111u);
  EXPECT_EQ(w[1], 0x33332222u);
  EXPECT_EQ(w[2], 0x44444433u);
  EXPECT_EQ(w[3], 0u);
  // Bits beyond the format are dropped, not smeared into neighbours.
  const auto m = pack_row({0xFF000000u, 0u, 0u, 0u}, f);
  EXPECT_EQ(m[0] | m[1] | m[2], 0u);
}

TEST(Pack, RandomRowsRoundTrip) {
  std::mt19937 rng(4200);
  for (const Format& f : {fp24::kFormat, fp32::kFormat, Float<4, 5>::kFormat}) {
    for (int i = 0; i < 100'000; ++i) {
      std::array<std::uint32_t, 4> v;
      for (auto& x : v)
        x = static_cast<std::uint32_t>(rng()) & f.bits_mask();
      const auto w = pack_row(v, f);
      for (int k = row_words(f); k < 4; ++k)
        ASSERT_EQ(w[k], 0u);
      ASSERT_EQ(unpack_row(w.data(), f), v) << format_name(f);
    }
  }
}

// --- op counters ----------------------------------------------------------------------------

TEST(OpCounts, EachOpCountsInItsClass) {
  OpCounts counts;
  const FpUnit<fp24> unit(Mode{}, &counts);
  const fp24 a = fp24::from_double(1.5);
  const fp24 b = fp24::from_double(2.25);
  unit.add(a, b);
  unit.sub(a, b);
  unit.sub(a, b);
  unit.mul(a, b);
  unit.div(a, b);
  unit.div(a, b);
  unit.div(a, b);
  unit.sqrt(a);
  unit.lt(a, b);
  unit.le(a, b);
  unit.eq(a, b);
  unit.min(a, b);
  unit.max(a, b);
  unit.to_double(a);  // conversions are wiring, not float units: not counted
  unit.from_double(1.0);
  EXPECT_EQ(counts, (OpCounts{3, 1, 3, 1, 5}));
  EXPECT_EQ(counts.total(), 13u);
  OpCounts sum{1, 2, 3, 4, 5};
  sum += counts;
  EXPECT_EQ(sum, (OpCounts{4, 3, 6, 5, 10}));
  // Without counters the same ops compute the same results.
  const FpUnit<fp24> quiet;
  EXPECT_EQ(quiet.div(a, b), unit.div(a, b));
  EXPECT_EQ(quiet.counts(), nullptr);
}

// --- helpers --------------------------------------------------------------------------------

TEST(Format, ParseAndName) {
  Format f;
  ASSERT_TRUE(parse_format("e7m16", &f));
  EXPECT_EQ(f, kFp24);
  ASSERT_TRUE(parse_format("fp32", &f));
  EXPECT_EQ(f, kFp32);
  ASSERT_TRUE(parse_format("e4m5", &f));
  EXPECT_EQ(format_name(f), "e4m5");
  EXPECT_FALSE(parse_format("e9m16", &f));   // exponent too wide
  EXPECT_FALSE(parse_format("e7m24", &f));   // mantissa too wide
  EXPECT_FALSE(parse_format("e7m16x", &f));  // trailing junk
  EXPECT_FALSE(parse_format("", &f));
  EXPECT_FALSE(parse_format("m16e7", &f));
  EXPECT_EQ(kFp24.bias(), 63);
  EXPECT_EQ(kFp24.one_bits(), 0x3F0000u);
  EXPECT_EQ(kFp24.max_finite_bits(), 0x7EFFFFu);
}

TEST(Format, BitGroups) {
  EXPECT_EQ(bit_groups(0x3F0000u, kFp24), "0.0111111.0000000000000000");
  EXPECT_EQ(bit_groups(0xFF0001u, kFp24), "1.1111111.0000000000000001");
}

}  // namespace
}  // namespace saarcor::ff::testing
