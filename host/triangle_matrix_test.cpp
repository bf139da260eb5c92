// T_delta (paper section 2.1.1 with the docs/memory-image.md erratum), instance matrices and the
// primary-ray basis (paper section 2.2.2, decision D8).
#include "host/triangle_matrix.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "fixedfloat/float.h"
#include "host/primary_rays.h"

namespace saarcor::host {
namespace {

#ifdef SAARCOR_SANITIZED
constexpr int kStride = 40;  // bunny triangles checked in fp24: every 40th
constexpr int kRandom = 2000;
#else
constexpr int kStride = 1;
constexpr int kRandom = 50000;
#endif

struct Tri {
  glm::vec3 a, b, c;
};

// Largest |result - expected| over the four mapped points, relative to the magnitude of the
// terms summed in each row (what binary64 rounding errors scale with).
double max_rel_error64(const Affine64& m, const Tri& t) {
  const glm::dvec3 a(t.a), b(t.b), c(t.c);
  const glm::dvec3 n = glm::dvec3(m.rows[2][0], m.rows[2][1], m.rows[2][2]);
  const glm::dvec3 pts[4] = {a, b, c, c + n};
  const glm::dvec3 want[4] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {0, 0, 1}};
  double worst = 0.0;
  for (int i = 0; i < 4; ++i) {
    const glm::dvec3 got = m.apply_point(pts[i]);
    for (int r = 0; r < 3; ++r) {
      const auto& row = m.rows[r];
      const double scale = std::abs(row[0] * pts[i].x) + std::abs(row[1] * pts[i].y) +
                           std::abs(row[2] * pts[i].z) + std::abs(row[3]) + 1.0;
      worst = std::max(worst, std::abs(got[r] - want[i][r]) / scale);
    }
  }
  return worst;
}

// Evaluates the rounded matrix with fp24 ops in the transformation unit's order
// (m0*x + m1*y) + (m2*z + t) on fp24-rounded inputs; returns the largest error relative to the
// row's term magnitudes, in units of fp24's relative precision 2^-16.
double max_error_fp24_ulps(const EncodedAffine& e, const Tri& t) {
  using ff::fp24;
  const ff::FpUnit<fp24> fpu;
  const glm::dvec3 a(t.a), b(t.b), c(t.c);
  glm::dvec3 n;
  for (int k = 0; k < 3; ++k)
    n[k] = fpu.to_double(fp24{e[2][k]});
  const glm::dvec3 pts[4] = {a, b, c, c + n};
  const glm::dvec3 want[4] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {0, 0, 1}};
  double worst = 0.0;
  for (int i = 0; i < 4; ++i) {
    const fp24 x = fpu.from_double(pts[i].x), y = fpu.from_double(pts[i].y),
               z = fpu.from_double(pts[i].z);
    for (int r = 0; r < 3; ++r) {
      const fp24 m0{e[r][0]}, m1{e[r][1]}, m2{e[r][2]}, tr{e[r][3]};
      const fp24 out =
          fpu.add(fpu.add(fpu.mul(m0, x), fpu.mul(m1, y)), fpu.add(fpu.mul(m2, z), tr));
      const double scale =
          std::abs(fpu.to_double(m0) * pts[i].x) + std::abs(fpu.to_double(m1) * pts[i].y) +
          std::abs(fpu.to_double(m2) * pts[i].z) + std::abs(fpu.to_double(tr)) + 1.0;
      worst = std::max(worst, std::abs(fpu.to_double(out) - want[i][r]) / scale / 0x1p-16);
    }
  }
  return worst;
}

std::vector<Tri> random_triangles(int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> centre(-100.0f, 100.0f);
  std::uniform_real_distribution<float> local(-1.0f, 1.0f);
  std::uniform_real_distribution<float> logsize(-3.0f, 2.0f);
  std::vector<Tri> out;
  while (static_cast<int>(out.size()) < n) {
    const glm::vec3 o(centre(rng), centre(rng), centre(rng));
    const float s = std::pow(10.0f, logsize(rng));
    Tri t{o + s * glm::vec3(local(rng), local(rng), local(rng)),
          o + s * glm::vec3(local(rng), local(rng), local(rng)),
          o + s * glm::vec3(local(rng), local(rng), local(rng))};
    // Keep reasonably shaped triangles: slivers are tested separately.
    const glm::dvec3 e0 = glm::dvec3(t.a - t.c), e1 = glm::dvec3(t.b - t.c);
    const double ratio = glm::length(glm::cross(e0, e1)) /
                         std::max({glm::dot(e0, e0), glm::dot(e1, e1),
                                   glm::dot(glm::dvec3(t.a - t.b), glm::dvec3(t.a - t.b))});
    if (ratio > 1e-3) out.push_back(t);
  }
  return out;
}

