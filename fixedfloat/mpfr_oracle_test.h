// Test-only: GNU MPFR as the oracle for the float ops (docs/fixedfloat.md), the operand
// generators shared by the fixedfloat tests, and the mismatch reporter.
//
// The oracle follows TOOLCHAIN.md gotcha 5: precision M+1, the format's exponent range (emax =
// bias+1, emin = (1-bias)+1-M in MPFR's 0.1xxx convention), mpfr_subnormalize after each op with
// its ternary value, then flush-to-zero where the mode says. In flush mode subnormal inputs are
// read as signed zero first. Encoding and decoding here use only frexp/ldexp and integers, never
// the code under test.
#pragma once

#include <gtest/gtest.h>
#include <mpfr.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "fixedfloat/float.h"
#include "fixedfloat/format.h"
#include "fixedfloat/operand_testing.h"

namespace saarcor::ff::testing {

#if defined(SAARCOR_SANITIZED)
inline constexpr std::uint64_t kCountDivisor = 100;
#else
inline constexpr std::uint64_t kCountDivisor = 1;
#endif

enum class Op { kAdd, kSub, kMul, kDiv, kSqrt, kLt, kLe, kEq, kMin, kMax };
inline constexpr Op kAllOps[] = {Op::kAdd, Op::kSub, Op::kMul, Op::kDiv, Op::kSqrt,
                                 Op::kLt,  Op::kLe,  Op::kEq,  Op::kMin, Op::kMax};
inline constexpr Op kBinaryArith[] = {Op::kAdd, Op::kSub, Op::kMul, Op::kDiv};
inline constexpr Op kCompares[] = {Op::kLt, Op::kLe, Op::kEq, Op::kMin, Op::kMax};

inline const char* op_name(Op op) {
  switch (op) {
    case Op::kAdd:
      return "add";
    case Op::kSub:
      return "sub";
    case Op::kMul:
      return "mul";
    case Op::kDiv:
      return "div";
    case Op::kSqrt:
      return "sqrt";
    case Op::kLt:
      return "lt";
    case Op::kLe:
      return "le";
    case Op::kEq:
      return "eq";
    case Op::kMin:
      return "min";
    case Op::kMax:
      return "max";
  }
  return "?";
}

inline std::string mode_name(const Mode& m) {
  return std::string(m.rounding == Rounding::kNearestEven ? "rne" : "rtz") + "/" +
         (m.subnormals == Subnormals::kFlush ? "flush" : "keep");
}

inline constexpr Mode kAllModes[] = {
    {Rounding::kNearestEven, Subnormals::kFlush},
    {Rounding::kNearestEven, Subnormals::kKeep},
    {Rounding::kTowardZero, Subnormals::kFlush},
    {Rounding::kTowardZero, Subnormals::kKeep},
};

// Independent exact value of an encoding (ldexp on integer fields).
inline double ref_value(std::uint32_t bits, const Format& f, Subnormals s) {
  const bool neg = (bits >> (f.exp_bits + f.man_bits)) & 1u;
  const std::uint32_t e = (bits >> f.man_bits) & ((1u << f.exp_bits) - 1u);
  const std::uint32_t man = bits & ((1u << f.man_bits) - 1u);
  double mag;
  if (e == (1u << f.exp_bits) - 1u) {
    if (man != 0) return std::numeric_limits<double>::quiet_NaN();
    mag = std::numeric_limits<double>::infinity();
  } else if (e == 0) {
    mag = s == Subnormals::kFlush ? 0.0 : std::ldexp(double(man), f.emin() - f.man_bits);
  } else {
    mag = std::ldexp(double(man + (1u << f.man_bits)), int(e) - f.bias() - f.man_bits);
  }
  return neg ? -mag : mag;
}

// Independent encoder of a value the format represents exactly (the oracle's results).
inline std::uint32_t ref_encode(double v, const Format& f) {
  if (std::isnan(v)) return f.nan_bits();
  const std::uint32_t sign = std::signbit(v) ? f.sign_mask() : 0u;
  const double a = std::fabs(v);
  if (std::isinf(a)) return sign | f.inf_bits();
  if (a == 0.0) return sign;
  int e2 = 0;
  std::frexp(a, &e2);
  const int ex = e2 - 1;
  if (ex < f.emin()) {
    const double q = std::ldexp(a, f.man_bits - f.emin());
    if (q != std::floor(q) || q >= double(1u << f.man_bits)) throw std::logic_error("not exact");
    return sign | static_cast<std::uint32_t>(q);
  }
  if (ex > f.emax()) throw std::logic_error("out of range");
  const double q = std::ldexp(a, f.man_bits - ex);
  if (q != std::floor(q)) throw std::logic_error("not exact");
  return sign | (static_cast<std::uint32_t>(ex + f.bias()) << f.man_bits) |
         (static_cast<std::uint32_t>(q) - (1u << f.man_bits));
}

inline bool ref_is_subnormal(std::uint32_t bits, const Format& f) {
  return ((bits >> f.man_bits) & f.exp_field_max()) == 0 && (bits & f.man_mask()) != 0;
}

// The value a comparator/mux passes on (min/max rule): flushed in flush mode.
inline std::uint32_t ref_flushed(std::uint32_t bits, const Format& f, const Mode& m) {
  if (m.subnormals == Subnormals::kFlush && ref_is_subnormal(bits, f)) return bits & f.sign_mask();
  return bits;
}

// MPFR with the format's precision and exponent range. Sets the thread's MPFR exponent range for
// its lifetime and restores it afterwards.
class MpfrOracle {
 public:
  MpfrOracle(const Format& f, const Mode& m)
      : f_(f), m_(m), old_emin_(mpfr_get_emin()), old_emax_(mpfr_get_emax()) {
    mpfr_set_emax(f.bias() + 1);
    mpfr_set_emin(f.emin() + 1 - f.man_bits);
    mpfr_inits2(f.man_bits + 1, a_, b_, r_, static_cast<mpfr_ptr>(nullptr));
    rnd_ = m.rounding == Rounding::kNearestEven ? MPFR_RNDN : MPFR_RNDZ;
  }
  ~MpfrOracle() {
    mpfr_clears(a_, b_, r_, static_cast<mpfr_ptr>(nullptr));
    mpfr_set_emin(old_emin_);
    mpfr_set_emax(old_emax_);
  }
  MpfrOracle(const MpfrOracle&) = delete;
  MpfrOracle& operator=(const MpfrOracle&) = delete;

