// The traversal, clip and transformation steps of units/datapath.h on binary64 values, one lane
// or two lanes at a time (SSE2 vectors): the host-speed paths of the thread program. Each accepts a
// result only where it equals the encoding path's bit for bit and otherwise tells the caller to
// redo the lane on encodings (units/datapath.h, the paper's op order), so the model's results
// never depend on them. Only the fast datapath policy (units/fast_datapath.h) calls them; the
// reference instantiation (units/reference_model.cpp) is built without them, and
// testbench/reference_datapath_test.cpp compares both frames step by step.
#pragma once

#include <cmath>
#include <cstring>

#include "units/datapath.h"
#include "units/lane_values.h"

namespace saarcor::units {

// ---- the traversal unit in binary64 (nearest-even only) ----------------------------------------
// The same steps on the exact binary64 values of the encodings, for speed: the segment bounds live
// as binary64 (a value of F converts exactly both ways), O[axis] is decoded and 1/D[axis] computed
// once per level. Each op's binary64 result is rounded to F's precision in binary64
// (round_to_format): for + and - that is double rounding, innocuous as 53 >= 2(M+1)+2 (Figueroa
// 1995, as in fixedfloat/ops.h), and x * (1/D) rounds like x / D (the midpoint-distance argument of
// ff::fast::div_reciprocal). A result is accepted only when it is zero or normal and finite in F,
// where both ways agree bit for bit; otherwise (overflow, underflow, inf or NaN operands, a divisor
// that is not normal, truncation: 1/D is then NaN) the caller redoes the lane with the encoding
// path (units/datapath.h). Compares and the max/min multiplexers are binary64 compares of the exact
// values (NaN never reaches them on this path). Tested against the encoding path in
// units/datapath_test.cpp.

// Rounds v to F's precision (nearest-even) in binary64; clears ok unless the result is zero or
// normal and finite in F.
template <class F>
inline double round_to_format(double v, bool& ok) {
  constexpr int kShift = 52 - F::kManBits;
  constexpr std::uint64_t kLowBits = (std::uint64_t{1} << kShift) - 1u;
  constexpr std::uint64_t kInfMag = std::uint64_t{0x7FF} << 53;  // magnitude bits, shifted by one
  constexpr std::uint64_t kMinMag = static_cast<std::uint64_t>(1023 + F::kFormat.emin()) << 53;
  constexpr std::uint64_t kSpanMag =
      static_cast<std::uint64_t>(F::kFormat.emax() - F::kFormat.emin() + 1) << 53;
  const auto u = std::bit_cast<std::uint64_t>(v);
  const std::uint64_t r = (u + (kLowBits >> 1) + ((u >> kShift) & 1u)) & ~kLowBits;
  const std::uint64_t mag = r << 1;
  ok &= ((u << 1) < kInfMag) & ((mag - kMinMag < kSpanMag) | (mag == 0));
  return std::bit_cast<double>(r);
}

// 1/D for the binary64 path: NaN unless D is normal and the mode rounds to nearest-even.
template <class F, class Fp>
inline double traversal_reciprocal(const Fp& fp, F d) {
  constexpr std::uint32_t kExpMax = F::kFormat.exp_field_max();
  const std::uint32_t e = (d.bits >> F::kManBits) & kExpMax;
  if (e == 0 || e == kExpMax || fp.mode().rounding != ff::Rounding::kNearestEven)
    return std::numeric_limits<double>::quiet_NaN();
  return 1.0 / fp.to_double(d);
}

// x is +-0 or normal (what decode_pair takes).
template <class F>
[[gnu::always_inline]] inline bool normal_or_zero(F x) {
  constexpr std::uint32_t kExpMax = F::kFormat.exp_field_max();
  const std::uint32_t e = (x.bits >> F::kManBits) & kExpMax;
  return (e - 1u < kExpMax - 1u) | ((x.bits & (F::kFormat.sign_mask() - 1u)) == 0);
}

// The encoding of a value that round_to_format accepted (zero or normal).
template <class F>
[[gnu::always_inline]] inline F encoding_of(double v) {
  constexpr int kShift = 52 - F::kManBits;
  constexpr std::uint64_t kRebias = static_cast<std::uint64_t>(1023 - F::kFormat.bias()) << 52;
  const auto u = std::bit_cast<std::uint64_t>(v);
  const std::uint64_t mag = u & ~(std::uint64_t{1} << 63);
  const auto sign = static_cast<std::uint32_t>(u >> 63) << (F::kExpBits + F::kManBits);
  return F{sign | (mag == 0 ? 0u : static_cast<std::uint32_t>((mag - kRebias) >> kShift))};
}

// transform_step on values, for operands whose exponents keep every intermediate in range. Let
// the nonzero linear matrix entries, the nonzero vector components and the nonzero translations
// have unbiased exponents in [lm, hm], [lv, hv], [lt, ht] (all normal). Then every product and
// translation, and so every sum, is a multiple of 2^L with L = min(lm + lv, lt) - M, and rounding
// at M+1 significant bits keeps that (a value below 2^(L+M+1) is already exact), so a nonzero
// intermediate is at least 2^L; and every first-level operand is below 2^B with
// B = max(hm + hv + 2, ht + 1), the sums below 2^(B+2). With L >= emin and B + 2 <= emax nothing
// leaves F's normal range except to an exact zero, and each op is its binary64 result rounded
// to F's precision without range checks: products are exact in binary64 (significands of at
// most 24 bits) and rounded once, sums rounded twice, innocuously (53 >= 2(M+1)+2); zeros give
// the IEEE signed zeros the encoding path gives.
struct ExponentRange {
  int lo = 1 << 20;  // empty: the bounds below then hold trivially
  int hi = -(1 << 20);
  bool normal = true;  // no subnormal, inf or NaN among the entries
  template <class F>
  void include(F x) {
    constexpr std::uint32_t kExpMax = F::kFormat.exp_field_max();
    if ((x.bits & (F::kFormat.sign_mask() - 1u)) == 0) return;
    const std::uint32_t e = (x.bits >> F::kManBits) & kExpMax;
    normal &= e != 0 && e != kExpMax;
    const int u = static_cast<int>(e) - F::kFormat.bias();
    lo = u < lo ? u : lo;
    hi = u > hi ? u : hi;
  }
};

// Rounds v to F's precision (nearest-even) in binary64, for results known to be zero or normal.
template <class F>
[[gnu::always_inline]] inline double round_in_range(double v) {
  constexpr int kShift = 52 - F::kManBits;
  constexpr std::uint64_t kLowBits = (std::uint64_t{1} << kShift) - 1u;
  const auto u = std::bit_cast<std::uint64_t>(v);
  return std::bit_cast<double>((u + (kLowBits >> 1) + ((u >> kShift) & 1u)) & ~kLowBits);
}

// The matrix entries as values, with the exponent ranges of the linear part and the translation.
template <class F>
struct MatrixValues {
  std::array<std::array<double, 4>, 3> m;  // every entry set by matrix_values
  ExponentRange linear, translation;
  bool nearest = true;  // the caller clears it for truncation (then no step is decided here)
};
template <class F>
inline MatrixValues<F> matrix_values(const Mat34<F>& m, ff::Subnormals s) {
  MatrixValues<F> v;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) {
      v.m[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)] = value_of(m[r][c], s);
      if (c < 3)
        v.linear.include(m[r][c]);
      else
        v.translation.include(m[r][c]);
    }
  return v;
}

