// The reference datapath policy of the thread program (ThreadProgram<F, kLanes,
// ReferenceDatapath>): every traversal, clip, transformation and RGS dot-product and cosine step on
// encodings in the paper's op order (units/datapath.h; each op through fixedfloat's
// round-and-pack), lane by lane. The same kernels as units/fast_datapath.h without any binary64
// arithmetic: this header and what it includes never see units/fast_paths.h, and the target that
// instantiates it (saarcor_units_reference, units/reference_model.cpp) is compiled so that it
// cannot (units/reference_guard/). testbench/reference_datapath_test.cpp compares it with the fast
// instantiation step by step and frame by frame.
#pragma once

#include <array>
#include <bit>
#include <cstdint>

#include "units/datapath.h"
#include "units/packet.h"

namespace saarcor::units {

struct ReferenceDatapath {
  // A transformation or dot step reads nothing but the encodings.
  template <class F>
  struct Matrix {};
  struct Operand {};

  // ---- the traversal unit's operands ------------------------------------------------------------
  // The traversal and clip kernels below read the rays' encodings: no values to keep.
  template <class S, class Axis>
  static void axis_values(const S&, Axis&, Axis&,
                          Ray<typename S::Float> Lane<typename S::Float>::*) {}

  // ---- the transformation unit ------------------------------------------------------------------
  template <class S>
  static Matrix<typename S::Float> matrix(const S&, const Mat34<typename S::Float>&) {
    return {};
  }
  template <class S, class F = typename S::Float>
  static Vec3<F> transform(const S& t, const Mat34<F>& m, const Matrix<F>&, const Vec3<F>& x,
                           bool translate) {
    return transform_step(t.u.raw, m, x, translate);
  }
  // out(i) = m * in(i) for the lanes in `mask`.
  template <class S, class In, class Out, class F = typename S::Float>
  static void transform_masked(const S& t, const Mat34<F>& m, const Matrix<F>&, std::uint64_t mask,
                               bool translate, In in, Out out) {
    for (int i = 0; i < t.p; ++i)
      if (lane_in(mask, i)) out(i) = transform_step(t.u.raw, m, in(i), translate);
  }

  // ---- the traversal unit -----------------------------------------------------------------------
  // The slab clip of a box (D29) for the lanes of `mask`, faces 0..5 in order (x entry, x exit,
  // y entry, ...), each clip_face on the segment's encodings; the entry face is lo for a positive
  // direction, hi for a negative one.
  template <class S, class Axis, class F = typename S::Float>
  static void clip_box(S& t, std::uint64_t mask, const std::array<F, 3>& box_lo,
                       const std::array<F, 3>& box_hi, const Axis&, const Axis&) {
    for (; mask != 0; mask &= mask - 1) {
      const int i = std::countr_zero(mask);
      const auto s = static_cast<std::size_t>(i);
      const Lane<F>& l = t.lane(i);
      F tn = t.encoding(t.v.clip_tn[s]), tf = t.encoding(t.v.clip_tf[s]);
      for (int face = 0; face < 6; ++face) {
        const int axis = face / 2;
        const auto k = static_cast<std::size_t>(axis);
        const bool entry = (face % 2) == 0;
        const bool lo_face = entry != l.current.d[axis].sign();
        units::clip_face(t.u.direct, lo_face ? box_lo[k] : box_hi[k], l.current.o[axis],
                         l.current.d[axis], entry, tn, tf);
      }
      t.v.clip_tn[s] = t.value(tn);
      t.v.clip_tf[s] = t.value(tf);
    }
  }

  // traversal_lane on encodings for every active lane at an inner node. The other lanes' slots
  // keep the segment they had (not read while they are outside the mask: LaneValues).
  template <class S, class Axis, class F = typename S::Float>
  static void decide(S& t, int axis, F split, std::uint64_t active, const Axis&, const Axis&,
                     TraversalDecision<S::kLaneCapacity>& d) {
    t.copy_slots(d.near_tf.data(), t.v.tf.data());
    t.copy_slots(d.far_tn.data(), t.v.tn.data());
    for (std::uint64_t m = active; m != 0; m &= m - 1) {
      const int i = std::countr_zero(m);
      const auto s = static_cast<std::size_t>(i);
      const Lane<F>& l = t.lane(i);
      const TraversalLane<F> e =
          traversal_lane(t.u.direct, split, l.current.o[axis], l.current.d[axis],
                         t.encoding(t.v.tn[s]), t.encoding(t.v.tf[s]));
      d.near_mask |= std::uint64_t{e.go_near} << i;
      d.far_mask |= std::uint64_t{e.go_far} << i;
      d.near_tf[s] = t.value(e.near_tf);
      d.far_tn[s] = t.value(e.far_tn);
    }
  }

  // ---- the RGS's dot products and cosines
  // ---------------------------------------------------------
  template <class F>
  static Operand operand(const Vec3<F>&) {
    return {};
  }
  template <class S, class F = typename S::Float>
  static F dot(const S& t, const Vec3<F>& a, const Vec3<F>& b) {
    return dot_step(t.u.raw, a, b);
  }
  template <class S, class F = typename S::Float>
  static F dot(const S& t, const Vec3<F>& a, const Operand&, const Vec3<F>& b, const Operand&) {
    return dot_step(t.u.raw, a, b);
  }
  // Two lanes' direction steps (a matrix each), each row dot_step with the row as the first
  // vector; the two lanes may be the same (one step).
  template <class S, class F = typename S::Float>
  static void direction_steps(const S& t, const Mat34<F>& ma, const Vec3<F>& va, const Mat34<F>& mb,
                              const Vec3<F>& vb, Vec3<F>& out_a, Vec3<F>& out_b) {
    const bool same = &ma == &mb && &va == &vb;
    const Vec3<F> a = direction_rows(t, ma, va);
    if (!same) out_b = direction_rows(t, mb, vb);
    out_a = a;
  }
  // -x / sqrt(a * b) on the RGS helper.
  template <class S, class F = typename S::Float>
  static F cosine(const S& t, F x, F a, F b) {
    const auto& fp = t.u.raw;
    return fp.div(x.neg(), fp.sqrt(fp.mul(a, b)));
  }

 private:
  template <class S, class F = typename S::Float>
  static Vec3<F> direction_rows(const S& t, const Mat34<F>& m, const Vec3<F>& v) {
    Vec3<F> out;
    for (int r = 0; r < 3; ++r)
      out[r] = dot_step(t.u.raw, Vec3<F>{m[r][0], m[r][1], m[r][2]}, v);
    return out;
  }
};

}  // namespace saarcor::units
