// The float operators of one DynRTC unit (DESIGN.md section 5; paper Table 2 counts them per unit):
// ff::FpUnit with inline answers for operands that are exact zeros. The datapaths feed many zeros
// (the direction step's zero translation, R' = (0,0,0), zero matrix entries) and x + (-x); the
// fixedfloat fast path sends those to the general routine. The answers here are the IEEE results
// the general routine gives for them (a + 0 = a, 0 * b = +-0, x + (-x) = +0 in both rounding
// modes, 0 / b = +-0, a / 0 = +-inf), checked bit for bit against FpUnit in units/unit_fp_test.cpp.
// Everything else goes to FpUnit unchanged; counting is the same.
#pragma once

#include <cstdint>

#include "fixedfloat/float.h"

namespace saarcor::units {

template <class F>
class UnitFp : public ff::FpUnit<F> {
  using Base = ff::FpUnit<F>;
  static constexpr std::uint32_t kSign = F::kFormat.sign_mask();
  static constexpr std::uint32_t kMag = kSign - 1u;
  static constexpr std::uint32_t kExpMax = F::kFormat.exp_field_max();
  static bool normal(std::uint32_t b) {
    const std::uint32_t e = (b >> F::kManBits) & kExpMax;
    return e != 0 && e != kExpMax;
  }

 public:
  using Base::Base;

  [[gnu::always_inline]] F add(F a, F b) const {
    const std::uint32_t ma = a.bits & kMag, mb = b.bits & kMag;
    if (mb == 0 && normal(a.bits)) return count_add(a);
    if (ma == 0 && normal(b.bits)) return count_add(b);
    if ((ma | mb) == 0) return count_add(F{a.bits & b.bits});  // -0 only for -0 + -0
    if (ma == mb && ((a.bits ^ b.bits) & kSign) != 0 && normal(a.bits))
      return count_add(F::zero());  // exact cancellation is +0 (no round-down mode)
    return Base::add(a, b);
  }
  [[gnu::always_inline]] F sub(F a, F b) const { return add(a, b.neg()); }
  [[gnu::always_inline]] F mul(F a, F b) const {
    const std::uint32_t ma = a.bits & kMag, mb = b.bits & kMag;
    if ((ma == 0 && (mb == 0 || normal(b.bits))) || (mb == 0 && normal(a.bits))) {
      if (auto* c = this->counts()) ++c->mul;
      return F{(a.bits ^ b.bits) & kSign};
    }
    return Base::mul(a, b);
  }
  [[gnu::always_inline]] F div(F a, F b) const {
    const std::uint32_t ma = a.bits & kMag, mb = b.bits & kMag;
    if (ma == 0 && normal(b.bits)) {
      if (auto* c = this->counts()) ++c->div;
      return F{(a.bits ^ b.bits) & kSign};
    }
    if (mb == 0 && normal(a.bits)) {
      if (auto* c = this->counts()) ++c->div;
      return F{((a.bits ^ b.bits) & kSign) | F::kFormat.inf_bits()};
    }
    return Base::div(a, b);
  }

 private:
  F count_add(F r) const {
    if (auto* c = this->counts()) ++c->add;
    return r;
  }
};

}  // namespace saarcor::units
