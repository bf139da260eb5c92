// Float<E, M>: the typed storage of one value of a parameterised format, and FpUnit, the set of
// floating-point operators a hardware unit owns (its rounding mode and its op counters).
//
// The storage is a struct around the encoding, so host float arithmetic cannot touch it by
// accident: every operation goes through an FpUnit (or the free functions with an explicit Mode).
#pragma once

#include <cstdint>

#include "fixedfloat/format.h"
#include "fixedfloat/ops.h"

namespace saarcor::ff {

template <int E, int M>
struct Float {
  static_assert(E >= 2 && E <= 8 && M >= 1 && M <= 23, "format outside the supported range");
  static constexpr Format kFormat{E, M};
  static constexpr int kExpBits = E;
  static constexpr int kManBits = M;
  static constexpr int kBits = 1 + E + M;

  std::uint32_t bits = 0;

  static constexpr Float from_bits(std::uint32_t b) { return Float{b & kFormat.bits_mask()}; }
  static Float from_double(double v, Mode m = {}) { return Float{fast::from_double<E, M>(v, m)}; }
  static Float from_float(float v, Mode m = {}) { return from_double(static_cast<double>(v), m); }
  static Float from_int(std::int64_t v, Mode m = {}) { return Float{ff::from_int(v, kFormat, m)}; }
  static constexpr Float zero() { return Float{0}; }
  static constexpr Float one() { return Float{kFormat.one_bits()}; }
  static constexpr Float infinity() { return Float{kFormat.inf_bits()}; }
  static constexpr Float nan() { return Float{kFormat.nan_bits()}; }
  static constexpr Float max_finite() { return Float{kFormat.max_finite_bits()}; }

  // Exact; in flush mode (the default) a subnormal encoding reads as +-0.
  double to_double(Subnormals s = Subnormals::kFlush) const { return fast::decode<E, M>(bits, s); }
  float to_float(Subnormals s = Subnormals::kFlush) const {
    return static_cast<float>(to_double(s));
  }
  std::int32_t to_int(Mode m = {}) const { return ff::to_int(bits, kFormat, m); }

  constexpr bool sign() const { return (bits & kFormat.sign_mask()) != 0; }
  constexpr Float neg() const { return Float{bits ^ kFormat.sign_mask()}; }
  constexpr Float abs() const { return Float{bits & ~kFormat.sign_mask()}; }
  bool is_nan() const { return ff::is_nan(bits, kFormat); }
  bool is_inf() const { return ff::is_inf(bits, kFormat); }
  bool is_zero() const { return ff::is_zero(bits, kFormat); }

  friend constexpr bool operator==(const Float&, const Float&) = default;  // bitwise
};

using fp24 = Float<7, 16>;
using fp32 = Float<8, 23>;

// Float ops counted per hardware unit (Table 2 of the paper lists adders, multipliers, dividers
// and comparators per unit). Subtraction counts as an add.
struct OpCounts {
  std::uint64_t add = 0;
  std::uint64_t mul = 0;
  std::uint64_t div = 0;
  std::uint64_t sqrt = 0;
  std::uint64_t cmp = 0;

  OpCounts& operator+=(const OpCounts& o) {
    add += o.add;
    mul += o.mul;
    div += o.div;
    sqrt += o.sqrt;
    cmp += o.cmp;
    return *this;
  }
  std::uint64_t total() const { return add + mul + div + sqrt + cmp; }
  friend bool operator==(const OpCounts&, const OpCounts&) = default;
};

// The operators of one unit: its rounding mode and, when enabled, its counters. Without counters
// (nullptr) counting costs one predictable branch.
template <class F>
class FpUnit {
 public:
  explicit FpUnit(Mode mode = {}, OpCounts* counts = nullptr) : rounder_(mode), counts_(counts) {}

  F add(F a, F b) const {
    if (counts_) ++counts_->add;
    return F{fast::add<F::kExpBits, F::kManBits>(a.bits, b.bits, rounder_)};
  }
  F sub(F a, F b) const {
    if (counts_) ++counts_->add;
    return F{fast::sub<F::kExpBits, F::kManBits>(a.bits, b.bits, rounder_)};
  }
  F mul(F a, F b) const {
    if (counts_) ++counts_->mul;
    return F{fast::mul<F::kExpBits, F::kManBits>(a.bits, b.bits, rounder_)};
  }
  F div(F a, F b) const {
    if (counts_) ++counts_->div;
    return F{fast::div<F::kExpBits, F::kManBits>(a.bits, b.bits, rounder_)};
  }
  F sqrt(F a) const {
    if (counts_) ++counts_->sqrt;
    return F{fast::sqrt<F::kExpBits, F::kManBits>(a.bits, rounder_)};
  }
  bool lt(F a, F b) const {
    if (counts_) ++counts_->cmp;
    return fast::lt<F::kExpBits, F::kManBits>(a.bits, b.bits, rounder_.mode);
  }
  bool le(F a, F b) const {
    if (counts_) ++counts_->cmp;
    return fast::le<F::kExpBits, F::kManBits>(a.bits, b.bits, rounder_.mode);
  }
  bool eq(F a, F b) const {
    if (counts_) ++counts_->cmp;
    return fast::eq<F::kExpBits, F::kManBits>(a.bits, b.bits, rounder_.mode);
  }
  F min(F a, F b) const {
    if (counts_) ++counts_->cmp;
    return F{fast::min<F::kExpBits, F::kManBits>(a.bits, b.bits, rounder_.mode)};
  }
  F max(F a, F b) const {
    if (counts_) ++counts_->cmp;
    return F{fast::max<F::kExpBits, F::kManBits>(a.bits, b.bits, rounder_.mode)};
  }
  F from_double(double v) const {
    return F{fast::from_double<F::kExpBits, F::kManBits>(v, rounder_.mode)};
  }
  F from_int(std::int64_t v) const { return F{ff::from_int(v, F::kFormat, rounder_.mode)}; }
  double to_double(F a) const {
    return fast::decode<F::kExpBits, F::kManBits>(a.bits, rounder_.mode.subnormals);
  }

  const Mode& mode() const { return rounder_.mode; }
  OpCounts* counts() const { return counts_; }

 private:
  fast::Rounder<F::kExpBits, F::kManBits> rounder_;
  OpCounts* counts_;
};

}  // namespace saarcor::ff