// true when the exponent condition above holds for this vector, every operand is normal or zero
// and the mode is nearest-even: then transform_step64 and transform_pair64 decide the step.
template <class F>
[[gnu::always_inline]] inline bool transform_decides(const MatrixValues<F>& mv, const Vec3<F>& v,
                                                     bool translate) {
  ExponentRange rv;
  rv.include(v[0]);
  rv.include(v[1]);
  rv.include(v[2]);
  const ExponentRange t = translate ? mv.translation : ExponentRange{};
  const int low = std::min(mv.linear.lo + rv.lo, t.lo) - F::kManBits;
  const int high = std::max(mv.linear.hi + rv.hi + 2, t.hi + 1);
  return mv.nearest & mv.linear.normal & t.normal & rv.normal & (low >= F::kFormat.emin()) &
         (high + 2 <= F::kFormat.emax());
}

// false: transform_decides does not hold; use transform_step.
template <class F>
[[gnu::always_inline]] inline bool transform_step64(const MatrixValues<F>& mv, const Vec3<F>& v,
                                                    bool translate, Vec3<F>& out) {
  if (!transform_decides<F>(mv, v, translate)) return false;
  // Normal or zero operands: value_of's subnormal mode does not matter.
  const std::array<double, 3> x = {value_of(v[0], ff::Subnormals::kFlush),
                                   value_of(v[1], ff::Subnormals::kFlush),
                                   value_of(v[2], ff::Subnormals::kFlush)};
  for (std::size_t k = 0; k < 3; ++k) {
    const auto& m = mv.m[k];
    const double tk = translate ? m[3] : 0.0;
    const double a = round_in_range<F>(m[0] * x[0]);
    const double b = round_in_range<F>(m[1] * x[1]);
    const double c = round_in_range<F>(m[2] * x[2]);
    out[static_cast<int>(k)] =
        encoding_of<F>(round_in_range<F>(round_in_range<F>(a + b) + round_in_range<F>(c + tk)));
  }
  return true;
}

