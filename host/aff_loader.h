// BART's AFF scene format (Lext, Assarsson, Möller: "A Benchmark for Animated Ray Tracing", IEEE
// CG&A 2001; an NFF extension with meshes, includes, static and keyframed transforms) -> Scene.
// Grammar, spline interpolation and the mapping onto Scene are described in docs/aff.md.
#pragma once

#include <string>
#include <vector>

#include "host/scene.h"

namespace saarcor::host {

// Loads an .aff file and everything it includes (`i`, relative to the including file's folder).
// Each include and each transform block (`xs`, `x`) becomes a Node; the triangles written directly
// in one of them become one Object with one Instance. A file included again in the same material
// state reuses the Objects of its first inclusion (instancing). Keyframed transforms (`x` + `k`)
// and the camera (`k camera`) become TRS nodes whose Kochanek-Bartels splines are sampled into
// LINEAR channels (kAffSamplesPerSecond, kAffMinStepsPerKey). The scene is evaluated at time 0;
// lights are not defaulted here (load_scene() does that). Throws one std::runtime_error "FILE:LINE:
// problem".
Scene load_aff(const std::string& path);

// Splines become LINEAR channels sampled at every key time (both one-sided values where BART's
// spline jumps) and max(kAffMinStepsPerKey, kAffSamplesPerSecond x interval) steps between
// consecutive key times (docs/aff.md, "Interpolation", gives the resulting error).
inline constexpr double kAffSamplesPerSecond = 60.0;
inline constexpr int kAffMinStepsPerKey = 16;

// One Kochanek-Bartels key: time, value (xyz, or axis xyz + angle in radians in w for rotations),
// tension, continuity, bias.
struct AffKey {
  double time = 0.0;
  glm::dvec4 value{0.0};
  double tension = 0.0;
  double continuity = 0.0;
  double bias = 0.0;
};

// BART's splines (kbsplpos.c, kbsplrot.c), evaluated at time t. They need at least 4 keys; the
// first and last only shape the end tangents, t is clamped to [keys[1].time, keys[n-2].time].
// Positions: Hermite with KB tangents. Rotations: axis-angle keys as quaternions, squad with KB
// tangents in the quaternion log space; returns a unit quaternion (w, x, y, z).
glm::dvec3 aff_position_spline(const std::vector<AffKey>& keys, double t);
glm::dquat aff_rotation_spline(const std::vector<AffKey>& keys, double t);

}  // namespace saarcor::host
