// Triangle and instance matrices (paper section 2.1.1; docs/memory-image.md; decisions D11, D19).
#include "host/triangle_matrix.h"

#include <algorithm>
#include <cmath>

namespace saarcor::host {

glm::dvec3 Affine64::apply_point(const glm::dvec3& p) const {
  glm::dvec3 o;
  for (int r = 0; r < 3; ++r) {
    const auto& m = rows[r];
    o[r] = (m[0] * p.x + m[1] * p.y) + (m[2] * p.z + m[3]);
  }
  return o;
}

glm::dvec3 Affine64::apply_vector(const glm::dvec3& d) const {
  glm::dvec3 o;
  for (int r = 0; r < 3; ++r) {
    const auto& m = rows[r];
    o[r] = (m[0] * d.x + m[1] * d.y) + (m[2] * d.z + 0.0);
  }
  return o;
}

glm::vec3 Affine32::apply_point(const glm::vec3& p) const {
  glm::vec3 o;
  for (int r = 0; r < 3; ++r) {
    const auto& m = rows[r];
    o[r] = (m[0] * p.x + m[1] * p.y) + (m[2] * p.z + m[3]);
  }
  return o;
}

glm::vec3 Affine32::apply_vector(const glm::vec3& d) const {
  glm::vec3 o;
  for (int r = 0; r < 3; ++r) {
    const auto& m = rows[r];
    o[r] = (m[0] * d.x + m[1] * d.y) + (m[2] * d.z + 0.0f);
  }
  return o;
}

Affine32 to_float(const Affine64& a) {
  Affine32 f;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      f.rows[r][c] = static_cast<float>(a.rows[r][c]);
  return f;
}

EncodedAffine encode_affine(const Affine64& a, const ff::Format& f) {
  EncodedAffine e{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      e[r][c] = ff::from_double(a.rows[r][c], f, ff::Mode{});
  return e;
}

bool all_finite(const EncodedAffine& e, const ff::Format& f) {
  for (const auto& row : e)
    for (std::uint32_t v : row)
      if (ff::is_inf(v, f) || ff::is_nan(v, f)) return false;
  return true;
}

bool fits_format(const Affine64& a, const ff::Format& f) {
  const double largest = ff::decode(f.max_finite_bits(), f, ff::Subnormals::kKeep);
  for (const auto& row : a.rows)
    for (double v : row)
      if (!(std::abs(v) <= largest)) return false;  // also NaN
  return true;
}

std::optional<Affine64> triangle_matrix(const glm::dvec3& a, const glm::dvec3& b,
                                        const glm::dvec3& c) {
  const glm::dvec3 e0 = a - c;
  const glm::dvec3 e1 = b - c;
  const glm::dvec3 cr = glm::cross(e0, e1);
  const double len = std::sqrt(glm::dot(cr, cr));
  const double longest2 = std::max({glm::dot(e0, e0), glm::dot(e1, e1), glm::dot(a - b, a - b)});
  // Written so that NaN and inf (non-finite vertices) are degenerate too.
  if (!(len > kDegenerateRelArea * longest2) || !std::isfinite(len) || !std::isfinite(longest2))
    return std::nullopt;
  const glm::dvec3 n = cr / len;
  // Inverse of the matrix with columns (e0, e1, n) by cofactors; its determinant
  // e0 . (e1 x n) = (e0 x e1) . n is |e0 x e1| = len, and its third row (e0 x e1)/len is n.
  const glm::dvec3 r0 = glm::cross(e1, n) / len;
  const glm::dvec3 r1 = glm::cross(n, e0) / len;
  const glm::dvec3 r2 = n;
  Affine64 t;
  const glm::dvec3 rs[3] = {r0, r1, r2};
  for (int r = 0; r < 3; ++r) {
    t.rows[r] = {rs[r].x, rs[r].y, rs[r].z, -((rs[r].x * c.x + rs[r].y * c.y) + rs[r].z * c.z)};
  }
  return t;
}

std::optional<Affine64> triangle_matrix(const glm::vec3& a, const glm::vec3& b,
                                        const glm::vec3& c) {
  return triangle_matrix(glm::dvec3(a), glm::dvec3(b), glm::dvec3(c));
}

std::optional<EncodedAffine> encoded_triangle_matrix(const glm::vec3& a, const glm::vec3& b,
                                                     const glm::vec3& c, const ff::Format& f) {
  const auto t = triangle_matrix(a, b, c);
  if (!t || !fits_format(*t, f)) return std::nullopt;
  return encode_affine(*t, f);
}

Affine64 affine_from_glm(const glm::dmat4& m) {
  Affine64 a;
  // glm is column-major: m[col][row].
  for (int r = 0; r < 3; ++r)
    a.rows[r] = {m[0][r], m[1][r], m[2][r], m[3][r]};
  return a;
}

std::optional<Affine64> world_to_object(const glm::dmat4& object_to_world) {
  const glm::dmat4& m = object_to_world;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return std::nullopt;
  if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0) return std::nullopt;
  const glm::dvec3 c0(m[0]), c1(m[1]), c2(m[2]), tr(m[3]);
  const double det = glm::dot(c0, glm::cross(c1, c2));
  const double scale = glm::length(c0) * glm::length(c1) * glm::length(c2);
  if (!(std::abs(det) > 1e-12 * scale)) return std::nullopt;
  // Rows of the inverse linear part are the cofactor vectors over the determinant.
  const glm::dvec3 rs[3] = {glm::cross(c1, c2) / det, glm::cross(c2, c0) / det,
                            glm::cross(c0, c1) / det};
  Affine64 w;
  for (int r = 0; r < 3; ++r) {
    w.rows[r] = {rs[r].x, rs[r].y, rs[r].z, -((rs[r].x * tr.x + rs[r].y * tr.y) + rs[r].z * tr.z)};
  }
  return w;
}

}  // namespace saarcor::host
