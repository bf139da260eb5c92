// Test-only: drives a Verilated fp_ops_top (rtl/fp_ops_top.sv: add, sub, mul, div, cmp, min, max
// of one format and mode side by side) with one operand pair per cycle and checks every op's
// result against fixedfloat (FpUnit in the same mode) bit for bit, and its latency: each result
// must come out exactly the op's latency after its operands went in (the cycle model's defaults,
// units/cycle_params.cpp). Idle cycles carry random junk operands, which must not produce
// results. A mismatch reports the op, the operands and both results in hex.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "fixedfloat/float.h"
#include "fixedfloat/operand_testing.h"
#include "units/cycle_params.h"

namespace saarcor::rtl::testing {

#if defined(SAARCOR_SANITIZED)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

enum Op { kAdd, kSub, kMul, kDiv, kLt, kLe, kEq, kMin, kMax, kOps };
inline constexpr const char* kOpNames[kOps] = {"add", "sub", "mul", "div", "lt",
                                               "le",  "eq",  "min", "max"};

// The latency of each op for adder, multiplier, divider and comparator latencies.
inline std::array<int, kOps> op_latencies(int add, int mul, int div, int cmp) {
  return {add, add, mul, div, cmp, cmp, cmp, cmp, cmp};
}
// The latency each op must show: the cycle model's defaults.
inline std::array<int, kOps> model_latencies() {
  const units::CycleParams p = units::prototype_params();
  return op_latencies(p.lat_add, p.lat_mul, p.lat_div, p.lat_cmp);
}

inline std::string hex(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%06x", static_cast<unsigned>(v));
  return buf;
}

template <class V, class F>
class OpsRig {
 public:
  // report = false: count mismatches without failing the test (to show the checker can fail).
  // latency: what each op must show (a model built with other LAT_* parameters).
  OpsRig(ff::Mode mode, std::string what, bool report = true,
         std::array<int, kOps> latency = model_latencies())
      : fp_(mode), what_(std::move(what)), report_(report), latency_(latency) {
    top_.rst = 1;
    top_.in_valid = 0;
    for (int i = 0; i < 3; ++i)
      tick();
    top_.rst = 0;
  }

  // One cycle with operands (a, b) going in.
  void issue(std::uint32_t a, std::uint32_t b) {
    ring_[issued_ % kRing] = {a, b, cycle_};
    ++issued_;
    top_.in_valid = 1;
    top_.a = a;
    top_.b = b;
    step();
  }
  // One cycle with nothing going in (junk on the operand ports).
  void idle(std::uint32_t junk_a, std::uint32_t junk_b) {
    top_.in_valid = 0;
    top_.a = junk_a & kMask;
    top_.b = junk_b & kMask;
    step();
  }
  // Idle cycles until every op has delivered everything.
  void drain() {
    for (int i = 0; i < 40; ++i)
      idle(0, 0);
  }
  // drain(), then every op must have delivered every result, right and on time.
  void finish() {
    drain();
    for (int op = 0; op < kOps; ++op) {
      EXPECT_EQ(seen_[op], issued_) << what_ << " " << kOpNames[op] << ": results delivered";
      EXPECT_EQ(stray_[op], 0u) << what_ << " " << kOpNames[op] << ": results without operands";
      EXPECT_EQ(mismatches_[op], 0u) << what_ << " " << kOpNames[op] << ": " << mismatches_[op]
                                     << " of " << seen_[op] << " results differ from fixedfloat";
      EXPECT_EQ(late_[op], 0u) << what_ << " " << kOpNames[op] << ": results not exactly "
                               << latency_[op] << " cycles after their operands";
    }
  }
  std::uint64_t issued() const { return issued_; }
  std::uint64_t mismatches() const {
    std::uint64_t n = 0;
    for (auto m : mismatches_)
      n += m;
    return n;
  }

  static constexpr std::uint32_t kMask = F::kFormat.bits_mask();

 private:
  struct Txn {
    std::uint32_t a = 0, b = 0;
    std::uint64_t cycle = 0;
  };
  static constexpr std::size_t kRing = 256;

