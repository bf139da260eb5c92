// The float operators of one DynRTC unit (docs/cycle-model.md; paper Table 2 counts them per unit):
// the ff::fast paths of ff::FpUnit with inline answers for operands that are exact zeros. The
// datapaths feed many zeros (the direction step's zero translation, R' = (0,0,0), zero matrix
// entries) and x + (-x); the fixedfloat fast path sends those to the general routine. The answers
// here are the IEEE results the general routine gives for them (a + 0 = a, 0 * b = +-0,
// x + (-x) = +0 in both rounding modes, 0 / b = +-0, a / 0 = +-inf), checked bit for bit against
// FpUnit in units/unit_fp_test.cpp. Everything else goes to the fast paths unchanged.
//
// RawFp has no counters: the thread program counts each datapath step's ops in bulk where it issues
// the step (the counts per step are fixed by the datapath, D30), so the hot path does no counter
// updates. UnitFp counts per op, as FpUnit does (tests, the RGS's few ops).
#pragma once

#include <cstdint>

#include "fixedfloat/float.h"

namespace saarcor::units {

// A divisor with its binary64 reciprocal (ff::fast::div_reciprocal): the traversal unit divides by
// the same direction component D[axis] for a whole level (d = (split - O) / D, the clip's
// (plane - O) / D), so 1/|D| is computed once when the ray enters the level's space. The quotient
// is the correctly rounded one either way (fixedfloat/div_reciprocal_test.cpp).
template <class F>
struct Divisor {
  F value{};
  double inv = 0.0;  // 1/|value| when value is normal; not read otherwise
};

// kZeroShortcuts = false leaves out the inline zero answers of add, sub, mul and div: the fast
// paths give the same results for zero operands (they send them to the general path), so this
// only trades the shortcut tests for slower zero cases; right for the traversal unit, whose
// operands are rarely zero.
template <class F, bool kZeroShortcuts = true>
class RawFp {
  static constexpr int E = F::kExpBits;
  static constexpr int M = F::kManBits;
  static constexpr std::uint32_t kSign = F::kFormat.sign_mask();
  static constexpr std::uint32_t kMag = kSign - 1u;
  static constexpr std::uint32_t kExpMax = F::kFormat.exp_field_max();
  static bool normal(std::uint32_t b) {
    const std::uint32_t e = (b >> F::kManBits) & kExpMax;
    return e != 0 && e != kExpMax;
  }

 public:
  explicit RawFp(ff::Mode mode = {}) : rounder_(mode) {}