// The Stanford bunny (ASCII PLY in the shared scenes): 69,451 real triangles.
std::vector<Tri> bunny_triangles() {
  std::ifstream in(std::string(SAARCOR_SHARED_SCENES) + "/StanfordBunny/bun_zipper.ply");
  if (!in) return {};
  std::string line;
  int nv = 0, nf = 0;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string w1, w2;
    ls >> w1 >> w2;
    if (w1 == "element" && w2 == "vertex") ls >> nv;
    if (w1 == "element" && w2 == "face") ls >> nf;
    if (w1 == "end_header") break;
  }
  std::vector<glm::vec3> v(static_cast<std::size_t>(nv));
  for (auto& p : v) {
    float conf, inten;
    in >> p.x >> p.y >> p.z >> conf >> inten;
  }
  std::vector<Tri> out;
  for (int i = 0; i < nf; ++i) {
    int k, i0, i1, i2;
    in >> k >> i0 >> i1 >> i2;
    out.push_back({v[static_cast<std::size_t>(i0)], v[static_cast<std::size_t>(i1)],
                   v[static_cast<std::size_t>(i2)]});
  }
  return out;
}

TEST(TriangleMatrix, MapsVerticesToUnitTriangleExactlyInBinary64) {
  const Tri t{{2.0f, 0.5f, -1.0f}, {-0.5f, 3.0f, 0.25f}, {0.75f, -1.5f, 2.0f}};
  const auto m = triangle_matrix(t.a, t.b, t.c);
  ASSERT_TRUE(m.has_value());
  EXPECT_LT(max_rel_error64(*m, t), 1e-15);
  // Row 2 is the unit normal of (A-C) x (B-C).
  const glm::dvec3 cr = glm::cross(glm::dvec3(t.a - t.c), glm::dvec3(t.b - t.c));
  const glm::dvec3 n = cr / glm::length(cr);
  EXPECT_EQ(m->rows[2][0], n.x);
  EXPECT_EQ(m->rows[2][1], n.y);
  EXPECT_EQ(m->rows[2][2], n.z);
}

TEST(TriangleMatrix, AxisAlignedTriangleHasTheExpectedCoefficients) {
  // A = (3,1,5), B = (1,4,5), C = (1,1,5): e0 = (2,0,0), e1 = (0,3,0), N = (0,0,1);
  // T_delta(X) = ((x-1)/2, (y-1)/3, z-5).
  const auto m = triangle_matrix(glm::vec3(3, 1, 5), glm::vec3(1, 4, 5), glm::vec3(1, 1, 5));
  ASSERT_TRUE(m.has_value());
  const std::array<std::array<double, 4>, 3> want = {
      {{0.5, 0.0, 0.0, -0.5}, {0.0, 1.0 / 3.0, 0.0, -1.0 / 3.0}, {0.0, 0.0, 1.0, -5.0}}};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      EXPECT_DOUBLE_EQ(m->rows[r][c], want[r][c]) << r << "," << c;
  const auto e = encoded_triangle_matrix(glm::vec3(3, 1, 5), glm::vec3(1, 4, 5), glm::vec3(1, 1, 5),
                                         ff::kFp24);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ((*e)[0][0], ff::from_double(0.5, ff::kFp24, {}));
  EXPECT_EQ((*e)[1][1], ff::from_double(1.0 / 3.0, ff::kFp24, {}));
  EXPECT_EQ((*e)[2][3], ff::from_double(-5.0, ff::kFp24, {}));
}

TEST(TriangleMatrix, RandomTrianglesBinary64AndFp24) {
  const auto tris = random_triangles(kRandom, 20040801u);
  double worst64 = 0.0, worst24 = 0.0, worst_normal = 0.0;
  for (const Tri& t : tris) {
    const auto m = triangle_matrix(t.a, t.b, t.c);
    ASSERT_TRUE(m.has_value());
    worst64 = std::max(worst64, max_rel_error64(*m, t));
    const glm::dvec3 n(m->rows[2][0], m->rows[2][1], m->rows[2][2]);
    worst_normal = std::max(worst_normal, std::abs(glm::length(n) - 1.0));
    const auto e = encoded_triangle_matrix(t.a, t.b, t.c, ff::kFp24);
    ASSERT_TRUE(e.has_value());
    worst24 = std::max(worst24, max_error_fp24_ulps(*e, t));
  }
  RecordProperty("worst_fp24_ulps", std::to_string(worst24));
  RecordProperty("worst_binary64", std::to_string(worst64 * 1e15) + "e-15");
  EXPECT_LT(worst64, 1e-14);
  EXPECT_LT(worst_normal, 1e-15);
  // Coefficient, input, mul and add roundings of half an ulp each; measured 1.0 (1.3 bunny).
  EXPECT_LT(worst24, 2.5);
  EXPECT_GT(worst24, 0.01);  // the rounding is visible: the check measures something
}

