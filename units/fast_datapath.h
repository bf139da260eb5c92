// The fast datapath policy of the thread program (ThreadProgram<F, kLanes, FastDatapath>, what
// every model runs): the traversal, clip, transformation and RGS dot-product and cosine steps on
// binary64 values two lanes at a time where units/fast_paths.h decides (the result equals the
// encoding path's bit for bit), and the lane redone on encodings (units/datapath.h, the paper's op
// order) where it does not. Its counterpart units/reference_datapath.h has the same kernels on
// encodings only; testbench/reference_datapath_test.cpp compares the two instantiations step by
// step. The unit semantics (units/*_step.h) call these kernels and count the ops themselves.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "units/fast_paths.h"
#include "units/packet.h"

namespace saarcor::units {

struct FastDatapath {
  // What a transformation step reads of a matrix besides its encodings: its entries' values and
  // exponent ranges (transform_decides).
  template <class F>
  using Matrix = MatrixValues<F>;
  // What a dot product reads of a vector besides its encodings (dot_step64).
  using Operand = DotOperand;

  // ---- the traversal unit's operands ------------------------------------------------------------
  // O and 1/D of every lane's ray `ray`, the reciprocals two lanes per division (the same binary64
  // quotients). Lanes outside the level's mask get values nothing reads. A lane whose D is not
  // normal, or a mode other than nearest-even, gets a NaN reciprocal: no traversal or clip step of
  // that lane is decided on values (round_to_format refuses NaN), so it is redone on encodings.
  template <class S, class Axis>
  static void axis_values(const S& t, Axis& o, Axis& inv,
                          Ray<typename S::Float> Lane<typename S::Float>::*ray) {
    using F = typename S::Float;
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    for (int i = 0; i < t.p; i += 2) {
      const Ray<F>& a = t.lane(i).*ray;
      const Ray<F>& b = t.lane(i + 1 < t.p ? i + 1 : i).*ray;
      const auto s = static_cast<std::size_t>(i);
      for (std::size_t k = 0; k < 3; ++k) {
        const int c = static_cast<int>(k);
        o[k][s] = t.value(a.o[c]);
        o[k][s + 1] = t.value(b.o[c]);
        const V2d r = 1.0 / decode_pair<F>(a.d[c].bits, b.d[c].bits);  // decoded as if normal
        inv[k][s] =
            t.nearest && ff::fast::is_normal<F::kExpBits, F::kManBits>(a.d[c].bits) ? r[0] : kNaN;
        inv[k][s + 1] =
            t.nearest && ff::fast::is_normal<F::kExpBits, F::kManBits>(b.d[c].bits) ? r[1] : kNaN;
      }
    }
  }

  // ---- the transformation unit ------------------------------------------------------------------
  // The matrix's values for transform_step64 (every entry zero or normal: decoded two at a time,
  // the same values); `nearest` cleared for truncation, where no step is decided on values.
  template <class S>
  static Matrix<typename S::Float> matrix(const S& t, const Mat34<typename S::Float>& m) {
    using F = typename S::Float;
    bool normal = true;
    for (const auto& r : m)
      for (const F x : r)
        normal &= normal_or_zero(x);
    if (!normal) {
      Matrix<F> mv = matrix_values(m, t.u.raw.mode().subnormals);
      mv.nearest = t.nearest;
      return mv;
    }
    Matrix<F> mv;
    for (std::size_t r = 0; r < 3; ++r) {
      const auto& rw = m[static_cast<int>(r)];
      for (int c = 0; c < 4; c += 2) {
        const V2d x = decode_pair<F>(rw[c].bits, rw[c + 1].bits);
        mv.m[r][static_cast<std::size_t>(c)] = x[0];
        mv.m[r][static_cast<std::size_t>(c + 1)] = x[1];
      }
      mv.linear.include(rw[0]);
      mv.linear.include(rw[1]);
      mv.linear.include(rw[2]);
      mv.translation.include(rw[3]);
    }
    mv.nearest = t.nearest;
    return mv;
  }

  // One vector: the two-lane path with both lanes the same (fewer moves than the scalar path).
  template <class S, class F = typename S::Float>
  static Vec3<F> transform(const S& t, const Mat34<F>& m, const Matrix<F>& mv, const Vec3<F>& x,
                           bool translate) {
    if (!transform_decides<F>(mv, x, translate)) return transform_step(t.u.raw, m, x, translate);
    const V2d d[3] = {decode_pair<F>(x[0].bits, x[0].bits), decode_pair<F>(x[1].bits, x[1].bits),
                      decode_pair<F>(x[2].bits, x[2].bits)};
    V2u r[3];
    transform_pair64<F>(mv, d, translate, r);
    return lane_of<F>(r, 0);
  }