  [[gnu::always_inline]] F add(F a, F b) const {
    if constexpr (!kZeroShortcuts) return F{ff::fast::add<E, M>(a.bits, b.bits, rounder_)};
    const std::uint32_t ma = a.bits & kMag, mb = b.bits & kMag;
    if (mb == 0 && normal(a.bits)) return a;
    if (ma == 0 && normal(b.bits)) return b;
    if ((ma | mb) == 0) return F{a.bits & b.bits};  // -0 only for -0 + -0
    if (ma == mb && ((a.bits ^ b.bits) & kSign) != 0 && normal(a.bits))
      return F::zero();  // exact cancellation is +0 (no round-down mode)
    return F{ff::fast::add<E, M>(a.bits, b.bits, rounder_)};
  }
  [[gnu::always_inline]] F sub(F a, F b) const {
    if constexpr (!kZeroShortcuts) return F{ff::fast::sub<E, M>(a.bits, b.bits, rounder_)};
    return add(a, b.neg());
  }
  [[gnu::always_inline]] F mul(F a, F b) const {
    if constexpr (!kZeroShortcuts) return F{ff::fast::mul<E, M>(a.bits, b.bits, rounder_)};
    const std::uint32_t ma = a.bits & kMag, mb = b.bits & kMag;
    if ((ma == 0 && (mb == 0 || normal(b.bits))) || (mb == 0 && normal(a.bits)))
      return F{(a.bits ^ b.bits) & kSign};
    return F{ff::fast::mul<E, M>(a.bits, b.bits, rounder_)};
  }
  [[gnu::always_inline]] F div(F a, F b) const {
    if constexpr (!kZeroShortcuts) return F{ff::fast::div<E, M>(a.bits, b.bits, rounder_)};
    const std::uint32_t ma = a.bits & kMag, mb = b.bits & kMag;
    if (ma == 0 && normal(b.bits)) return F{(a.bits ^ b.bits) & kSign};
    if (mb == 0 && normal(a.bits)) return F{((a.bits ^ b.bits) & kSign) | F::kFormat.inf_bits()};
    return F{ff::fast::div<E, M>(a.bits, b.bits, rounder_)};
  }
  [[gnu::always_inline]] F div(F a, const Divisor<F>& d) const {
    const F b = d.value;
    if constexpr (!kZeroShortcuts)
      return F{ff::fast::div_reciprocal<E, M>(a.bits, b.bits, d.inv, rounder_)};
    const std::uint32_t ma = a.bits & kMag, mb = b.bits & kMag;
    if (ma == 0 && normal(b.bits)) return F{(a.bits ^ b.bits) & kSign};
    if (mb == 0 && normal(a.bits)) return F{((a.bits ^ b.bits) & kSign) | F::kFormat.inf_bits()};
    return F{ff::fast::div_reciprocal<E, M>(a.bits, b.bits, d.inv, rounder_)};
  }
  static Divisor<F> divisor(F b) {
    return {b, normal(b.bits) ? ff::fast::reciprocal<E, M>(b.bits) : 0.0};
  }
  F sqrt(F a) const { return F{ff::fast::sqrt<E, M>(a.bits, rounder_)}; }
  bool lt(F a, F b) const { return ff::fast::lt<E, M>(a.bits, b.bits, rounder_.mode); }
  bool le(F a, F b) const { return ff::fast::le<E, M>(a.bits, b.bits, rounder_.mode); }
  bool eq(F a, F b) const { return ff::fast::eq<E, M>(a.bits, b.bits, rounder_.mode); }
  F min(F a, F b) const { return F{ff::fast::min<E, M>(a.bits, b.bits, rounder_.mode)}; }
  F max(F a, F b) const { return F{ff::fast::max<E, M>(a.bits, b.bits, rounder_.mode)}; }
  F from_double(double v) const { return F{ff::fast::from_double<E, M>(v, rounder_.mode)}; }
  F from_int(std::int64_t v) const { return F{ff::from_int(v, F::kFormat, rounder_.mode)}; }
  double to_double(F a) const { return ff::fast::decode<E, M>(a.bits, rounder_.mode.subnormals); }

  const ff::Mode& mode() const { return rounder_.mode; }

 private:
  ff::fast::Rounder<E, M> rounder_;
};

template <class F>
class UnitFp : public RawFp<F> {
  using Raw = RawFp<F>;

 public:
  explicit UnitFp(ff::Mode mode = {}, ff::OpCounts* counts = nullptr)
      : Raw(mode), counts_(counts) {}

  F add(F a, F b) const {
    count(&ff::OpCounts::add);
    return Raw::add(a, b);
  }
  F sub(F a, F b) const {
    count(&ff::OpCounts::add);
    return Raw::sub(a, b);
  }
  F mul(F a, F b) const {
    count(&ff::OpCounts::mul);
    return Raw::mul(a, b);
  }
  F div(F a, F b) const {
    count(&ff::OpCounts::div);
    return Raw::div(a, b);
  }
  F div(F a, const Divisor<F>& b) const {
    count(&ff::OpCounts::div);
    return Raw::div(a, b);
  }
  F sqrt(F a) const {
    count(&ff::OpCounts::sqrt);
    return Raw::sqrt(a);
  }
  bool lt(F a, F b) const {
    count(&ff::OpCounts::cmp);
    return Raw::lt(a, b);
  }
  bool le(F a, F b) const {
    count(&ff::OpCounts::cmp);
    return Raw::le(a, b);
  }
  bool eq(F a, F b) const {
    count(&ff::OpCounts::cmp);
    return Raw::eq(a, b);
  }
  F min(F a, F b) const {
    count(&ff::OpCounts::cmp);
    return Raw::min(a, b);
  }
  F max(F a, F b) const {
    count(&ff::OpCounts::cmp);
    return Raw::max(a, b);
  }

  ff::OpCounts* counts() const { return counts_; }

 private:
  void count(std::uint64_t ff::OpCounts::*field) const {
    if (counts_) ++(counts_->*field);
  }
  ff::OpCounts* counts_;
};

}  // namespace saarcor::units