// ---- two lanes at a time ----------------------------------------------------------------------
// The same value paths on pairs of lanes (GCC/Clang vector extensions: one SSE2 register per pair
// on x86-64). Every lane's op sequence is unchanged, so each lane's results are those of the
// scalar functions above; the rounding to F's precision is the same integer arithmetic on the
// binary64 bit patterns, lane by lane.
// round_in_range on both lanes.
template <class F>
[[gnu::always_inline]] inline V2d round_in_range2(V2d v) {
  constexpr int kShift = 52 - F::kManBits;
  constexpr std::uint64_t kLowBits = (std::uint64_t{1} << kShift) - 1u;
  const auto u = std::bit_cast<V2u>(v);
  return std::bit_cast<V2d>((u + (kLowBits >> 1) + ((u >> kShift) & 1u)) & ~kLowBits);
}

// The exact values of two encodings that are zero or normal (value_of; the subnormal mode does not
// matter for them). The magnitude is decoded as if normal: a zero then lands on 2^-bias, which no
// normal value of F equals, and is cleared there.
template <class F>
[[gnu::always_inline]] inline V2d decode_pair(std::uint32_t a, std::uint32_t b) {
  constexpr int kShift = 52 - F::kManBits;
  constexpr std::uint64_t kRebias = static_cast<std::uint64_t>(1023 - F::kFormat.bias()) << 52;
  constexpr std::uint64_t kMag = F::kFormat.sign_mask() - 1u;
  constexpr double kZeroImage = std::bit_cast<double>(kRebias);
  const V2u e = {a, b};
  const V2u sign = (e >> (F::kExpBits + F::kManBits)) << 63;
  V2u mag = ((e & kMag) << kShift) + kRebias;
  mag &= ~std::bit_cast<V2u>(std::bit_cast<V2d>(mag) == kZeroImage);
  return std::bit_cast<V2d>(mag | sign);
}

// encoding_of on both lanes (values that are zero or normal in F and on its grid).
template <class F>
[[gnu::always_inline]] inline V2u encode_pair(V2d v) {
  constexpr int kShift = 52 - F::kManBits;
  constexpr std::uint64_t kRebias = static_cast<std::uint64_t>(1023 - F::kFormat.bias()) << 52;
  const auto u = std::bit_cast<V2u>(v);
  const V2u mag = u & ~(std::uint64_t{1} << 63);
  const auto zero = std::bit_cast<V2u>(v == 0.0);
  return (((mag - kRebias) >> kShift) & ~zero) | ((u >> 63) << (F::kExpBits + F::kManBits));
}
template <class F>
[[gnu::always_inline]] inline Vec3<F> lane_of(const V2u (&e)[3], int lane) {
  return {F{static_cast<std::uint32_t>(e[0][lane])}, F{static_cast<std::uint32_t>(e[1][lane])},
          F{static_cast<std::uint32_t>(e[2][lane])}};
}