  // out(i) = m * in(i) for the lanes in `mask`: two lanes at a time on values where
  // transform_decides holds for both or one of them, the others on encodings.
  template <class S, class In, class Out, class F = typename S::Float>
  static void transform_masked(const S& t, const Mat34<F>& m, const Matrix<F>& mv,
                               std::uint64_t mask, bool translate, In in, Out out) {
    for (int i = 0; i < t.p; i += 2) {
      const int j = i + 1 < t.p ? i + 1 : i;
      const bool a = lane_in(mask, i), b = j != i && lane_in(mask, j);
      if (!(a | b)) continue;
      const Vec3<F>& va = in(i);
      const Vec3<F>& vb = in(j);
      const bool da = a && transform_decides<F>(mv, va, translate);
      const bool db = b && transform_decides<F>(mv, vb, translate);
      if (da | db) {
        const V2d x[3] = {decode_pair<F>(va[0].bits, vb[0].bits),
                          decode_pair<F>(va[1].bits, vb[1].bits),
                          decode_pair<F>(va[2].bits, vb[2].bits)};
        V2u r[3];
        transform_pair64<F>(mv, x, translate, r);
        if (da) out(i) = lane_of<F>(r, 0);
        if (db) out(j) = lane_of<F>(r, 1);
      }
      if (a && !da) out(i) = transform_step(t.u.raw, m, in(i), translate);
      if (b && !db) out(j) = transform_step(t.u.raw, m, in(j), translate);
    }
  }

  // ---- the traversal unit -----------------------------------------------------------------------
  // The slab clip of a box (D29) for the lanes of `mask`, faces 0..5: x entry, x exit, y entry, ...
  // The entry face is lo for a positive direction, hi for a negative one; the exit face the other.
  // Two lanes at a time through the six faces on values; a lane that any face does not decide
  // there is redone alone from its start values (clip_lane).
  template <class S, class Axis, class F = typename S::Float>
  static void clip_box(S& t, std::uint64_t mask, const std::array<F, 3>& box_lo,
                       const std::array<F, 3>& box_hi, const Axis& lo, const Axis& inv) {
    std::array<double, 3> lo_value, hi_value;
    for (std::size_t k = 0; k < 3; ++k) {
      lo_value[k] = t.value(box_lo[k]);
      hi_value[k] = t.value(box_hi[k]);
    }
    std::uint64_t redo = 0;
    for (int i = 0; i < t.p; i += 2) {
      const std::uint64_t lanes = (mask >> i) & 3u;
      if (lanes == 0) continue;
      const Lane<F>& l0 = t.lane(i);
      const Lane<F>& l1 = t.lane(i + 1 < t.p ? i + 1 : i);
      const auto s = static_cast<std::size_t>(i);
      V2i ok = {-1, -1};
      V2d tn = load2(&t.v.clip_tn[s]), tf = load2(&t.v.clip_tf[s]);
      for (int axis = 0; axis < 3; ++axis) {
        const auto k = static_cast<std::size_t>(axis);
        // Per lane: the entry face is lo for a positive direction (sign bit clear).
        const V2i neg = {l0.current.d[axis].sign() ? -1 : 0, l1.current.d[axis].sign() ? -1 : 0};
        const V2d lo_plane = {lo_value[k], lo_value[k]}, hi_plane = {hi_value[k], hi_value[k]};
        const V2d o = load2(&lo[k][s]), d = load2(&inv[k][s]);
        clip_face_pair64<F>(select2(neg, hi_plane, lo_plane), o, d, true, tn, tf, ok);
        clip_face_pair64<F>(select2(neg, lo_plane, hi_plane), o, d, false, tn, tf, ok);
      }
      const std::uint64_t decided = lanes & mask2(ok);
      if ((decided & 1u) != 0) {
        t.v.clip_tn[s] = tn[0];
        t.v.clip_tf[s] = tf[0];
      }
      if ((decided & 2u) != 0) {
        t.v.clip_tn[s + 1] = tn[1];
        t.v.clip_tf[s + 1] = tf[1];
      }
      redo |= (lanes & ~decided) << i;
    }
    for (; redo != 0; redo &= redo - 1)
      clip_lane(t, std::countr_zero(redo), box_lo, box_hi, lo_value, hi_value, lo, inv);
  }