  // Result encoding of op (compares give 0 or 1).
  std::uint32_t eval(Op op, std::uint32_t a, std::uint32_t b) {
    load(a_, a);
    load(b_, b);
    int t = 0;
    switch (op) {
      case Op::kAdd:
        t = mpfr_add(r_, a_, b_, rnd_);
        break;
      case Op::kSub:
        t = mpfr_sub(r_, a_, b_, rnd_);
        break;
      case Op::kMul:
        t = mpfr_mul(r_, a_, b_, rnd_);
        break;
      case Op::kDiv:
        t = mpfr_div(r_, a_, b_, rnd_);
        break;
      case Op::kSqrt:
        t = mpfr_sqrt(r_, a_, rnd_);
        break;
      case Op::kLt:
        return mpfr_less_p(a_, b_) ? 1u : 0u;
      case Op::kLe:
        return mpfr_lessequal_p(a_, b_) ? 1u : 0u;
      case Op::kEq:
        return mpfr_equal_p(a_, b_) ? 1u : 0u;
      case Op::kMin:
        return mpfr_less_p(b_, a_) ? ref_flushed(b, f_, m_) : ref_flushed(a, f_, m_);
      case Op::kMax:
        return mpfr_less_p(a_, b_) ? ref_flushed(b, f_, m_) : ref_flushed(a, f_, m_);
    }
    mpfr_subnormalize(r_, t, rnd_);
    const std::uint32_t r = ref_encode(mpfr_get_d(r_, MPFR_RNDN), f_);
    if (m_.subnormals == Subnormals::kFlush && ref_is_subnormal(r, f_)) return r & f_.sign_mask();
    return r;
  }

