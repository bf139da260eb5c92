// Triangle and instance matrices the host uploads (paper section 2.1.1, the affine triangle
// transformation; docs/memory-image.md, matrix rows and the T_delta erratum; decisions D11, D18,
// D19).
//
// Every matrix is an affine 3x4 map written as three rows (m_r0, m_r1, m_r2, t_r), the order in
// which the image stores it and the transformation unit evaluates it:
//   out_r = (m_r0*x + m_r1*y) + (m_r2*z + t_r).
// The host computes each matrix in binary64 and rounds every coefficient once into the image's
// float format (decision D11).
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <optional>

#include "fixedfloat/format.h"

namespace saarcor::host {

// An affine map in binary64, row-major: rows[r] = (m_r0, m_r1, m_r2, t_r).
struct Affine64 {
  std::array<std::array<double, 4>, 3> rows{};
  glm::dvec3 apply_point(const glm::dvec3& p) const;   // binary64, datapath op order
  glm::dvec3 apply_vector(const glm::dvec3& d) const;  // translation left out
};

// The same map in binary32 (each coefficient rounded once from binary64): what the float
// reference renderer uses.
struct Affine32 {
  std::array<std::array<float, 4>, 3> rows{};
  glm::vec3 apply_point(const glm::vec3& p) const;  // binary32, datapath op order
  glm::vec3 apply_vector(const glm::vec3& d) const;
};

// The same map as float encodings of an image format, ready to be packed into three rows.
using EncodedAffine = std::array<std::array<std::uint32_t, 4>, 3>;

Affine32 to_float(const Affine64& a);
// Rounds every coefficient once (round to nearest even, the format's default mode).
EncodedAffine encode_affine(const Affine64& a, const ff::Format& f);
// True when every coefficient of `e` is finite (no overflow to inf, no NaN).
bool all_finite(const EncodedAffine& e, const ff::Format& f);
// True when every coefficient of `a` is finite with magnitude at most f's largest finite value,
// so that rounding it into f gives a finite encoding (a cheap test before encode_affine).
bool fits_format(const Affine64& a, const ff::Format& f);

// A triangle is degenerate when |(A-C) x (B-C)| <= kDegenerateRelArea * L^2, with L the longest
// edge. The ratio is scale-free (twice the area over the squared longest edge: 0 for a line,
// sqrt(3)/2 for an equilateral triangle) and bounds the condition number of T_delta^-1. The value
// is the loader's (host/scene.h kDegenerateRelativeArea), so the image builder drops the same
// triangles the scene reports. Near the threshold the binary64 normal is only accurate to about
// 1e-16 / ratio (1e-4 at the threshold) because the cross product cancels; such slivers are far
// thinner than a pixel in any sensible view. Triangles with ratio above 1e-10 get T_delta
// accurate to well under fp24's half-ulp (2^-17) before the single rounding.
inline constexpr double kDegenerateRelArea = 1e-12;

// T_delta of triangle (A, B, C): maps A -> (1,0,0), B -> (0,1,0), C -> (0,0,0) and C + N ->
// (0,0,1), N the unit normal of (A-C) x (B-C). Built as the inverse of
// T_delta^-1(X) = [A-C, B-C, N] X + C (decision D11, the paper's erratum: the third column is N,
// not N - C), in binary64. Row 2 is N itself. std::nullopt for a degenerate triangle (see
// kDegenerateRelArea) or non-finite vertices.
std::optional<Affine64> triangle_matrix(const glm::dvec3& a, const glm::dvec3& b,
                                        const glm::dvec3& c);
std::optional<Affine64> triangle_matrix(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c);

// T_delta rounded into format f; std::nullopt when the triangle is degenerate or a coefficient
// overflows the format (!fits_format: a sliver so thin that 1/height exceeds the format's range).
std::optional<EncodedAffine> encoded_triangle_matrix(const glm::vec3& a, const glm::vec3& b,
                                                     const glm::vec3& c, const ff::Format& f);

// An instance's world -> object map: the inverse of object_to_world (glm, column-major, affine:
// bottom row (0,0,0,1)), in binary64. std::nullopt when object_to_world is not affine, has
// non-finite entries, or its linear part is singular (|det| <= 1e-12 times the product of its
// column lengths).
std::optional<Affine64> world_to_object(const glm::dmat4& object_to_world);

// The same map for an object -> world glm matrix, as rows (no inversion).
Affine64 affine_from_glm(const glm::dmat4& m);

}  // namespace saarcor::host