// One row of transform_step64 on two lanes: m0·x0 + m1·x1 + (m2·x2 + t), each op rounded to F's
// precision; a lane's row entries and translation may differ from the other lane's.
template <class F>
[[gnu::always_inline]] inline V2u row_pair64(V2d m0, V2d m1, V2d m2, V2d t, const V2d (&x)[3]) {
  const V2d a = round_in_range2<F>(m0 * x[0]);
  const V2d b = round_in_range2<F>(m1 * x[1]);
  const V2d c = round_in_range2<F>(m2 * x[2]);
  return encode_pair<F>(round_in_range2<F>(round_in_range2<F>(a + b) + round_in_range2<F>(c + t)));
}

// transform_step64's arithmetic for two vectors x (components as pairs); each lane must satisfy
// transform_decides (lanes that do not give meaningless results, to be discarded).
template <class F>
[[gnu::always_inline]] inline void transform_pair64(const MatrixValues<F>& mv, const V2d (&x)[3],
                                                    bool translate, V2u (&out)[3]) {
  for (std::size_t k = 0; k < 3; ++k) {
    const auto& m = mv.m[k];
    const double tk = translate ? m[3] : 0.0;
    out[k] = row_pair64<F>(V2d{m[0], m[0]}, V2d{m[1], m[1]}, V2d{m[2], m[2]}, V2d{tk, tk}, x);
  }
}

// A vector as dot_step64 reads it: its components' exact values (meaningful when its range says
// normal or zero) and its exponent range. Decoded once, it serves every dot it takes part in (the
// RGS's normal meets each light's shadow direction).
struct DotOperand {
  V2d xy{};  // components 0 and 1
  double z = 0.0;
  ExponentRange range;
};
template <class F>
[[gnu::always_inline]] inline DotOperand dot_operand(const Vec3<F>& a, const ExponentRange& range) {
  DotOperand o;
  o.xy = decode_pair<F>(a[0].bits, a[1].bits);
  o.z = decode_pair<F>(a[2].bits, a[2].bits)[0];
  o.range = range;
  return o;
}
template <class F>
[[gnu::always_inline]] inline DotOperand dot_operand(const Vec3<F>& a) {
  ExponentRange r;
  r.include(a[0]);
  r.include(a[1]);
  r.include(a[2]);
  return dot_operand<F>(a, r);
}
// dot_step on values. dot_step(a, b) is row 0 of a direction step with the linear part (a; 0; 0),
// so transform_decides' condition with a's exponent range for the matrix's and no translation
// (L = la + lb - M >= emin, B = ha + hb + 2 <= emax - 2, every operand normal or zero) makes each
// op its binary64 result rounded once to F's precision, as in transform_step64. dot_step64_decides
// is that condition on two exponent ranges (a range containing several vectors' ranges decides
// for each of them: a direction step's rows); dot_step64 returns false where it is not decided
// (use dot_step), on decoded operands or on vectors (rb: b's exponent range, when known).
template <class F>
[[gnu::always_inline]] inline bool dot_step64_decides(const ExponentRange& a,
                                                      const ExponentRange& b, bool nearest) {
  const int low = a.lo + b.lo - F::kManBits;
  const int high = a.hi + b.hi + 2;
  return nearest & a.normal & b.normal & (low >= F::kFormat.emin()) &
         (high + 2 <= F::kFormat.emax());
}
template <class F>
[[gnu::always_inline]] inline bool dot_step64(const DotOperand& a, const DotOperand& b,
                                              bool nearest, F& out) {
  if (!dot_step64_decides<F>(a.range, b.range, nearest)) return false;
  const V2d p = a.xy * b.xy;
  const double x = round_in_range<F>(p[0]);
  const double y = round_in_range<F>(p[1]);
  const double z = round_in_range<F>(a.z * b.z);
  out = encoding_of<F>(round_in_range<F>(round_in_range<F>(x + y) + round_in_range<F>(z + 0.0)));
  return true;
}
template <class F>
[[gnu::always_inline]] inline bool dot_step64(const Vec3<F>& a, const Vec3<F>& b,
                                              const ExponentRange& rb, bool nearest, F& out) {
  return dot_step64<F>(dot_operand<F>(a), dot_operand<F>(b, rb), nearest, out);
}
template <class F>
[[gnu::always_inline]] inline bool dot_step64(const Vec3<F>& a, const Vec3<F>& b, bool nearest,
                                              F& out) {
  return dot_step64<F>(dot_operand<F>(a), dot_operand<F>(b), nearest, out);
}