 private:
  void load(mpfr_ptr x, std::uint32_t bits) {
    const int inexact = mpfr_set_d(x, ref_value(bits, f_, m_.subnormals), MPFR_RNDN);
    if (inexact != 0) throw std::logic_error("operand not exact in MPFR");
  }

  Format f_;
  Mode m_;
  mpfr_exp_t old_emin_;
  mpfr_exp_t old_emax_;
  mpfr_rnd_t rnd_;
  mpfr_t a_, b_, r_;
};

// The code under test: the inline fast paths through FpUnit<F> and the runtime-format functions
// (used by the command-line tools) must both agree with the oracle.
template <class F>
std::uint32_t eval_unit(const FpUnit<F>& u, Op op, std::uint32_t a, std::uint32_t b) {
  const F x = F::from_bits(a);
  const F y = F::from_bits(b);
  switch (op) {
    case Op::kAdd:
      return u.add(x, y).bits;
    case Op::kSub:
      return u.sub(x, y).bits;
    case Op::kMul:
      return u.mul(x, y).bits;
    case Op::kDiv:
      return u.div(x, y).bits;
    case Op::kSqrt:
      return u.sqrt(x).bits;
    case Op::kLt:
      return u.lt(x, y) ? 1u : 0u;
    case Op::kLe:
      return u.le(x, y) ? 1u : 0u;
    case Op::kEq:
      return u.eq(x, y) ? 1u : 0u;
    case Op::kMin:
      return u.min(x, y).bits;
    case Op::kMax:
      return u.max(x, y).bits;
  }
  return 0;
}

inline std::uint32_t eval_runtime(const Format& f, const Mode& m, Op op, std::uint32_t a,
                                  std::uint32_t b) {
  switch (op) {
    case Op::kAdd:
      return op_add(a, b, f, m);
    case Op::kSub:
      return op_sub(a, b, f, m);
    case Op::kMul:
      return op_mul(a, b, f, m);
    case Op::kDiv:
      return op_div(a, b, f, m);
    case Op::kSqrt:
      return op_sqrt(a, f, m);
    case Op::kLt:
      return op_lt(a, b, f, m) ? 1u : 0u;
    case Op::kLe:
      return op_le(a, b, f, m) ? 1u : 0u;
    case Op::kEq:
      return op_eq(a, b, f, m) ? 1u : 0u;
    case Op::kMin:
      return op_min(a, b, f, m);
    case Op::kMax:
      return op_max(a, b, f, m);
  }
  return 0;
}

// Counts mismatches and reports the first few with operands as sign.exponent.mantissa groups.
class MismatchLog {
 public:
  MismatchLog(const Format& f, const Mode& m) : f_(f), m_(m) {}
  void check(const char* path, Op op, std::uint32_t a, std::uint32_t b, std::uint32_t got,
             std::uint32_t want) {
    if (got == want) return;
    if (++count_ > 8) return;
    const bool is_cmp = op == Op::kLt || op == Op::kLe || op == Op::kEq;
    std::ostringstream s;
    s << format_name(f_) << " " << mode_name(m_) << " " << path << " " << op_name(op)
      << " a=" << bit_groups(a, f_);
    if (op != Op::kSqrt) s << " b=" << bit_groups(b, f_);
    if (is_cmp) {
      s << " got=" << got << " want=" << want;
    } else {
      s << " got=" << bit_groups(got, f_) << " want=" << bit_groups(want, f_);
    }
    ADD_FAILURE() << s.str();
  }
  std::uint64_t count() const { return count_; }

 private:
  Format f_;
  Mode m_;
  std::uint64_t count_ = 0;
};

}  // namespace saarcor::ff::testing
