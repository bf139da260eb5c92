// The primary-ray transformation T_init = [Cr, Cu, Cd; Cp] (paper section 2.2.2;
// docs/shading.md; decision D8), pre-scaled by the host so that the RGS issues the initial ray
// R' = ((0,0,0), (px, py, 1)) with integer pixel indices and stays free of floating point:
//   origin = Cp, direction = px*Cr + py*Cu + Cd,
// px = 0..width-1 left to right, py = 0..height-1 with row 0 at the top of the image. The pixel
// centre (+0.5) and the mapping of [0, width) x [0, height) onto the screen window [-1, 1]^2 are
// folded into Cd. The window spans the camera's vertical field of view and width/height times
// that horizontally (square pixels). The direction is not normalised (its length is 1 at the
// image centre); t stays comparable across levels because every transform is affine.
#pragma once

#include <glm/glm.hpp>

#include "host/scene.h"

namespace saarcor::host {

struct PrimaryBasis {
  glm::dvec3 cr{0.0};  // per pixel column, towards the right
  glm::dvec3 cu{0.0};  // per pixel row, downwards on screen (row 0 at the top)
  glm::dvec3 cd{0.0};  // direction of pixel (0, 0): forward + folded offsets
  glm::dvec3 cp{0.0};  // camera position

  glm::dvec3 direction(int px, int py) const;  // binary64, as (px*cr + py*cu) + cd
};

// Throws std::runtime_error for a non-positive image size, a field of view outside (0, pi), or a
// camera whose forward vector is zero or parallel to its up vector.
PrimaryBasis primary_basis(const Camera& camera, int width, int height);

// The binary32 versions of the four vectors, each component rounded once from binary64: what the
// float reference renderer uses (direction = (px*cr + py*cu) + cd in binary32).
struct PrimaryBasis32 {
  glm::vec3 cr{0.0f}, cu{0.0f}, cd{0.0f}, cp{0.0f};
  glm::vec3 direction(int px, int py) const;
};
PrimaryBasis32 to_float(const PrimaryBasis& b);

}  // namespace saarcor::host