  void tick() {
    top_.clk = 0;
    top_.eval();
    top_.clk = 1;
    top_.eval();
    ++cycle_;
  }
  void step() {
    tick();
    if (top_.add_valid) check(kAdd, top_.add_y);
    if (top_.sub_valid) check(kSub, top_.sub_y);
    if (top_.mul_valid) check(kMul, top_.mul_y);
    if (top_.div_valid) check(kDiv, top_.div_y);
    if (top_.cmp_valid) {
      check(kLt, top_.lt);
      check(kLe, top_.le);
      check(kEq, top_.eq);
    }
    if (top_.min_valid) check(kMin, top_.min_y);
    if (top_.max_valid) check(kMax, top_.max_y);
  }
  std::uint32_t expected(int op, std::uint32_t a, std::uint32_t b) const {
    const F x = F::from_bits(a);
    const F y = F::from_bits(b);
    switch (op) {
      case kAdd:
        return fp_.add(x, y).bits;
      case kSub:
        return fp_.sub(x, y).bits;
      case kMul:
        return fp_.mul(x, y).bits;
      case kDiv:
        return fp_.div(x, y).bits;
      case kLt:
        return fp_.lt(x, y) ? 1u : 0u;
      case kLe:
        return fp_.le(x, y) ? 1u : 0u;
      case kEq:
        return fp_.eq(x, y) ? 1u : 0u;
      case kMin:
        return fp_.min(x, y).bits;
      default:
        return fp_.max(x, y).bits;
    }
  }
  void check(int op, std::uint32_t got) {
    if (seen_[op] >= issued_) {
      ++stray_[op];
      return;
    }
    const Txn& t = ring_[seen_[op] % kRing];
    ++seen_[op];
    const auto lat = static_cast<int>(cycle_ - t.cycle);
    if (lat != latency_[op] && ++late_[op] <= 3) {
      ADD_FAILURE() << what_ << " " << kOpNames[op] << " " << hex(t.a) << " " << hex(t.b)
                    << ": result after " << lat << " cycles, the op's latency is " << latency_[op];
    }
    const std::uint32_t want = expected(op, t.a, t.b);
    if (got != want && ++mismatches_[op] <= 5 && report_) {
      ADD_FAILURE() << what_ << " " << kOpNames[op] << "(" << hex(t.a) << ", " << hex(t.b)
                    << "): fixedfloat " << hex(want) << ", RTL " << hex(got);
    }
  }

  V top_;
  ff::FpUnit<F> fp_;
  std::string what_;
  bool report_;
  std::array<int, kOps> latency_;
  std::array<Txn, kRing> ring_{};
  std::uint64_t cycle_ = 0;
  std::uint64_t issued_ = 0;
  std::array<std::uint64_t, kOps> seen_{}, stray_{}, mismatches_{}, late_{};
};

// Operands as fixedfloat's oracle tests generate them (fixedfloat/operand_testing.h).
using ff::testing::OperandGen;

// Hand-picked fp24 operands (fixedfloat/fp24_mpfr_test.cpp's edge list), both signs.
inline std::vector<std::uint32_t> fp24_edges() {
  const ff::Format f = ff::kFp24;
  const std::uint32_t one = f.one_bits();
  const std::uint32_t min_normal = 1u << 16;
  const std::uint32_t max_finite = f.max_finite_bits();
  std::vector<std::uint32_t> v = {0u,
                                  f.inf_bits(),
                                  f.nan_bits(),
                                  f.inf_bits() | 1u,
                                  max_finite,
                                  max_finite - 1u,
                                  min_normal,
                                  min_normal + 1u,
                                  min_normal - 1u,
                                  1u,
                                  0x8000u,
                                  one,
                                  one + 1u,
                                  one - 1u,
                                  one | 0x8000u,
                                  one + (1u << 16),
                                  one + (17u << 16),
                                  one - (17u << 16),
                                  one + (40u << 16),
                                  one - (40u << 16),
                                  (one - (1u << 16)) | 0xFFFFu,
                                  one - (16u << 16),
                                  0x7Du << 16,
                                  (0x7Eu << 16) | 0x8000u,
                                  0x1Fu << 16,
                                  (0x1Eu << 16) | 0xFFFFu,
                                  (0x20u << 16) | 0x5555u,
                                  0x155555u,
                                  0x2AAAAAu,
                                  0x3FFFFFu,
                                  0x008001u,
                                  0x00FFFFu,
                                  0x020000u,
                                  0x010001u,
                                  0x410000u,
                                  0x420000u};
  const std::size_t n = v.size();
  for (std::size_t i = 0; i < n; ++i)
    v.push_back(v[i] | f.sign_mask());
  return v;
}

// Every pair of edge operands, then `count` generated pairs, with an idle cycle now and then.
template <class Rig>
void run_fp24(Rig& rig, std::uint64_t count, std::uint64_t seed) {
  const auto edges = fp24_edges();
  std::mt19937_64 junk(seed ^ 0x5eedu);
  for (std::uint32_t a : edges)
    for (std::uint32_t b : edges)
      rig.issue(a, b);
  OperandGen gen(ff::kFp24, seed);
  for (std::uint64_t i = 0; i < count; ++i) {
    const auto [a, b] = gen.pair();
    rig.issue(a, b);
    if (junk() % 16 == 0)
      rig.idle(static_cast<std::uint32_t>(junk()), static_cast<std::uint32_t>(junk()));
  }
  rig.finish();
}

}  // namespace saarcor::rtl::testing