TEST(TriangleMatrix, BunnyTrianglesBinary64AndFp24) {
  const auto tris = bunny_triangles();
  ASSERT_EQ(tris.size(), 69451u);
  int degenerate = 0, checked = 0;
  double worst64 = 0.0, worst24 = 0.0;
  for (std::size_t i = 0; i < tris.size(); ++i) {
    const Tri& t = tris[i];
    const auto m = triangle_matrix(t.a, t.b, t.c);
    if (!m) {
      ++degenerate;
      continue;
    }
    worst64 = std::max(worst64, max_rel_error64(*m, t));
    if (i % kStride != 0) continue;
    const auto e = encoded_triangle_matrix(t.a, t.b, t.c, ff::kFp24);
    ASSERT_TRUE(e.has_value());
    worst24 = std::max(worst24, max_error_fp24_ulps(*e, t));
    ++checked;
  }
  RecordProperty("worst_fp24_ulps", std::to_string(worst24));
  RecordProperty("worst_binary64", std::to_string(worst64 * 1e15) + "e-15");
  EXPECT_EQ(degenerate, 0);
  EXPECT_GT(checked, 1000);
  EXPECT_LT(worst64, 1e-14);
  EXPECT_LT(worst24, 2.5);
}

TEST(TriangleMatrix, DegenerateTrianglesGiveNullopt) {
  const glm::vec3 a(0, 0, 0), b(1, 1, 1), c(2, 2, 2);
  EXPECT_FALSE(triangle_matrix(a, b, c).has_value());  // collinear
  EXPECT_FALSE(triangle_matrix(a, a, b).has_value());  // repeated vertex
  EXPECT_FALSE(triangle_matrix(a, a, a).has_value());  // a point
  const float nan = std::nanf("");
  EXPECT_FALSE(triangle_matrix(glm::vec3(nan, 0, 0), b, glm::vec3(0, 1, 0)).has_value());
  // A sliver just above and just below the relative threshold (the threshold is scale-free).
  for (double scale : {1e-6, 1.0, 1e6}) {
    const glm::dvec3 p(0, 0, 0), q(scale, 0, 0);
    EXPECT_TRUE(triangle_matrix(p, q, glm::dvec3(0.5 * scale, 1e-11 * scale, 0)).has_value());
    EXPECT_FALSE(triangle_matrix(p, q, glm::dvec3(0.5 * scale, 1e-13 * scale, 0)).has_value());
  }
  // Valid in binary64 but 1/height overflows fp24's range (about 1.8e19): dropped for fp24.
  const glm::vec3 p(0, 0, 0), q(1e-21f, 0, 0), r(0, 1e-21f, 0);
  EXPECT_TRUE(triangle_matrix(p, q, r).has_value());
  EXPECT_FALSE(encoded_triangle_matrix(p, q, r, ff::kFp24).has_value());
  EXPECT_TRUE(encoded_triangle_matrix(p, q, r, ff::kFp32).has_value());
  // fits_format: the largest finite fp24 value encodes finitely, twice it does not.
  Affine64 big;
  big.rows[1][2] = ff::decode(ff::kFp24.max_finite_bits(), ff::kFp24, ff::Subnormals::kKeep);
  EXPECT_TRUE(fits_format(big, ff::kFp24));
  EXPECT_TRUE(all_finite(encode_affine(big, ff::kFp24), ff::kFp24));
  big.rows[1][2] *= -2.0;
  EXPECT_FALSE(fits_format(big, ff::kFp24));
  EXPECT_FALSE(all_finite(encode_affine(big, ff::kFp24), ff::kFp24));
  big.rows[1][2] = std::nan("");
  EXPECT_FALSE(fits_format(big, ff::kFp24));
}

TEST(InstanceMatrix, WorldToObjectInvertsObjectToWorld) {
  glm::dmat4 m(1.0);
  // Rotation about a skew axis, non-uniform scale, translation (column-major).
  const double ca = std::cos(0.7), sa = std::sin(0.7);
  m[0] = glm::dvec4(2.0 * ca, 2.0 * sa, 0.0, 0.0);
  m[1] = glm::dvec4(-0.5 * sa, 0.5 * ca, 0.0, 0.0);
  m[2] = glm::dvec4(0.1, 0.2, 3.0, 0.0);
  m[3] = glm::dvec4(10.0, -20.0, 5.0, 1.0);
  const auto w = world_to_object(m);
  ASSERT_TRUE(w.has_value());
  const Affine64 o2w = affine_from_glm(m);
  for (const glm::dvec3 p : {glm::dvec3(0, 0, 0), glm::dvec3(1, 2, 3), glm::dvec3(-7, 0.5, 9)}) {
    const glm::dvec3 back = w->apply_point(o2w.apply_point(p));
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(back[k], p[k], 1e-13);
  }
  // The float version is the binary64 one rounded once.
  const Affine32 f = to_float(*w);
  EXPECT_EQ(f.rows[1][3], static_cast<float>(w->rows[1][3]));
}

