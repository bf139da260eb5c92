// The DynRTC datapaths as pure functions (paper sections 2.1-2.3 and 3.1; docs/cycle-model.md
// and 7): the transformation step, the traversal step of one kd-node for a packet, the
// unit-triangle intersection and its acceptance rules (decision D13 plus the tie rule of
// docs/shading.md section 3), the slab clip of D29, and the RGS FP helper's refraction factor. Each
// takes the float unit (UnitFp) of the hardware unit that owns the operators, so ops are counted
// per unit. The functional model and the cycle model call these same functions; nothing here keeps
// state, so results cannot depend on timing. `fp` is a UnitFp (counts every op) or a RawFp (the
// thread program, which counts each step's ops in bulk). These are the paper's op order on
// encodings (the reference datapath); the same steps on binary64 values, which the thread program
// takes where they decide, are in units/fast_paths.h.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <limits>

#include "fixedfloat/float.h"
#include "fixedfloat/pack.h"
#include "memif/image_format.h"
#include "units/unit_fp.h"

namespace saarcor::units {

template <class F>
using Vec3 = std::array<F, 3>;
// One affine 3x4 matrix, row r = (m_r0, m_r1, m_r2, t_r), as the memory image stores it.
template <class F>
using Mat34 = std::array<std::array<F, 4>, 3>;

template <class F>
struct Ray {
  Vec3<F> o{};
  Vec3<F> d{};
  friend bool operator==(const Ray&, const Ray&) = default;
};

// ---- bit tests (no comparator: wires on the encoding) ---------------------------------------
template <class F>
inline std::uint32_t magnitude_bits(F x) {
  return x.bits & (F::kFormat.sign_mask() - 1u);
}
template <class F>
inline bool bits_zero(F x) {
  return magnitude_bits(x) == 0;
}
template <class F>
inline bool bits_nan(F x) {
  return magnitude_bits(x) > F::kFormat.inf_bits();
}
template <class F>
inline bool bits_inf(F x) {
  return magnitude_bits(x) == F::kFormat.inf_bits();
}
template <class F>
inline bool is_neg_nonzero(F x) {  // x < 0, NaN excluded
  return x.sign() && !bits_zero(x) && !bits_nan(x);
}
template <class F>
inline bool is_pos_nonzero(F x) {  // x > 0, NaN excluded
  return !x.sign() && !bits_zero(x) && !bits_nan(x);
}
template <class F>
inline bool is_nonneg(F x) {  // x >= 0 (-0 included), NaN excluded
  return (!x.sign() || bits_zero(x)) && !bits_nan(x);
}
// For operands known to be >= 0 and not NaN the encoding orders like the value (with -0 read as
// +0): D13's "bit-pattern compare", used where the intersection unit has no comparator.
template <class F>
inline std::uint32_t magnitude_key(F x) {
  return magnitude_bits(x);
}

// ---- transformation unit (paper 2.3, docs/cycle-model.md: 9 mul, 9 add per step)
// ----------------------- One step: per output component r, (m_r0*x + m_r1*y) + (m_r2*z + t_r). A
// direction step feeds zero as the translation (the adder still runs: -0 + +0 = +0, a real datapath
// effect).
template <class F, class Fp>
[[gnu::flatten]] inline Vec3<F> transform_step(const Fp& fp, const Mat34<F>& m, const Vec3<F>& v,
                                               bool translate) {
  Vec3<F> out;
  for (int r = 0; r < 3; ++r) {
    const F t = translate ? m[r][3] : F::zero();
    out[r] = fp.add(fp.add(fp.mul(m[r][0], v[0]), fp.mul(m[r][1], v[1])),
                    fp.add(fp.mul(m[r][2], v[2]), t));
  }
  return out;
}

// The dot product as one row of a zero-translation step: (a.x*b.x + a.y*b.y) + (a.z*b.z + 0).
template <class F, class Fp>
[[gnu::flatten]] inline F dot_step(const Fp& fp, const Vec3<F>& a, const Vec3<F>& b) {
  return fp.add(fp.add(fp.mul(a[0], b[0]), fp.mul(a[1], b[1])),
                fp.add(fp.mul(a[2], b[2]), F::zero()));
}

// ---- RGS FP helper: the refraction factor (paper 2.2.2, docs/shading.md, D10, D12)
// ---------------- The paper generates a refracted ray from T_R = [D, N, D; O] and R' = ((t, 0, e),
// (-eta, mu, 0)) with mu = eta*c - sqrt(1 - eta^2 + (eta*c)^2), c = N.D: the textbook formula for a
// D that points back to the viewer. With D the ray's direction, as in every other row of the table,
// and N the normal facing the ray (as for reflection), c = -N.D (the cosine of incidence, >= 0) and
// the refracted direction is eta*D + mu*N: R' = ((t, 0, e), (eta, mu, 0)), with eta = n1 / n2 (the
// side the ray comes from over the side it enters). Neither D nor N is a unit vector (D9), so the
// helper scales mu by |D| / |N|, which gives the refracted direction the length of D:
//   mu = (eta*c - sqrt((1 - eta*eta)*(D.D * N.N) + (eta*c)^2)) / N.N,   c = -N.D
// (for unit D and N exactly the paper's mu). A negative radicand is total internal reflection: no
// refracted ray exists (a sign test). Inputs: N.D, D.D and N.N from the transformation unit's dot
// products. 5 mul, 3 add, 1 sqrt, 1 div.
template <class F>
struct RefractionFactor {
  F mu{};              // the refracted direction is eta*D + mu*N (NaN under total reflection)
  bool total = false;  // total internal reflection: the radicand is < 0
};
template <class F, class Fp>
inline RefractionFactor<F> refraction_factor(const Fp& fp, F eta, F nd, F dd, F nn) {
  const F ec = fp.mul(eta, nd.neg());
  const F g = fp.sub(F::one(), fp.mul(eta, eta));
  const F radicand = fp.add(fp.mul(g, fp.mul(dd, nn)), fp.mul(ec, ec));
  RefractionFactor<F> r;
  r.total = is_neg_nonzero(radicand);
  r.mu = fp.div(fp.sub(ec, fp.sqrt(radicand)), nn);
  return r;
}

// ---- traversal unit (paper 3.1, docs/cycle-model.md, decisions D27/D33)
// --------------------------------- One ray's lane of a kd-node step. The packet shares one
// near/far order (all active rays have the same direction sign on the split axis, D27): near =
// lower child when the sign bit is clear. d = (split - O[axis]) / D[axis]; the ray segment [tn, tf]
// needs the near child unless d < tn and the far child unless d > tf. When it needs both, near gets
// [tn, d] and far [d, tf]; a NaN d (origin on the plane, direction parallel) keeps [tn, tf] on both
// sides (a bit test, no comparator). 1 add, 1 div, 2 cmp.
template <class F>
struct TraversalLane {
  bool go_near = false;
  bool go_far = false;
  F near_tf{};  // near child's interval end (start stays tn)
  F far_tn{};   // far child's interval start (end stays tf)
};

// d_axis: the direction component, or its Divisor (the same quotient, see units/unit_fp.h).
template <class F, class Fp, class Den>
[[gnu::flatten]] inline TraversalLane<F> traversal_lane(const Fp& fp, F split, F o_axis, Den d_axis,
                                                        F tn, F tf) {
  const F d = fp.div(fp.sub(split, o_axis), d_axis);
  const bool before = fp.lt(d, tn);  // plane before the segment: far side only
  const bool after = fp.lt(tf, d);   // plane beyond the segment: near side only
  TraversalLane<F> r;
  r.go_near = !before;
  r.go_far = !after;
  const bool nan = bits_nan(d);
  r.near_tf = (r.go_far && !nan) ? d : tf;
  r.far_tn = (r.go_near && !nan) ? d : tn;
  return r;
}

// Early termination at node entry (1 cmp): a ray leaves a node whose segment starts beyond its
// closest hit. Equal values stay (a later triangle may tie in t, docs/shading.md section 3).
template <class F, class Fp>
inline bool terminated(const Fp& fp, F t_best, F tn) {
  return fp.lt(t_best, tn);
}

// Slab clip of D29 against one face of a box, with the traversal unit's adders and dividers:
// t = (plane - O[axis]) / D[axis]; an entry face raises tn (max), an exit face lowers tf (min).
// The face is the entry face when the direction's sign bit is clear for `lo`, set for `hi`. The
// comparator-multiplexer max/min keep the old bound on NaN (origin on a parallel face).
// 1 add, 1 div, 1 cmp.
template <class F, class Fp, class Den>
[[gnu::flatten]] inline void clip_face(const Fp& fp, F plane, F o_axis, Den d_axis, bool entry,
                                       F& tn, F& tf) {
  const F t = fp.div(fp.sub(plane, o_axis), d_axis);
  if (entry)
    tn = fp.max(tn, t);
  else
    tf = fp.min(tf, t);
}

// ---- intersection unit (paper 2.1.2, docs/cycle-model.md: 3 add, 2 mul, 1 div per ray)
// --------------
template <class F>
struct Candidate {
  F t{}, u{}, v{}, c{};  // c = D'z, the cosine with the geometric normal
  bool inside = false;   // D'z != 0, t > 0, u >= 0, v >= 0, u + v <= 1, no NaN (bit tests)
};

// t = -O'z / D'z, u = O'x + t*D'x, v = O'y + t*D'y; u + v is the third adder.
template <class F, class Fp>
[[gnu::flatten]] inline Candidate<F> intersect_unit_triangle(const Fp& fp, const Ray<F>& r) {
  Candidate<F> c;
  c.c = r.d[2];
  c.t = fp.div(r.o[2].neg(), r.d[2]);
  c.u = fp.add(r.o[0], fp.mul(c.t, r.d[0]));
  c.v = fp.add(r.o[1], fp.mul(c.t, r.d[1]));
  const F sum = fp.add(c.u, c.v);
  c.inside = !bits_zero(c.c) && !bits_nan(c.c) && is_pos_nonzero(c.t) && !bits_inf(c.t) &&
             is_nonneg(c.u) && is_nonneg(c.v) && is_nonneg(sum) &&
             magnitude_key(sum) <= F::one().bits;
  return c;
}

// The closest-hit record of one ray. Instance/triangle = memif::kNone when there is no hit.
template <class F>
struct HitRecord {
  F t = F::infinity();
  F u{}, v{}, c{};
  std::uint32_t instance = memif::kNone;
  std::uint32_t triangle = memif::kNone;
  bool hit() const { return instance != memif::kNone; }
  friend bool operator==(const HitRecord&, const HitRecord&) = default;
};

// Acceptance (D13 with the tie rule of docs/shading.md section 3): inside, and t < t_best, or
// t == t_best with a smaller (instance, triangle). t > 0 and t_best >= 0 are both non-negative,
// so the compares are magnitude compares of the encodings (no comparator, as D13 asks).
template <class F>
inline bool accepts(const Candidate<F>& c, std::uint32_t instance, std::uint32_t triangle,
                    const HitRecord<F>& best) {
  if (!c.inside) return false;
  const std::uint32_t kt = magnitude_key(c.t);
  const std::uint32_t kb = magnitude_key(best.t);
  if (kt != kb) return kt < kb;
  if (instance != best.instance) return instance < best.instance;
  return triangle < best.triangle;
}

// ---- memory image reads (what the caches deliver) ---------------------------------------------
// As image.row(row) for an image in F's format (the thread program checks that), unpacked with the
// format known at compile time.
template <class F>
inline std::array<F, 4> read_row(const memif::MemoryImage& image, std::uint32_t row) {
  constexpr int kWords = ff::row_words(F::kFormat);
  std::array<std::uint32_t, 4> w{};
  for (int i = 0; i < kWords; ++i)
    w[static_cast<std::size_t>(i)] = image.item_word(memif::ItemType::kRow, row, i);
  const auto v = ff::unpack_row(w.data(), F::kFormat);
  return {F::from_bits(v[0]), F::from_bits(v[1]), F::from_bits(v[2]), F::from_bits(v[3])};
}
template <class F>
inline Mat34<F> read_matrix(const memif::MemoryImage& image, std::uint32_t first_row) {
  return {read_row<F>(image, first_row), read_row<F>(image, first_row + 1),
          read_row<F>(image, first_row + 2)};
}

}  // namespace saarcor::units