struct TraversalLane64 {
  bool go_near = false;
  bool go_far = false;
  double near_tf = 0.0;
  double far_tn = 0.0;
};

// traversal_lane on values; false: not decided here, use traversal_lane.
template <class F>
[[gnu::always_inline]] inline bool traversal_lane64(double split, double o_axis, double inv_d,
                                                    double tn, double tf, TraversalLane64& r) {
  bool ok = true;
  const double d = round_to_format<F>(round_to_format<F>(split - o_axis, ok) * inv_d, ok);
  r.go_near = !(d < tn);
  r.go_far = !(tf < d);
  r.near_tf = r.go_far ? d : tf;
  r.far_tn = r.go_near ? d : tn;
  return ok;
}

// clip_face on values; false (tn, tf unchanged): not decided here, use clip_face.
template <class F>
[[gnu::always_inline]] inline bool clip_face64(double plane, double o_axis, double inv_d,
                                               bool entry, double& tn, double& tf) {
  bool ok = true;
  const double t = round_to_format<F>(round_to_format<F>(plane - o_axis, ok) * inv_d, ok);
  if (!ok) return false;
  if (entry)
    tn = tn < t ? t : tn;
  else
    tf = t < tf ? t : tf;
  return true;
}

// round_to_format on both lanes; a lane of `ok` is cleared unless its result is zero or normal
// and finite in F. The same decision as round_to_format's integer tests, made by double compares
// of the rounded magnitude: a non-finite input rounds to inf or NaN, which fails them too
// (tested in units/datapath_test.cpp).
template <class F>
[[gnu::always_inline]] inline V2d round_to_format2(V2d v, V2i& ok) {
  constexpr double kMin =
      std::bit_cast<double>(static_cast<std::uint64_t>(1023 + F::kFormat.emin()) << 52);
  constexpr double kLimit =
      std::bit_cast<double>(static_cast<std::uint64_t>(1023 + F::kFormat.emax() + 1) << 52);
  const V2d r = round_in_range2<F>(v);
  const auto mag = std::bit_cast<V2d>(std::bit_cast<V2u>(r) & ~(std::uint64_t{1} << 63));
  ok &= ((mag >= kMin) & (mag < kLimit)) | (r == 0.0);
  return r;
}

// traversal_lane64 on two lanes. go_near, go_far and fail as bits 0 and 1; a failed lane (not
// decided here, as traversal_lane64's false) must be redone with traversal_lane.
struct TraversalPair64 {
  std::uint64_t go_near = 0, go_far = 0, fail = 0;
  V2d near_tf{}, far_tn{};
};
template <class F>
[[gnu::always_inline]] inline TraversalPair64 traversal_pair64(V2d split, V2d o_axis, V2d inv_d,
                                                               V2d tn, V2d tf) {
  V2i ok = {-1, -1};
  const V2d d = round_to_format2<F>(round_to_format2<F>(split - o_axis, ok) * inv_d, ok);
  const V2i before = d < tn;  // not go_near
  const V2i after = tf < d;   // not go_far
  TraversalPair64 r;
  r.go_near = ~mask2(before) & 3u;
  r.go_far = ~mask2(after) & 3u;
  r.fail = ~mask2(ok) & 3u;
  r.near_tf = select2(after, tf, d);  // go_far ? d : tf
  r.far_tn = select2(before, tn, d);  // go_near ? d : tn
  return r;
}

// clip_face64 on two lanes (plane per lane); lanes of `ok` are cleared where it would return
// false (then tn, tf of that lane are meaningless and the caller redoes the lane).
template <class F>
[[gnu::always_inline]] inline void clip_face_pair64(V2d plane, V2d o_axis, V2d inv_d, bool entry,
                                                    V2d& tn, V2d& tf, V2i& ok) {
  const V2d t = round_to_format2<F>(round_to_format2<F>(plane - o_axis, ok) * inv_d, ok);
  if (entry)
    tn = select2(tn < t, t, tn);
  else
    tf = select2(t < tf, t, tf);
}

}  // namespace saarcor::units
