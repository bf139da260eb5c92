// Per-pixel closest-hit records of one frame: what every model (float reference, functional fp24,
// cycle) writes and what `saarcor compare` reads. The hit EXR stores exactly these channels:
// float hit.t, hit.u, hit.v, hit.cos, uint hit.instance, hit.triangle, float ray.ox..ray.dz.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

namespace saarcor {

struct PixelHit {
  float t = std::numeric_limits<float>::infinity();  // miss: +inf
  float u = 0.0f;
  float v = 0.0f;
  float cos = 0.0f;  // D'_z: the cosine with the geometric normal (unnormalised D)
  std::uint32_t instance = 0xFFFFFFFFu;  // glTF node index (built-ins: instance index); miss: ~0
  std::uint32_t triangle = 0xFFFFFFFFu;  // index within its mesh; miss: ~0
  float ox = 0, oy = 0, oz = 0;          // world-space primary ray
  float dx = 0, dy = 0, dz = 0;
  bool hit() const { return instance != 0xFFFFFFFFu; }
  friend bool operator==(const PixelHit&, const PixelHit&) = default;
};

struct HitBuffer {
  int width = 0;
  int height = 0;
  std::vector<PixelHit> pixels;  // row-major, row 0 at the top
  PixelHit& at(int x, int y) { return pixels[static_cast<std::size_t>(y) * width + x]; }
  const PixelHit& at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
};

// An 8-bit RGB frame (what the frame buffer holds), row 0 at the top.
struct Rgb8Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // 3 bytes per pixel
};

}  // namespace saarcor
