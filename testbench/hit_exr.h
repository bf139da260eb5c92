// The hit EXR: one frame's per-pixel closest-hit records (testbench/hit_buffer.h) as ONE
// multi-channel OpenEXR file, so any other tool can read the hits and trace the same rays
// (docs/compare.md; channel layout in docs/compare.md):
//   float hit.t, hit.u, hit.v, hit.cos; uint hit.instance, hit.triangle;
//   float ray.ox, ray.oy, ray.oz, ray.dx, ray.dy, ray.dz.
// A miss has hit.t = +inf and both ids 0xFFFFFFFF. Values are stored bit for bit (lossless zip).
#pragma once

#include <array>
#include <string>

#include "testbench/hit_buffer.h"

namespace saarcor {

inline constexpr std::array<const char*, 12> kHitExrChannels = {
    "hit.t",  "hit.u",  "hit.v",  "hit.cos", "hit.instance", "hit.triangle",
    "ray.ox", "ray.oy", "ray.oz", "ray.dx",  "ray.dy",       "ray.dz"};

// Writes atomically (testbench/image_io.h); throws std::runtime_error naming the file.
void write_hit_exr(const std::string& path, const HitBuffer& hits);
// Reads a hit EXR; throws when the file is missing, is not an image, or lacks a hit channel or
// has it in the wrong type (the message names the channel).
HitBuffer read_hit_exr(const std::string& path);
// True when the file is an image with a `hit.t` channel (false for other images; throws when
// the file is missing or unreadable).
bool is_hit_exr(const std::string& path);

}  // namespace saarcor