TEST(InstanceMatrix, RejectsSingularAndProjectiveTransforms) {
  glm::dmat4 flat(1.0);
  flat[2] = glm::dvec4(0.0);
  EXPECT_FALSE(world_to_object(flat).has_value());
  glm::dmat4 proj(1.0);
  proj[2][3] = -1.0;  // a perspective row
  EXPECT_FALSE(world_to_object(proj).has_value());
  glm::dmat4 inf(1.0);
  inf[3][0] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(world_to_object(inf).has_value());
  // A tiny but regular scale is fine: the singularity test is relative.
  glm::dmat4 tiny(1e-9);
  tiny[3][3] = 1.0;
  const auto wt = world_to_object(tiny);
  ASSERT_TRUE(wt.has_value());
  EXPECT_DOUBLE_EQ(wt->rows[0][0], 1e9);
}

TEST(PrimaryRays, PixelCentresSpanTheFieldOfView) {
  Camera cam;
  cam.position = {1.0f, 2.0f, 3.0f};
  cam.forward = {0.0f, 0.0f, -1.0f};
  cam.up = {0.0f, 1.0f, 0.0f};
  cam.yfov = static_cast<float>(2.0 * std::atan(0.5));  // tan(fov/2) = 0.5
  const int w = 64, h = 48;
  const PrimaryBasis b = primary_basis(cam, w, h);
  EXPECT_EQ(b.cp, glm::dvec3(cam.position));
  const double th = std::tan(0.5 * double(cam.yfov));
  const double tw = th * w / h;
  for (int py : {0, 17, h - 1}) {
    for (int px : {0, 31, w - 1}) {
      const glm::dvec3 d = b.direction(px, py);
      const double sx = (2.0 * (px + 0.5) / w - 1.0) * tw;  // right = +x
      const double sy = (1.0 - 2.0 * (py + 0.5) / h) * th;  // row 0 at the top
      EXPECT_NEAR(d.x, sx, 1e-15);
      EXPECT_NEAR(d.y, sy, 1e-15);
      EXPECT_NEAR(d.z, -1.0, 1e-15);
    }
  }
  // The image centre (between the four middle pixels) looks along forward.
  const glm::dvec3 centre = 0.5 * (b.direction(w / 2 - 1, h / 2 - 1) + b.direction(w / 2, h / 2));
  EXPECT_NEAR(centre.x, 0.0, 1e-15);
  EXPECT_NEAR(centre.y, 0.0, 1e-15);
  // The top edge of row 0 is at the field of view's edge: pixel centre + half a row up.
  const glm::dvec3 top = b.direction(0, 0) - 0.5 * b.cu;
  EXPECT_NEAR(top.y / -top.z, th, 1e-15);
  // binary32 version: each vector rounded once.
  const PrimaryBasis32 f = to_float(b);
  EXPECT_EQ(f.cd.x, static_cast<float>(b.cd.x));
}

TEST(PrimaryRays, RotatedCameraUsesItsOwnBasis) {
  Camera cam;
  cam.forward = {1.0f, 0.0f, 0.0f};
  cam.up = {0.0f, 0.0f, 1.0f};
  const PrimaryBasis b = primary_basis(cam, 10, 10);
  // right = forward x up = (0,-1,0); rows go down = -z.
  EXPECT_LT(b.cr.y, 0.0);
  EXPECT_NEAR(b.cr.x, 0.0, 1e-16);
  EXPECT_LT(b.cu.z, 0.0);
  EXPECT_GT(b.cd.x, 0.99);
}

TEST(PrimaryRays, BadCamerasAreRefused) {
  Camera cam;
  EXPECT_THROW(primary_basis(cam, 0, 10), std::runtime_error);
  cam.up = cam.forward;
  try {
    primary_basis(cam, 8, 8);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("parallel"), std::string::npos) << e.what();
  }
  Camera c2;
  c2.yfov = 0.0f;
  EXPECT_THROW(primary_basis(c2, 8, 8), std::runtime_error);
}

}  // namespace
}  // namespace saarcor::host
