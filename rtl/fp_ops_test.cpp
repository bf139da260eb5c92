// The SystemVerilog float operators (rtl/fp_*.sv) against fixedfloat, bit for bit, in all four
// modes: every operand pair of e4m5 (Float<4,5>), and fp24 edge pairs plus ~200K TestFloat-style
// random pairs per mode (rtl_deep_tests runs more). Every result must also arrive exactly the
// cycle model's latency after its operands (lat.add, lat.mul, lat.div, lat.cmp).
#include <gtest/gtest.h>

#include <random>

#include "Vfp_ops_e4m5_lat_1.h"
#include "Vfp_ops_e4m5_rne_flush.h"
#include "Vfp_ops_e4m5_rne_keep.h"
#include "Vfp_ops_e4m5_rtz_flush.h"
#include "Vfp_ops_e4m5_rtz_keep.h"
#include "Vfp_ops_e7m16_lat_a.h"
#include "Vfp_ops_e7m16_lat_b.h"
#include "Vfp_ops_e7m16_rne_flush.h"
#include "Vfp_ops_e7m16_rne_keep.h"
#include "Vfp_ops_e7m16_rtz_flush.h"
#include "Vfp_ops_e7m16_rtz_keep.h"
#include "rtl/fp_ops_rig.h"

namespace saarcor::rtl::testing {
namespace {

using E4M5 = ff::Float<4, 5>;
using ff::fp24;

constexpr ff::Mode kRneFlush{ff::Rounding::kNearestEven, ff::Subnormals::kFlush};
constexpr ff::Mode kRneKeep{ff::Rounding::kNearestEven, ff::Subnormals::kKeep};
constexpr ff::Mode kRtzFlush{ff::Rounding::kTowardZero, ff::Subnormals::kFlush};
constexpr ff::Mode kRtzKeep{ff::Rounding::kTowardZero, ff::Subnormals::kKeep};

// Every pair of e4m5 encodings (2^20), an idle cycle with junk operands now and then. The
// sanitizer build takes every 8th first operand.
template <class V>
void exhaustive_e4m5(ff::Mode mode, const char* what,
                     std::array<int, kOps> latency = model_latencies()) {
  OpsRig<V, E4M5> rig(mode, what, true, latency);
  std::mt19937_64 junk(7);
  const std::uint32_t step = kSanitized ? 8 : 1;
  for (std::uint32_t a = 0; a < 1024; a += step) {
    for (std::uint32_t b = 0; b < 1024; ++b) {
      rig.issue(a, b);
      if ((b & 63) == 17)
        rig.idle(static_cast<std::uint32_t>(junk()), static_cast<std::uint32_t>(junk()));
    }
  }
  rig.finish();
  EXPECT_EQ(rig.issued(), (1024u / step) * 1024u);
}

TEST(RtlFpE4M5Exhaustive, NearestEvenFlush) {
  exhaustive_e4m5<Vfp_ops_e4m5_rne_flush>(kRneFlush, "e4m5 rne flush");
}
TEST(RtlFpE4M5Exhaustive, NearestEvenKeep) {
  exhaustive_e4m5<Vfp_ops_e4m5_rne_keep>(kRneKeep, "e4m5 rne keep");
}
TEST(RtlFpE4M5Exhaustive, TowardZeroFlush) {
  exhaustive_e4m5<Vfp_ops_e4m5_rtz_flush>(kRtzFlush, "e4m5 rtz flush");
}
TEST(RtlFpE4M5Exhaustive, TowardZeroKeep) {
  exhaustive_e4m5<Vfp_ops_e4m5_rtz_keep>(kRtzKeep, "e4m5 rtz keep");
}

constexpr std::uint64_t kFp24Count = kSanitized ? 20'000 : 200'000;

TEST(RtlFp24Random, NearestEvenFlush) {
  OpsRig<Vfp_ops_e7m16_rne_flush, fp24> rig(kRneFlush, "fp24 rne flush");
  run_fp24(rig, kFp24Count, 1);
}
TEST(RtlFp24Random, NearestEvenKeep) {
  OpsRig<Vfp_ops_e7m16_rne_keep, fp24> rig(kRneKeep, "fp24 rne keep");
  run_fp24(rig, kFp24Count, 2);
}
TEST(RtlFp24Random, TowardZeroFlush) {
  OpsRig<Vfp_ops_e7m16_rtz_flush, fp24> rig(kRtzFlush, "fp24 rtz flush");
  run_fp24(rig, kFp24Count, 3);
}
TEST(RtlFp24Random, TowardZeroKeep) {
  OpsRig<Vfp_ops_e7m16_rtz_keep, fp24> rig(kRtzKeep, "fp24 rtz keep");
  run_fp24(rig, kFp24Count, 4);
}

// The latency parameters move stage boundaries (and merge them, or add output registers); the
// results stay bit-exact and arrive after exactly the configured latency. Nearest even, keep.
TEST(RtlFpOtherLatencies, Fp24ShorterPipelines) {
  OpsRig<Vfp_ops_e7m16_lat_a, fp24> rig(kRneKeep, "fp24 lat 1/2/3/2", true,
                                        op_latencies(1, 2, 3, 2));
  run_fp24(rig, kFp24Count / 4, 5);
}
TEST(RtlFpOtherLatencies, Fp24LongerPipelines) {
  OpsRig<Vfp_ops_e7m16_lat_b, fp24> rig(kRneKeep, "fp24 lat 5/4/24/3", true,
                                        op_latencies(5, 4, 24, 3));
  run_fp24(rig, kFp24Count / 4, 6);
}
TEST(RtlFpOtherLatencies, E4M5SingleStageExhaustive) {
  exhaustive_e4m5<Vfp_ops_e4m5_lat_1>(kRneKeep, "e4m5 lat 1", op_latencies(1, 1, 1, 1));
}

// One operand pair into an idle pipeline: each op's valid rises exactly its latency later (the
// first cycle whose outputs carry the result; the operands went in the cycle before edge 1).
TEST(RtlFpLatency, EachOpTakesTheCycleModelsLatency) {
  Vfp_ops_e7m16_rne_flush top;
  auto tick = [&] {
    top.clk = 0;
    top.eval();
    top.clk = 1;
    top.eval();
  };
  top.rst = 1;
  top.in_valid = 0;
  tick();
  tick();
  top.rst = 0;
  top.in_valid = 1;
  top.a = 0x3F0000;  // 1.0
  top.b = 0x400000;  // 2.0
  tick();
  top.in_valid = 0;
  std::array<int, kOps> first{};
  first.fill(-1);
  for (int cycle = 1; cycle <= 40; ++cycle) {
    const bool v[kOps] = {top.add_valid != 0, top.sub_valid != 0, top.mul_valid != 0,
                          top.div_valid != 0, top.cmp_valid != 0, top.cmp_valid != 0,
                          top.cmp_valid != 0, top.min_valid != 0, top.max_valid != 0};
    for (int op = 0; op < kOps; ++op) {
      if (!v[op]) continue;
      EXPECT_EQ(first[op], -1) << kOpNames[op] << ": a second result for one operand pair";
      first[op] = cycle;
    }
    tick();
  }
  const auto lat = model_latencies();
  for (int op = 0; op < kOps; ++op)
    EXPECT_EQ(first[op], lat[op]) << kOpNames[op];
  // The defaults the RTL was built for (units/cycle_params.cpp).
  EXPECT_EQ(lat[kAdd], 3);
  EXPECT_EQ(lat[kMul], 3);
  EXPECT_EQ(lat[kDiv], 8);
  EXPECT_EQ(lat[kLt], 1);
}

// The harness can fail: the truncating RTL checked against a nearest-even fixedfloat disagrees.
TEST(RtlFpHarness, AWrongModeIsCaught) {
  OpsRig<Vfp_ops_e7m16_rtz_flush, fp24> rig(kRneFlush, "fp24 rtz vs rne", /*report=*/false);
  OperandGen gen(ff::kFp24, 9);
  for (int i = 0; i < 2000; ++i) {
    const auto [a, b] = gen.pair();
    rig.issue(a, b);
  }
  rig.drain();
  EXPECT_GT(rig.mismatches(), 100u);
}

}  // namespace
}  // namespace saarcor::rtl::testing