  // traversal_lane for every active lane at an inner node: two lanes at a time on values
  // (inactive lanes are computed along and dropped), the lanes the values do not decide on
  // encodings.
  template <class S, class Axis, class F = typename S::Float>
  static void decide(S& t, int axis, F split, std::uint64_t active, const Axis& lo, const Axis& inv,
                     TraversalDecision<S::kLaneCapacity>& d) {
    std::uint64_t fail = 0;
    const double split_value = t.value(split);
    const V2d split2 = {split_value, split_value};
    const auto a = static_cast<std::size_t>(axis);
    for (int i = 0; i < t.p; i += 2) {
      const auto s = static_cast<std::size_t>(i);
      const TraversalPair64 r = traversal_pair64<F>(split2, load2(&lo[a][s]), load2(&inv[a][s]),
                                                    load2(&t.v.tn[s]), load2(&t.v.tf[s]));
      d.near_mask |= r.go_near << i;
      d.far_mask |= r.go_far << i;
      fail |= r.fail << i;
      store2(&d.near_tf[s], r.near_tf);
      store2(&d.far_tn[s], r.far_tn);
    }
    d.near_mask &= active;
    d.far_mask &= active;
    for (std::uint64_t m = fail & active; m != 0; m &= m - 1)
      decide_lane(t, axis, split, std::countr_zero(m), d);
  }

  // ---- the RGS's dot products and cosines
  // ---------------------------------------------------------
  template <class F>
  static Operand operand(const Vec3<F>& a) {
    return dot_operand<F>(a);
  }
  // dot_step (a zero-translation row) on values where dot_step64 decides, else on encodings.
  template <class S, class F = typename S::Float>
  static F dot(const S& t, const Vec3<F>& a, const Vec3<F>& b) {
    F r;
    if (dot_step64<F>(a, b, t.nearest, r)) return r;
    return dot_step(t.u.raw, a, b);
  }
  // The same with both vectors decoded already (operand(a), operand(b)).
  template <class S, class F = typename S::Float>
  static F dot(const S& t, const Vec3<F>& a, const Operand& da, const Vec3<F>& b,
               const Operand& db) {
    F r;
    if (dot_step64<F>(da, db, t.nearest, r)) return r;
    return dot_step(t.u.raw, a, b);
  }

  // Two lanes' direction steps (a matrix each), each row dot_step's expression with the row as
  // the first vector: where direction_decides holds, both lanes' rows go through dot_step64's ops
  // together (one lane per half of a vector register: each lane's ops and values are its own, so
  // its results are dot_step64's); otherwise the lane row by row. The two lanes may be the same
  // (one step); out_a and out_b may then be the same vector.
  template <class S, class F = typename S::Float>
  static void direction_steps(const S& t, const Mat34<F>& ma, const Vec3<F>& va, const Mat34<F>& mb,
                              const Vec3<F>& vb, Vec3<F>& out_a, Vec3<F>& out_b) {
    const bool da = direction_decides(t, ma, va);
    const bool same = &ma == &mb && &va == &vb;
    const bool db = same ? da : direction_decides(t, mb, vb);
    if (da | db) {
      const V2d x[3] = {decode_pair<F>(va[0].bits, vb[0].bits),
                        decode_pair<F>(va[1].bits, vb[1].bits),
                        decode_pair<F>(va[2].bits, vb[2].bits)};
      V2u e[3];
      for (int r = 0; r < 3; ++r) {
        e[r] = row_pair64<F>(decode_pair<F>(ma[r][0].bits, mb[r][0].bits),
                             decode_pair<F>(ma[r][1].bits, mb[r][1].bits),
                             decode_pair<F>(ma[r][2].bits, mb[r][2].bits), V2d{0.0, 0.0}, x);
      }
      if (db) out_b = lane_of<F>(e, 1);
      if (da) out_a = lane_of<F>(e, 0);
    }
    if (!da) out_a = direction_rows(t, ma, va);
    if (!db && !same) out_b = direction_rows(t, mb, vb);
  }

