// The primary-ray transformation (paper section 2.2.2; docs/shading.md; decision D8).
#include "host/primary_rays.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace saarcor::host {

glm::dvec3 PrimaryBasis::direction(int px, int py) const {
  const double x = px, y = py;
  return (x * cr + y * cu) + cd;
}

glm::vec3 PrimaryBasis32::direction(int px, int py) const {
  const float x = static_cast<float>(px), y = static_cast<float>(py);
  return (x * cr + y * cu) + cd;
}

PrimaryBasis primary_basis(const Camera& camera, int width, int height) {
  if (width <= 0 || height <= 0)
    throw std::runtime_error("image size " + std::to_string(width) + "x" + std::to_string(height) +
                             " is not positive");
  const double fov = camera.yfov;
  if (!(fov > 0.0 && fov < 3.14159265358979)) {
    throw std::runtime_error("camera vertical field of view " + std::to_string(fov) +
                             " rad is outside (0, pi)");
  }
  const glm::dvec3 fwd_in(camera.forward);
  const double flen = glm::length(fwd_in);
  if (!(flen > 0.0) || !std::isfinite(flen))
    throw std::runtime_error("camera forward vector is zero or not finite");
  const glm::dvec3 f = fwd_in / flen;
  const glm::dvec3 side = glm::cross(f, glm::dvec3(camera.up));
  const double slen = glm::length(side);
  if (!(slen > 1e-9) || !std::isfinite(slen))
    throw std::runtime_error("camera up vector is zero or parallel to its forward vector");
  // Orthonormal basis: right = forward x up, up re-orthogonalised against forward.
  const glm::dvec3 r = side / slen;
  const glm::dvec3 u = glm::cross(r, f);
  const double half_h = std::tan(0.5 * fov);                      // screen y = +-1 at the fov edges
  const double half_w = half_h * double(width) / double(height);  // square pixels
  // Screen x = ((px + 0.5) * 2 / width - 1) * half_w, screen y = (1 - (py + 0.5) * 2 / height)
  // * half_h; direction = f + x*r + y*u.
  PrimaryBasis b;
  b.cr = r * (2.0 * half_w / double(width));
  b.cu = u * (-2.0 * half_h / double(height));
  b.cd =
      f + r * (half_w * (1.0 / double(width) - 1.0)) + u * (half_h * (1.0 - 1.0 / double(height)));
  b.cp = glm::dvec3(camera.position);
  return b;
}

PrimaryBasis32 to_float(const PrimaryBasis& b) {
  return {glm::vec3(b.cr), glm::vec3(b.cu), glm::vec3(b.cd), glm::vec3(b.cp)};
}

}  // namespace saarcor::host
