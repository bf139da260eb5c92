// Datapath unit tests with hand-computed fp24 values (units/datapath.h, units/mailbox.h).
#include "units/datapath.h"
#include "units/fast_paths.h"

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <random>
#include <vector>

#include "units/mailbox.h"

namespace saarcor::units {
namespace {

using F = ff::fp24;

F f(double v) {
  return F::from_double(v);
}

TEST(TransformStep, OpOrderIsM0XPlusM1YThenM2ZPlusT) {
  ff::OpCounts ops;
  UnitFp<F> fp({}, &ops);
  const double e = std::ldexp(1.0, -17);  // half an ulp of 1.0 in fp24
  // Row 0: (1*1 + e*1) + (e*1 + 0): 1 + e ties to even (1), e + 0 = e, 1 + e -> 1 again. Any
  // other association (1 + (e + e) = 1 + 2^-16) would give the next float above 1.
  Mat34<F> m{};
  m[0] = {f(1), f(e), f(e), f(0)};
  m[1] = {f(2), f(3), f(4), f(5)};
  m[2] = {f(0.5), f(-1), f(0.25), f(-8)};
  const Vec3<F> v{f(1), f(1), f(1)};
  const Vec3<F> o = transform_step(fp, m, v, true);
  EXPECT_EQ(o[0].bits, f(1).bits);
  EXPECT_EQ(o[1].bits, f(14).bits);     // (2 + 3) + (4 + 5)
  EXPECT_EQ(o[2].bits, f(-8.25).bits);  // (0.5 - 1) + (0.25 - 8)
  EXPECT_EQ(ops.mul, 9u);
  EXPECT_EQ(ops.add, 9u);
  // Direction step: the translation is replaced by zero, the adder still runs: -0 + +0 = +0.
  const Vec3<F> d = transform_step(fp, m, Vec3<F>{f(-0.0), f(-0.0), f(-0.0)}, false);
  EXPECT_EQ(d[1].bits, 0u);  // +0, not the -0 of the products
  EXPECT_EQ(ops.mul, 18u);
  EXPECT_EQ(ops.add, 18u);
  EXPECT_EQ(dot_step(fp, Vec3<F>{f(1), f(2), f(3)}, Vec3<F>{f(4), f(5), f(6)}).bits, f(32).bits);
}

// Ray generation through transformations (paper 2.2.2, docs/shading.md): T = [A, B, C; D] has rows
// (A_r, B_r, C_r, D_r); the origin step translates, the direction step does not.
Mat34<F> columns(const Vec3<F>& a, const Vec3<F>& b, const Vec3<F>& c, const Vec3<F>& d) {
  Mat34<F> t{};
  for (int r = 0; r < 3; ++r)
    t[r] = {a[r], b[r], c[r], d[r]};
  return t;
}
Vec3<F> v3(double x, double y, double z) {
  return {f(x), f(y), f(z)};
}
void expect_vec(const Vec3<F>& got, double x, double y, double z, const char* what) {
  EXPECT_EQ(got[0].bits, f(x).bits) << what << " x";
  EXPECT_EQ(got[1].bits, f(y).bits) << what << " y";
  EXPECT_EQ(got[2].bits, f(z).bits) << what << " z";
}

TEST(RayGeneration, ShadowReflectionTransparency) {
  UnitFp<F> fp;
  const Vec3<F> zero = v3(0, 0, 0);
  // Shadow: T = [L, O, D; 0], R' = ((1,0,0), (-1, 1, t)) -> (L, O + t*D - L).
  const Vec3<F> light = v3(1, 2, 3), o = v3(0, 0, 0), d = v3(1, 1, 1);
  const Mat34<F> ts = columns(light, o, d, zero);
  expect_vec(transform_step(fp, ts, v3(1, 0, 0), true), 1, 2, 3, "shadow origin");
  expect_vec(transform_step(fp, ts, v3(-1, 1, 2), false), 1, 0, -1, "shadow direction");
  // T_R = [D, N, D; O] (translation O, the erratum). A ray straight down onto the floor y = 0
  // from (0, 5, 0): t = 5, N = (0, 1, 0), c = N.D = -1, e = 0.25.
  const Vec3<F> down = v3(0, -1, 0), n = v3(0, 1, 0), origin = v3(0, 5, 0);
  const Mat34<F> tr = columns(down, n, down, origin);
  // Reflection: R' = ((-e, 0, t), (1, -2c, 0)) -> (O + t*D - e*D, D - 2c*N).
  expect_vec(transform_step(fp, tr, v3(-0.25, 0, 5), true), 0, 0.25, 0, "reflection origin");
  expect_vec(transform_step(fp, tr, v3(1, 2, 0), false), 0, 1, 0, "reflection direction");
  // Transparency: R' = ((e, 0, t), (1, 0, 0)) -> (O + t*D + e*D, D).
  expect_vec(transform_step(fp, tr, v3(0.25, 0, 5), true), 0, -0.25, 0, "transparency origin");
  expect_vec(transform_step(fp, tr, v3(1, 0, 0), false), 0, -1, 0, "transparency direction");
}

// Refraction (docs/shading.md with the sign decided in D12): T_R = [D, N, D; O] on
// R' = ((t, 0, e), (eta, mu, 0)) gives (O + t*D + e*D, eta*D + mu*N), N facing the ray.
TEST(RayGeneration, Refraction) {
  ff::OpCounts ops;
  UnitFp<F> fp({}, &ops);
  // A ray (1, -1, 0) at 45 degrees onto the floor y = 0 from (-5, 5, 0): t = 5, N = (0, 1, 0),
  // e = 0.25, eta = 0.5. N.D = -1, D.D = 2, N.N = 1: eta*c = 0.5, the radicand
  // (1 - 0.25)*2 + 0.25 = 1.75, mu = 0.5 - sqrt(1.75).
  const Vec3<F> d = v3(1, -1, 0), n = v3(0, 1, 0), origin = v3(-5, 5, 0);
  const Mat34<F> tr = columns(d, n, d, origin);
  expect_vec(transform_step(fp, tr, v3(5, 0, 0.25), true), 0.25, -0.25, 0, "refraction origin");
  ops = {};
  const RefractionFactor<F> r =
      refraction_factor(fp, f(0.5), dot_step(fp, n, d), dot_step(fp, d, d), dot_step(fp, n, n));
  EXPECT_FALSE(r.total);
  const F root = f(std::sqrt(1.75));  // sqrt(1.75) rounded once; 0.5 - root is exact
  EXPECT_EQ(r.mu.bits, f(0.5 - root.to_double()).bits);
  EXPECT_EQ(ops.mul, 9u + 5u);  // three dot products, then the helper's 5 mul, 3 add, sqrt, div
  EXPECT_EQ(ops.add, 9u + 3u);
  EXPECT_EQ(ops.sqrt, 1u);
  EXPECT_EQ(ops.div, 1u);
  // eta*D + mu*N = (0.5, -0.5 + mu, 0) = (0.5, -root, 0): |(0.5, -1.3229)| = sqrt(2) = |D|, and
  // sin(theta_t) = 0.5 / sqrt(2) = eta * sin(45 degrees) (Snell).
  const Vec3<F> dir = transform_step(fp, tr, Vec3<F>{f(0.5), r.mu, f(0)}, false);
  expect_vec(dir, 0.5, -root.to_double(), 0, "refraction direction");
  // Leaving glass (eta = 1.5) at 45 degrees is beyond the critical angle (41.8 degrees): the
  // radicand (1 - 2.25)*2 + 2.25 = -0.25 is negative, total internal reflection.
  EXPECT_TRUE(refraction_factor(fp, f(1.5), f(-1), f(2), f(1)).total);
  // eta = 1 (no change of medium) leaves the direction alone: mu = (c - sqrt(c^2)) / N.N = 0.
  const RefractionFactor<F> same = refraction_factor(fp, f(1), f(-1), f(2), f(1));
  EXPECT_FALSE(same.total);
  expect_vec(transform_step(fp, tr, Vec3<F>{f(1), same.mu, f(0)}, false), 1, -1, 0, "eta = 1");
}

using V64 = std::array<double, 3>;
V64 cross64(const V64& a, const V64& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot64(const V64& a, const V64& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
V64 values(const Vec3<F>& v) {
  return {v[0].to_double(), v[1].to_double(), v[2].to_double()};
}

// Worst deviations of the refracted directions from Snell's law, the plane of incidence and |D|.
struct SnellWorst {
  int refracted = 0, total = 0;
  double snell = 0.0, plane = 0.0, length = 0.0;
};

// One refraction: total internal reflection exactly when eta sin(theta_i) > 1; otherwise the
// direction's deviations, weighted near the critical angle (where the square root amplifies the
// radicand's rounding) by cos(theta_t) / 0.01. fp24 rounds at 2^-17 = 7.6e-6.
void check_refraction(const UnitFp<F>& fp, const Vec3<F>& d, const Vec3<F>& n, F eta,
                      SnellWorst& w) {
  const V64 D = values(d), N = values(n);
  const double dd = dot64(D, D), nn = dot64(N, N);
  const double cos_i = -dot64(N, D) / std::sqrt(dd * nn);
  if (!(cos_i > 1e-3)) return;  // (nearly) grazing or degenerate: no meaningful angle
  const double sin_i = std::sqrt(std::max(0.0, 1.0 - cos_i * cos_i));
  const RefractionFactor<F> r =
      refraction_factor(fp, eta, dot_step(fp, n, d), dot_step(fp, d, d), dot_step(fp, n, n));
  const double want = eta.to_double() * sin_i;  // sin(theta_t)
  if (std::abs(want - 1.0) < 1e-3) return;      // at the critical angle either answer is right
  ASSERT_EQ(r.total, want > 1.0) << "eta " << eta.to_double() << " sin_i " << sin_i;
  ++(r.total ? w.total : w.refracted);
  if (r.total) return;
  Mat34<F> tr{};
  for (int i = 0; i < 3; ++i)
    tr[i] = {d[i], n[i], d[i], F::zero()};
  const V64 T = values(transform_step(fp, tr, Vec3<F>{eta, r.mu, f(0)}, false));
  const double tt = dot64(T, T);
  const V64 tn = cross64(T, N), pn = cross64(D, N);
  const double weight = std::min(1.0, std::sqrt(std::max(0.0, 1.0 - want * want)) / 1e-2);
  const double snell = std::abs(std::sqrt(dot64(tn, tn) / (tt * nn)) - want) * weight;
  const double plane = std::abs(dot64(T, pn)) / std::sqrt(tt * dot64(pn, pn));  // T . (D x N)
  const double length = std::abs(std::sqrt(tt / dd) - 1.0) * weight;
  EXPECT_LT(snell, 2e-4) << "eta " << eta.to_double() << " sin_i " << sin_i;
  EXPECT_LT(plane, 1e-4);
  EXPECT_LT(length, 2e-4);
  EXPECT_LT(dot64(T, N), 0.0) << "the refracted ray crosses the surface";
  w.snell = std::max(w.snell, snell);
  w.plane = std::max(w.plane, plane);
  w.length = std::max(w.length, length);
}

// Snell's law in fp24: for random unnormalised D and N (N facing the ray) and eta in [0.4, 2.5],
// the refracted direction T = eta*D + mu*N satisfies sin(theta_t) = eta * sin(theta_i), lies in the
// plane of D and N, goes through the surface (T.N < 0) and has the length of D; total internal
// reflection is reported exactly when eta * sin(theta_i) > 1 (checked away from the boundary).
TEST(Refraction, SnellsLawInFp24) {
  UnitFp<F> fp;
  std::mt19937_64 rng(0x5E11u);
  std::uniform_real_distribution<double> u(-1.0, 1.0), len(-3.0, 3.0), eta_d(0.4, 2.5);
  SnellWorst w;
  for (int k = 0; k < 20000; ++k) {
    const double sd = std::exp2(len(rng)), sn = std::exp2(len(rng));
    const Vec3<F> d{f(u(rng) * sd), f(u(rng) * sd), f(u(rng) * sd)};
    Vec3<F> n{f(u(rng) * sn), f(u(rng) * sn), f(u(rng) * sn)};
    const F eta = f(eta_d(rng));
    if (!is_neg_nonzero(dot_step(fp, n, d))) {  // the RGS turns the normal to face the ray
      for (F& x : n)
        x = x.neg();
    }
    check_refraction(fp, d, n, eta, w);
    if (::testing::Test::HasFatalFailure()) return;
  }
  EXPECT_GT(w.refracted, 5000);
  EXPECT_GT(w.total, 1000);
  std::printf(
      "[ snell    ] fp24: %d refracted, %d totally reflected; worst |sin_t - eta sin_i| %.2g, "
      "out of plane %.2g, |T|/|D| - 1 %.2g\n",
      w.refracted, w.total, w.snell, w.plane, w.length);
}

TEST(TraversalLane, BothChildrenSplitTheSegmentAtD) {
  ff::OpCounts ops;
  UnitFp<F> fp({}, &ops);
  const TraversalLane<F> r = traversal_lane(fp, f(2), f(0), f(1), f(0), f(10));
  EXPECT_TRUE(r.go_near);
  EXPECT_TRUE(r.go_far);
  EXPECT_EQ(r.near_tf.bits, f(2).bits);
  EXPECT_EQ(r.far_tn.bits, f(2).bits);
  EXPECT_EQ(ops.add, 1u);
  EXPECT_EQ(ops.div, 1u);
  EXPECT_EQ(ops.cmp, 2u);
}

TEST(TraversalLane, OneSideAndRounding) {
  UnitFp<F> fp;
  // Plane behind the segment start (d = -3 < tn): far child only.
  TraversalLane<F> r = traversal_lane(fp, f(2), f(5), f(1), f(0), f(10));
  EXPECT_FALSE(r.go_near);
  EXPECT_TRUE(r.go_far);
  EXPECT_EQ(r.far_tn.bits, f(0).bits);  // unchanged start
  // Plane beyond the segment end (d = 20 > tf): near child only.
  r = traversal_lane(fp, f(20), f(0), f(1), f(0), f(10));
  EXPECT_TRUE(r.go_near);
  EXPECT_FALSE(r.go_far);
  EXPECT_EQ(r.near_tf.bits, f(10).bits);
  // d = 1/3 rounded to 17 significant bits: 1.0101010101010101|01.. x 2^-2 rounds down.
  r = traversal_lane(fp, f(1), f(0), f(3), f(0), f(10));
  EXPECT_EQ(r.near_tf.bits, 0x3D5555u);
  // Direction parallel to the plane, origin on it: 0/0 = NaN, both children keep [tn, tf].
  r = traversal_lane(fp, f(2), f(2), f(0), f(1), f(4));
  EXPECT_TRUE(r.go_near && r.go_far);
  EXPECT_EQ(r.near_tf.bits, f(4).bits);
  EXPECT_EQ(r.far_tn.bits, f(1).bits);
  // Parallel, origin below the plane: d = +inf, near only.
  r = traversal_lane(fp, f(2), f(1), f(0), f(1), f(4));
  EXPECT_TRUE(r.go_near);
  EXPECT_FALSE(r.go_far);
  // Early termination: only a segment starting strictly beyond the closest hit is dropped.
  EXPECT_TRUE(terminated(fp, f(1), f(2)));
  EXPECT_FALSE(terminated(fp, f(2), f(2)));
}

TEST(ClipFace, EntryRaisesStartExitLowersEnd) {
  ff::OpCounts ops;
  UnitFp<F> fp({}, &ops);
  F tn = f(0), tf = F::infinity();
  clip_face(fp, f(1), f(-1), f(2), true, tn, tf);   // (1 - -1) / 2 = 1
  clip_face(fp, f(5), f(-1), f(2), false, tn, tf);  // (5 + 1) / 2 = 3
  EXPECT_EQ(tn.bits, f(1).bits);
  EXPECT_EQ(tf.bits, f(3).bits);
  EXPECT_EQ(ops.add, 2u);
  EXPECT_EQ(ops.div, 2u);
  EXPECT_EQ(ops.cmp, 2u);
  // Origin on a face of a parallel slab: NaN keeps the old bounds.
  clip_face(fp, f(1), f(1), f(0), true, tn, tf);
  EXPECT_EQ(tn.bits, f(1).bits);
}

Ray<F> unit_ray(double ox, double oy, double oz, double dx, double dy, double dz) {
  return {{f(ox), f(oy), f(oz)}, {f(dx), f(dy), f(dz)}};
}

TEST(Intersection, HitMissEdge) {
  ff::OpCounts ops;
  UnitFp<F> fp({}, &ops);
  Candidate<F> c = intersect_unit_triangle(fp, unit_ray(0.25, 0.125, 2, 0.5, 0.25, -4));
  // t = 2/4 = 0.5, u = 0.25 + 0.25 = 0.5, v = 0.125 + 0.125 = 0.25.
  EXPECT_TRUE(c.inside);
  EXPECT_EQ(c.t.bits, f(0.5).bits);
  EXPECT_EQ(c.u.bits, f(0.5).bits);
  EXPECT_EQ(c.v.bits, f(0.25).bits);
  EXPECT_EQ(c.c.bits, f(-4).bits);
  EXPECT_EQ(ops.add, 3u);
  EXPECT_EQ(ops.mul, 2u);
  EXPECT_EQ(ops.div, 1u);
  EXPECT_EQ(ops.cmp, 0u);  // acceptance is bit tests and magnitude compares (D13)
  // u + v = 1.5: outside.
  EXPECT_FALSE(intersect_unit_triangle(fp, unit_ray(0.75, 0.75, 1, 0, 0, -1)).inside);
  // Edge u + v = 1 and vertex u = 0: inside (edges inclusive).
  EXPECT_TRUE(intersect_unit_triangle(fp, unit_ray(0.5, 0.5, 1, 0, 0, -1)).inside);
  EXPECT_TRUE(intersect_unit_triangle(fp, unit_ray(0, 0, 1, 0, 0, -1)).inside);
  // u + v one ulp of 1 above 1: outside. Half an ulp above rounds (ties to even) back to 1 in
  // the third adder: inside, a precision effect of the format.
  EXPECT_FALSE(
      intersect_unit_triangle(fp, unit_ray(0.5, 0.5 + std::ldexp(1.0, -16), 1, 0, 0, -1)).inside);
  EXPECT_TRUE(
      intersect_unit_triangle(fp, unit_ray(0.5, 0.5 + std::ldexp(1.0, -17), 1, 0, 0, -1)).inside);
  // u one ulp below zero.
  EXPECT_FALSE(
      intersect_unit_triangle(fp, unit_ray(-std::ldexp(1.0, -30), 0.5, 1, 0, 0, -1)).inside);
  // Behind the origin (t = -1), parallel (D'z = 0), and t = 0 are misses.
  EXPECT_FALSE(intersect_unit_triangle(fp, unit_ray(0.25, 0.25, -1, 0, 0, -1)).inside);
  EXPECT_FALSE(intersect_unit_triangle(fp, unit_ray(0.25, 0.25, 1, 0, 0, 0)).inside);
  EXPECT_FALSE(intersect_unit_triangle(fp, unit_ray(0.25, 0.25, 0, 0, 0, -1)).inside);
  // -0 counts as 0 for u: t * D'x = 1 * -0.
  EXPECT_TRUE(intersect_unit_triangle(fp, unit_ray(-0.0, 0.5, 1, -0.0, 0, -1)).inside);
}

TEST(Intersection, TieRuleSmallerInstanceThenTriangle) {
  UnitFp<F> fp;
  const Candidate<F> c = intersect_unit_triangle(fp, unit_ray(0.25, 0.25, 1, 0, 0, -1));
  HitRecord<F> best;
  EXPECT_TRUE(accepts(c, 5, 9, best));  // anything beats no hit
  best.t = f(1);
  best.instance = 5;
  best.triangle = 9;
  EXPECT_TRUE(accepts(c, 4, 100, best));  // equal t, smaller instance
  EXPECT_TRUE(accepts(c, 5, 8, best));    // equal t, same instance, smaller triangle
  EXPECT_FALSE(accepts(c, 5, 9, best));   // the same triangle again changes nothing
  EXPECT_FALSE(accepts(c, 5, 10, best));
  EXPECT_FALSE(accepts(c, 6, 0, best));
  best.t = F::from_bits(f(1).bits + 1);  // one ulp further: any instance wins
  EXPECT_TRUE(accepts(c, 99, 99, best));
  best.t = F::from_bits(f(1).bits - 1);  // one ulp nearer: nothing wins
  EXPECT_FALSE(accepts(c, 0, 0, best));
}

TEST(Mailbox, SkipsVisitedRaysOnlyAndEvictsOldest) {
  Mailbox mb(2);
  EXPECT_EQ(mb.filter(5, 0b0011), 0b0011u);
  EXPECT_EQ(mb.filter(5, 0b0110), 0b0100u);  // ray 1 visited 5 already
  EXPECT_EQ(mb.filter(5, 0b0111), 0u);       // skip: every ray visited it
  EXPECT_EQ(mb.filter(7, 0b0001), 0b0001u);
  EXPECT_EQ(mb.filter(9, 0b0001), 0b0001u);  // evicts 5 (oldest)
  EXPECT_EQ(mb.filter(7, 0b0001), 0u);
  EXPECT_EQ(mb.filter(5, 0b0001), 0b0001u);  // a revisit after eviction
  mb.clear();
  EXPECT_EQ(mb.filter(9, 0b0001), 0b0001u);
  Mailbox off(0);
  EXPECT_EQ(off.filter(1, 3), 3u);
  EXPECT_EQ(off.filter(1, 3), 3u);
}

// ---- the binary64 paths against the encoding paths -------------------------------------------

// Operands: mostly values of moderate size (the common case the binary64 paths decide), plus
// zeros, subnormals, the extremes of the range, inf and NaN (which they must hand back).
template <class G>
std::uint32_t operand(std::mt19937_64& rng) {
  const auto u = rng();
  const std::uint32_t sign = (u & 1u) != 0 ? G::kFormat.sign_mask() : 0u;
  const std::uint32_t man = static_cast<std::uint32_t>(u >> 8) & G::kFormat.man_mask();
  const auto bias = static_cast<std::uint32_t>(G::kFormat.bias());
  switch ((u >> 1) % 16) {
    case 0:
      return sign;  // +-0
    case 1:
      return sign | (man == 0 ? 1u : man);  // subnormal
    case 2:
      return sign | G::kFormat.inf_bits();
    case 3:
      return G::kFormat.nan_bits();
    case 4:  // near the top of the range
      return sign |
             ((G::kFormat.exp_field_max() - 1u - static_cast<std::uint32_t>((u >> 40) % 4))
              << G::kManBits) |
             man;
    case 5:  // near the bottom
      return sign | ((1u + static_cast<std::uint32_t>((u >> 40) % 4)) << G::kManBits) | man;
    case 6:  // wide
      return sign |
             ((1u + static_cast<std::uint32_t>((u >> 40) % (G::kFormat.exp_field_max() - 1u)))
              << G::kManBits) |
             man;
    default:  // moderate: 2^-12 .. 2^12
      return sign | ((bias - 12u + static_cast<std::uint32_t>((u >> 40) % 25)) << G::kManBits) |
             man;
  }
}

// One random traversal lane and its two clip faces: where the binary64 path decides, it equals
// the encoding path. Returns whether the traversal lane was decided there.
template <class G>
bool check_traversal_and_clip_case(const RawFp<G, false>& fp, ff::Mode mode, std::mt19937_64& rng) {
  const auto op = [&] { return G::from_bits(operand<G>(rng)); };
  const auto value = [&](G x) { return value_of(x, mode.subnormals); };
  // Traversal lane: the segment bounds are values of encodings, never NaN (tf may be inf).
  const G split = op(), o = op(), d = op();
  G tn = op(), tf = op();
  if (bits_nan(tn)) tn = G::zero();
  if (bits_nan(tf)) tf = G::infinity();
  TraversalLane64 r64;
  const double inv = traversal_reciprocal(fp, d);
  const bool decided = traversal_lane64<G>(value(split), value(o), inv, value(tn), value(tf), r64);
  if (decided) {
    const TraversalLane<G> r = traversal_lane(fp, split, o, d, tn, tf);
    EXPECT_EQ(r64.go_near, r.go_near) << split.bits << " " << o.bits << " " << d.bits;
    EXPECT_EQ(r64.go_far, r.go_far) << split.bits << " " << o.bits << " " << d.bits;
    // The model keeps segment bounds as values (a subnormal reads as +-0 in flush mode).
    const auto same = [&](double v, G e) {
      return v == value(e) && std::signbit(v) == std::signbit(value(e));
    };
    EXPECT_TRUE(same(r64.near_tf, r.near_tf) && same(r64.far_tn, r.far_tn))
        << ff::format_name(G::kFormat) << " keep=" << (mode.subnormals == ff::Subnormals::kKeep)
        << " split " << split.bits << " o " << o.bits << " d " << d.bits << " tn " << tn.bits
        << " tf " << tf.bits;
  }
  for (const bool entry : {true, false}) {
    double tn64 = value(tn), tf64 = value(tf);
    G tn_e = tn, tf_e = tf;
    if (clip_face64<G>(value(split), value(o), inv, entry, tn64, tf64)) {
      clip_face(fp, split, o, d, entry, tn_e, tf_e);
      EXPECT_EQ(tn64, value(tn_e));
      EXPECT_EQ(tf64, value(tf_e));
      EXPECT_EQ(std::signbit(tn64), std::signbit(value(tn_e)));
      EXPECT_EQ(std::signbit(tf64), std::signbit(value(tf_e)));
    }
  }
  return decided;
}

// One random transformation step, mostly on moderate operands so that many are decided on
// values: where transform_step64 decides, it equals transform_step. Returns the steps decided.
template <class G>
int check_transform_case(const RawFp<G, false>& fp, ff::Mode mode, std::mt19937_64& rng) {
  const auto op_t = [&] {
    const G x = G::from_bits(operand<G>(rng));
    const std::uint32_t e = (x.bits >> G::kManBits) & G::kFormat.exp_field_max();
    const int u = static_cast<int>(e) - G::kFormat.bias();
    return (rng() % 16) == 0 || bits_zero(x) || (u >= -20 && u <= 20)
               ? x
               : G::from_bits(G::one().bits | (x.bits & G::kFormat.man_mask()) |
                              (x.bits & G::kFormat.sign_mask()));
  };
  Mat34<G> m;
  for (auto& row : m)
    for (auto& x : row)
      x = op_t();
  const Vec3<G> v{op_t(), op_t(), op_t()};
  MatrixValues<G> mv = matrix_values(m, mode.subnormals);
  int decided = 0;
  for (const bool translate : {true, false}) {
    Vec3<G> out;
    if (transform_step64<G>(mv, v, translate, out)) {
      ++decided;
      const Vec3<G> want = transform_step(fp, m, v, translate);
      for (int k = 0; k < 3; ++k)
        EXPECT_EQ(out[k].bits, want[k].bits) << "row " << k;
    }
  }
  return decided;
}

template <class G>
void check_binary64_paths(ff::Mode mode, int n) {
  const RawFp<G, false> fp(mode);
  std::mt19937_64 rng(2024);
  int decided = 0, transforms = 0;
  for (int it = 0; it < n && !::testing::Test::HasFailure(); ++it) {
    decided += check_traversal_and_clip_case<G>(fp, mode, rng) ? 1 : 0;
    transforms += check_transform_case<G>(fp, mode, rng);
  }
  EXPECT_GT(decided, n / 4);  // the binary64 paths decide the common case
  EXPECT_GT(transforms, n / 4);
}

// The formats the value paths serve, each run through `check(FormatTag<G>{}, mode, count)`: fp24
// with `n` random cases, the others with n / 4; in every rounding and subnormal mode listed. The
// sanitizer build runs a twentieth of `n`.
template <class G>
struct FormatTag {
  using type = G;
};
template <class Check>
void over_formats(std::initializer_list<ff::Rounding> roundings, int n, const Check& check) {
#if defined(SAARCOR_SANITIZED)
  n /= 20;
#endif
  for (const ff::Rounding r : roundings)
    for (const ff::Subnormals s : {ff::Subnormals::kFlush, ff::Subnormals::kKeep}) {
      const ff::Mode mode{r, s};
      check(FormatTag<ff::fp24>{}, mode, n);
      check(FormatTag<ff::Float<7, 23>>{}, mode, n / 4);
      check(FormatTag<ff::Float<8, 23>>{}, mode, n / 4);
      check(FormatTag<ff::Float<7, 10>>{}, mode, n / 4);
    }
}

TEST(Binary64Paths, AgreeWithTheEncodingPaths) {
  over_formats({ff::Rounding::kNearestEven}, 400'000, [](auto format, ff::Mode mode, int n) {
    check_binary64_paths<typename decltype(format)::type>(mode, n);
  });
}

inline bool same_double(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

// round_to_format2 on arbitrary binary64 patterns (specials included) and on values near F's
// range limits, against round_to_format lane by lane.
template <class G>
void check_round_pair_case(std::mt19937_64& rng) {
  std::array<double, 2> x;
  for (auto& v : x) {
    const std::uint64_t r = rng();
    v = (r & 3u) == 0 ? std::bit_cast<double>(rng())
                      : std::ldexp(std::bit_cast<double>((r >> 12) | 0x3FF0000000000000ull),
                                   static_cast<int>(rng() % 8) - 4 +
                                       ((r & 4u) != 0 ? G::kFormat.emin() : G::kFormat.emax()));
  }
  V2i ok = {-1, -1};
  const V2d r = round_to_format2<G>(V2d{x[0], x[1]}, ok);
  for (int k = 0; k < 2; ++k) {
    bool ok1 = true;
    const double r1 = round_to_format<G>(x[static_cast<std::size_t>(k)], ok1);
    EXPECT_EQ(ok[k] != 0, ok1) << x[static_cast<std::size_t>(k)];
    EXPECT_TRUE(!ok1 || same_double(r[k], r1));
  }
}

// Traversal and clip on two lanes against the one-lane forms. Returns the lanes decided.
template <class G>
int check_traversal_pair_case(const RawFp<G, false>& fp, ff::Mode mode, std::mt19937_64& rng) {
  const auto op = [&] { return G::from_bits(operand<G>(rng)); };
  const auto value = [&](G x) { return value_of(x, mode.subnormals); };
  std::array<double, 2> split, o, inv, tn, tf;
  for (std::size_t k = 0; k < 2; ++k) {
    split[k] = value(op());
    o[k] = value(op());
    inv[k] = traversal_reciprocal(fp, op());
    G a = op(), b = op();
    if (bits_nan(a)) a = G::zero();
    if (bits_nan(b)) b = G::infinity();
    tn[k] = value(a);
    tf[k] = value(b);
  }
  const auto v2 = [](const std::array<double, 2>& a) { return V2d{a[0], a[1]}; };
  const TraversalPair64 p = traversal_pair64<G>(v2(split), v2(o), v2(inv), v2(tn), v2(tf));
  int decided_lanes = 0;
  for (std::size_t k = 0; k < 2; ++k) {
    TraversalLane64 r1;
    const bool decided = traversal_lane64<G>(split[k], o[k], inv[k], tn[k], tf[k], r1);
    EXPECT_EQ(((p.fail >> k) & 1u) == 0, decided);
    if (!decided) continue;
    ++decided_lanes;
    EXPECT_EQ(((p.go_near >> k) & 1u) != 0, r1.go_near);
    EXPECT_EQ(((p.go_far >> k) & 1u) != 0, r1.go_far);
    EXPECT_TRUE(same_double(p.near_tf[static_cast<int>(k)], r1.near_tf));
    EXPECT_TRUE(same_double(p.far_tn[static_cast<int>(k)], r1.far_tn));
  }
  for (const bool entry : {true, false}) {
    V2d tn2 = v2(tn), tf2 = v2(tf);
    V2i ok2 = {-1, -1};
    clip_face_pair64<G>(v2(split), v2(o), v2(inv), entry, tn2, tf2, ok2);
    for (std::size_t k = 0; k < 2; ++k) {
      double tn1 = tn[k], tf1 = tf[k];
      const bool decided = clip_face64<G>(split[k], o[k], inv[k], entry, tn1, tf1);
      EXPECT_EQ(ok2[static_cast<int>(k)] != 0, decided);
      EXPECT_TRUE(!decided || (same_double(tn2[static_cast<int>(k)], tn1) &&
                               same_double(tf2[static_cast<int>(k)], tf1)));
    }
  }
  return decided_lanes;
}

// Decode, encode and the transformation step on two lanes. Returns the lane steps decided.
template <class G>
int check_transform_pair_case(const RawFp<G, false>& fp, ff::Mode mode, std::mt19937_64& rng) {
  const auto op = [&] { return G::from_bits(operand<G>(rng)); };
  const auto value = [&](G x) { return value_of(x, mode.subnormals); };
  Mat34<G> m;
  for (auto& row : m)
    for (auto& e : row)
      e = G::from_bits(G::one().bits ^
                       (static_cast<std::uint32_t>(rng()) &
                        (G::kFormat.man_mask() | G::kFormat.sign_mask() | (7u << G::kManBits))));
  const MatrixValues<G> mv = matrix_values(m, mode.subnormals);
  std::array<Vec3<G>, 2> v;
  for (auto& vec : v)
    for (auto& c : vec)
      c = op();
  for (int c = 0; c < 3; ++c) {
    const V2d d = decode_pair<G>(v[0][c].bits, v[1][c].bits);
    const V2u e = encode_pair<G>(d);
    for (int k = 0; k < 2; ++k) {
      const G x1 = v[static_cast<std::size_t>(k)][c];
      if (!bits_zero(x1) && !ff::fast::is_normal<G::kExpBits, G::kManBits>(x1.bits)) continue;
      EXPECT_TRUE(same_double(d[k], value(x1))) << x1.bits;
      EXPECT_EQ(static_cast<std::uint32_t>(e[k]), x1.bits);
    }
  }
  int transforms = 0;
  for (const bool translate : {true, false}) {
    const V2d xs[3] = {decode_pair<G>(v[0][0].bits, v[1][0].bits),
                       decode_pair<G>(v[0][1].bits, v[1][1].bits),
                       decode_pair<G>(v[0][2].bits, v[1][2].bits)};
    V2u out[3];
    transform_pair64<G>(mv, xs, translate, out);
    for (int k = 0; k < 2; ++k) {
      if (!transform_decides<G>(mv, v[static_cast<std::size_t>(k)], translate)) continue;
      ++transforms;
      const Vec3<G> want = transform_step(fp, m, v[static_cast<std::size_t>(k)], translate);
      const Vec3<G> got = lane_of<G>(out, k);
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(got[c].bits, want[c].bits);
    }
  }
  return transforms;
}

// The two-lane forms (thread program) against the one-lane value paths, lane by lane.
template <class G>
void check_pair_paths(ff::Mode mode, int n) {
  std::mt19937_64 rng(77);
  const RawFp<G, false> fp(mode);
  int decided_lanes = 0, transforms = 0;
  for (int it = 0; it < n && !::testing::Test::HasFailure(); ++it) {
    check_round_pair_case<G>(rng);
    decided_lanes += check_traversal_pair_case<G>(fp, mode, rng);
    transforms += check_transform_pair_case<G>(fp, mode, rng);
  }
  EXPECT_GT(decided_lanes, n / 4);  // the value paths decide the common case
  EXPECT_GT(transforms, n / 8);
}

TEST(Binary64Paths, PairFormsAgreeWithOneLane) {
  over_formats({ff::Rounding::kNearestEven}, 200'000, [](auto format, ff::Mode mode, int n) {
    check_pair_paths<typename decltype(format)::type>(mode, n);
  });
}

// dot_step64 (the RGS's dot products and direction steps) against dot_step on encodings: random
// operands of every class, mostly moderate ones (decided), and exponents at the limits of its
// condition. Where it decides, the encoding and the sign of a zero must agree; truncation never
// decides.
template <class G>
void check_dot_paths(ff::Mode mode, int n) {
  std::mt19937_64 rng(99);
  const RawFp<G> fp(mode);
  const bool nearest = mode.rounding == ff::Rounding::kNearestEven;
  const auto op = [&] { return G::from_bits(operand<G>(rng)); };
  // Nonzero normal operands with unbiased exponents in [lo, hi] (zero one time in eight).
  const auto in_range = [&](int lo, int hi) {
    const auto u = rng();
    if (u % 8 == 0) return G::from_bits((u & 8u) != 0 ? G::kFormat.sign_mask() : 0u);
    const int e = lo + static_cast<int>((u >> 4) % static_cast<std::uint64_t>(hi - lo + 1));
    return G::from_bits(((u & 8u) != 0 ? G::kFormat.sign_mask() : 0u) |
                        (static_cast<std::uint32_t>(e + G::kFormat.bias()) << G::kManBits) |
                        (static_cast<std::uint32_t>(u >> 20) & G::kFormat.man_mask()));
  };
  const int emin = G::kFormat.emin(), emax = G::kFormat.emax(), m = G::kManBits;
  int decided = 0, edge = 0;
  for (int it = 0; it < n; ++it) {
    Vec3<G> a, b;
    switch (it % 4) {
      case 0:  // every class
        a = {op(), op(), op()};
        b = {op(), op(), op()};
        break;
      case 1:  // moderate
        a = {in_range(-12, 12), in_range(-12, 12), in_range(-12, 12)};
        b = {in_range(-12, 12), in_range(-12, 12), in_range(-12, 12)};
        break;
      case 2: {  // near the low limit L = la + lb - M = emin (and one below it)
        const int l = (emin + m) / 2 - static_cast<int>(rng() % 2);
        a = {in_range(l, l + 3), in_range(l, l + 3), in_range(l, l + 3)};
        b = {in_range(emin + m - l - 1, emin + m - l + 2), in_range(emin + m - l, emin + m - l + 2),
             in_range(emin + m - l, emin + m - l + 2)};
        break;
      }
      default: {  // near the high limit ha + hb + 4 = emax (and one above it)
        const int h = (emax - 4) / 2;
        a = {in_range(h - 3, h), in_range(h - 3, h), in_range(h - 3, h + 1)};
        b = {in_range(emax - 4 - h - 3, emax - 4 - h), in_range(emax - 4 - h - 3, emax - 4 - h),
             in_range(emax - 4 - h - 3, emax - 4 - h + 1)};
        break;
      }
    }
    const G want = dot_step(fp, a, b);
    G got;
    if (!dot_step64<G>(a, b, nearest, got)) continue;
    ASSERT_TRUE(nearest);
    ++decided;
    edge += it % 4 >= 2;
    ASSERT_EQ(got.bits, want.bits)
        << ff::format_name(G::kFormat) << " a " << a[0].bits << " " << a[1].bits << " " << a[2].bits
        << " b " << b[0].bits << " " << b[1].bits << " " << b[2].bits;
    // A direction step's row is the same expression (the thread program's direction steps).
    const Mat34<G> mat = {
        {{a[0], a[1], a[2], op()}, {b[0], b[1], b[2], op()}, {a[2], b[0], a[1], op()}}};
    ASSERT_EQ(transform_step(fp, mat, b, false)[0].bits, want.bits);
  }
  if (nearest) {
    EXPECT_GT(decided, n / 4);
    EXPECT_GT(edge, n / 20);
  }
}

TEST(Binary64Paths, DotStepAgreesWithTheEncodingPath) {
  over_formats({ff::Rounding::kNearestEven, ff::Rounding::kTowardZero}, 400'000,
               [](auto format, ff::Mode mode, int n) {
                 check_dot_paths<typename decltype(format)::type>(mode, n);
               });
}

TEST(Binary64Paths, DotStepEdgeCases) {
  const UnitFp<F> fp;
  const auto dot64 = [](const Vec3<F>& a, const Vec3<F>& b, bool nearest = true) {
    F r;
    EXPECT_TRUE(dot_step64<F>(a, b, nearest, r));
    return r.bits;
  };
  const auto refused = [](const Vec3<F>& a, const Vec3<F>& b, bool nearest = true) {
    F r;
    return !dot_step64<F>(a, b, nearest, r);
  };
  // Signed zeros: (-0 + -0) + (-0 + +0) = +0, as on the encodings; all-zero vectors decide.
  const Vec3<F> nz = v3(-0.0, -0.0, -0.0), pos = v3(1, 2, 3);
  EXPECT_EQ(dot64(nz, pos), dot_step(fp, nz, pos).bits);
  EXPECT_EQ(dot64(nz, pos), 0u);
  EXPECT_EQ(dot64(nz, nz), 0u);
  // Exact cancellation gives +0; the tie of 1 + 2^-17 rounds to even, as in transform_step.
  EXPECT_EQ(dot64(v3(3, -3, 0), v3(5, 5, 7)), 0u);
  const double e = std::ldexp(1.0, -17);
  EXPECT_EQ(dot64(v3(1, e, e), v3(1, 1, 1)), f(1).bits);
  EXPECT_EQ(dot64(v3(1, 2, 3), v3(4, 5, 6)), f(32).bits);
  // Limits of the condition for fp24 (emin = -62, emax = 63, M = 16): la + lb - 16 >= -62 and
  // ha + hb + 4 <= 63.
  const auto p2 = [](int k) { return F::from_double(std::ldexp(1.0, k)); };
  const Vec3<F> one{p2(0), p2(0), p2(0)};
  EXPECT_FALSE(refused(Vec3<F>{p2(-23), p2(0), p2(0)}, Vec3<F>{p2(-23), p2(0), p2(0)}));
  EXPECT_TRUE(refused(Vec3<F>{p2(-24), p2(0), p2(0)}, Vec3<F>{p2(-23), p2(0), p2(0)}));
  EXPECT_FALSE(refused(Vec3<F>{p2(29), p2(0), p2(0)}, Vec3<F>{p2(30), p2(0), p2(0)}));
  EXPECT_TRUE(refused(Vec3<F>{p2(30), p2(0), p2(0)}, Vec3<F>{p2(30), p2(0), p2(0)}));
  // Near overflow: the largest finite values would overflow (the encoding path gives inf).
  const F big = F::from_bits(F::kFormat.inf_bits() - 1u);
  EXPECT_TRUE(refused(Vec3<F>{big, big, big}, one));
  EXPECT_TRUE(bits_inf(dot_step(fp, Vec3<F>{big, big, big}, Vec3<F>{big, big, big})));
  // Subnormal, inf and NaN operands, and truncation, are left to the encoding path.
  EXPECT_TRUE(refused(Vec3<F>{F::from_bits(1u), p2(0), p2(0)}, one));
  EXPECT_TRUE(refused(Vec3<F>{F::infinity(), p2(0), p2(0)}, one));
  EXPECT_TRUE(refused(Vec3<F>{F::from_bits(F::kFormat.nan_bits()), p2(0), p2(0)}, one));
  EXPECT_TRUE(refused(pos, pos, false));
}

// Truncation: the binary64 traversal path never decides (1/D is NaN).
TEST(Binary64Paths, TruncationAlwaysFallsBack) {
  const RawFp<F> fp({ff::Rounding::kTowardZero, ff::Subnormals::kFlush});
  TraversalLane64 r;
  EXPECT_FALSE(traversal_lane64<F>(1.0, 0.0, traversal_reciprocal(fp, f(2)), 0.0, 10.0, r));
  const RawFp<F> rne;
  EXPECT_TRUE(traversal_lane64<F>(1.0, 0.0, traversal_reciprocal(rne, f(2)), 0.0, 10.0, r));
  EXPECT_EQ(r.near_tf, 0.5);
}

}  // namespace
}  // namespace saarcor::units