  // -x / sqrt(a * b) on the RGS helper. Normal operands in nearest-even: the three ops on binary64
  // values, each rounded to F's precision where round_to_format accepts it (what ff::fast's mul,
  // sqrt and div compute and round: the product is exact, the root and the quotient
  // double-rounded innocuously), without encoding the intermediates; anything else, or a result
  // out of F's normal range, on the encodings.
  template <class S, class F = typename S::Float>
  static F cosine(const S& t, F x, F a, F b) {
    using ff::fast::is_normal;
    constexpr int E = F::kExpBits, M = F::kManBits;
    if (t.nearest & is_normal<E, M>(x.bits) & is_normal<E, M>(a.bits) & is_normal<E, M>(b.bits)) {
      bool ok = true;
      const V2d ab = decode_pair<F>(a.bits, b.bits);
      const double p = round_to_format<F>(ab[0] * ab[1], ok);
      const double root = round_to_format<F>(std::sqrt(p), ok);
      const double q = round_to_format<F>(-decode_pair<F>(x.bits, x.bits)[0] / root, ok);
      if (ok) return encoding_of<F>(q);
    }
    const auto& fp = t.u.raw;
    return fp.div(x.neg(), fp.sqrt(fp.mul(a, b)));
  }

 private:
  // One lane's six faces, each on values where it decides, else on encodings.
  template <class S, class Axis, class F = typename S::Float>
  static void clip_lane(S& t, int i, const std::array<F, 3>& box_lo, const std::array<F, 3>& box_hi,
                        const std::array<double, 3>& lo_value,
                        const std::array<double, 3>& hi_value, const Axis& lo, const Axis& inv) {
    const auto s = static_cast<std::size_t>(i);
    const Lane<F>& l = t.lane(i);
    double& clip_tn = t.v.clip_tn[s];
    double& clip_tf = t.v.clip_tf[s];
    for (int face = 0; face < 6; ++face) {
      const int axis = face / 2;
      const auto k = static_cast<std::size_t>(axis);
      const bool entry = (face % 2) == 0;
      const bool lo_face = entry != l.current.d[axis].sign();
      if (clip_face64<F>(lo_face ? lo_value[k] : hi_value[k], lo[k][s], inv[k][s], entry, clip_tn,
                         clip_tf))
        continue;
      F tn = t.encoding(clip_tn), tf = t.encoding(clip_tf);
      units::clip_face(t.u.direct, lo_face ? box_lo[k] : box_hi[k], l.current.o[axis],
                       l.current.d[axis], entry, tn, tf);
      clip_tn = t.value(tn);
      clip_tf = t.value(tf);
    }
  }

  // traversal_lane on encodings for lane i, over what the values left in d.
  template <class S, class F = typename S::Float>
  static void decide_lane(S& t, int axis, F split, int i, TraversalDecision<S::kLaneCapacity>& d) {
    const auto s = static_cast<std::size_t>(i);
    const Lane<F>& l = t.lane(i);
    const TraversalLane<F> e =
        traversal_lane(t.u.direct, split, l.current.o[axis], l.current.d[axis],
                       t.encoding(t.v.tn[s]), t.encoding(t.v.tf[s]));
    const std::uint64_t bit = std::uint64_t{1} << i;
    d.near_mask = e.go_near ? d.near_mask | bit : d.near_mask & ~bit;
    d.far_mask = e.go_far ? d.far_mask | bit : d.far_mask & ~bit;
    d.near_tf[s] = t.value(e.near_tf);
    d.far_tn[s] = t.value(e.far_tn);
  }

  // dot_step64's condition for every row at once: the linear part's exponent range contains each
  // row's, so where it holds, each row's holds too. (With a matrix per lane, T_shadow or T_R, the
  // exponent ranges are cheaper than matrix() for one step.)
  template <class S, class F = typename S::Float>
  static bool direction_decides(const S& t, const Mat34<F>& m, const Vec3<F>& v) {
    ExponentRange rm, rv;
    for (int r = 0; r < 3; ++r) {
      rm.include(m[r][0]);
      rm.include(m[r][1]);
      rm.include(m[r][2]);
    }
    rv.include(v[0]);
    rv.include(v[1]);
    rv.include(v[2]);
    return dot_step64_decides<F>(rm, rv, t.nearest);
  }
  // The row-by-row direction step: dot_step64 per row where its condition holds, else dot_step.
  template <class S, class F = typename S::Float>
  static Vec3<F> direction_rows(const S& t, const Mat34<F>& m, const Vec3<F>& v) {
    ExponentRange rv;
    rv.include(v[0]);
    rv.include(v[1]);
    rv.include(v[2]);
    Vec3<F> out;
    for (int r = 0; r < 3; ++r) {
      const Vec3<F> row{m[r][0], m[r][1], m[r][2]};
      if (!dot_step64<F>(row, v, rv, t.nearest, out[r])) out[r] = dot_step(t.u.raw, row, v);
    }
    return out;
  }
};

}  // namespace saarcor::units
