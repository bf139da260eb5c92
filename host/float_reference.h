// The float reference renderer: the golden model of docs/compare.md (model 1). It traverses
// the same kd-trees the hardware reads (paper section 2: a top-level tree over object instances,
// then the object's own tree after the world -> object transform; docs/cycle-model.md) and
// intersects with the unit-triangle method of paper section 2.1 (docs/cycle-model.md), in IEEE
// binary32 with the datapath op orders, so the functional fp24 model differs from it only by the
// number format. Primary rays come from the camera basis exactly as the hardware's T_init
// (paper section 2.2.2, decision D8). Shading follows docs/shading.md. docs/float-reference.md
// gives the rules (interval, tie, mailbox, defaults).
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "host/kdtree.h"
#include "host/primary_rays.h"
#include "host/triangle_matrix.h"

namespace saarcor::host {

struct Scene;
struct BuiltImage;

inline constexpr std::uint32_t kFloatNoHit = 0xFFFFFFFFu;

// A ray in world space; the direction is not normalised (t is the same in every space).
struct FloatRay {
  glm::vec3 origin{0.0f};
  glm::vec3 direction{0.0f, 0.0f, 1.0f};
};

// The closest hit of one ray (docs/cycle-model.md: t, u, v, object and triangle id, D'z).
struct FloatHit {
  float t = std::numeric_limits<float>::infinity();  // miss: +inf
  float u = 0.0f;
  float v = 0.0f;
  float cos = 0.0f;                      // D'_z (unnormalised direction against the unit normal)
  std::uint32_t instance = kFloatNoHit;  // index into the instance table (Scene::instances order)
  std::uint32_t triangle = kFloatNoHit;  // index within the object's mesh
  bool hit() const { return instance != kFloatNoHit; }
};

// What one ray cost, in the hardware's units (so reports can set them beside the fp24 model's).
struct FloatTraceStats {
  std::uint64_t rays = 0;
  std::uint64_t traversal_steps = 0;  // inner-node steps, both levels
  std::uint64_t leaves = 0;           // leaves visited, both levels
  std::uint64_t list_entries = 0;     // list entries fetched, both levels
  std::uint64_t mailbox_skips = 0;    // instances skipped because the ray already visited them
  std::uint64_t transformations = 0;  // world -> object ray transforms
  std::uint64_t intersections = 0;    // unit-triangle tests
  FloatTraceStats& operator+=(const FloatTraceStats& o);
};

// The float reference's copy of one instance, one object and the trees, all in binary32.
// How the float reference takes a ray into an instance's object space (docs/float-reference.md).
enum class InstanceStep {
  // binary64, the object-space ray rounded once: the golden image (instances scaled ~40 and
  // translated ~600, as in VC, lose ~1e-5 of t to a binary32 step).
  kBinary64,
  // binary32 in the datapath's op order, as every other step: then Float<7,23> hardware gives
  // the reference's results bit for bit on every scene (a check of both models' op orders).
  kBinary32,
};

struct FloatInstance {
  Affine64 world_to_object;
  Affine32 world_to_object32;  // the same rounded once
  std::uint32_t object = 0;
  std::uint32_t id = 0;  // glTF node index (built-ins: instance index), what hit records report
};

// A compact kd-node: bits = axis (0..2) or 3 = leaf in bits 0..1, child pair or item count above;
// payload = split (binary32 bits) or first list item.
struct FloatNode {
  std::uint32_t bits = 3;
  std::uint32_t payload = 0;
};

struct FloatObject {
  std::uint32_t root = 0;         // index of its root node in FloatScene::nodes
  std::uint32_t item_base = 0;    // its list items start here in FloatScene::items
  std::uint32_t matrix_base = 0;  // T_delta of its triangle 0 in FloatScene::triangles
  std::uint32_t triangle_count = 0;
  std::uint32_t shading_base = 0;  // shading record index of its triangle 0 (image objects)
  Aabb bounds;                     // object space: the root box of its tree
};

// Everything trace_float() reads. Built once per frame from the BuiltImage (or, in tests, from
// hand-made trees and matrices with add_object / add_instance / set_top).
class FloatScene {
 public:
  FloatScene() = default;
  // The image's trees and binary64 matrices (each rounded once to binary32).
  explicit FloatScene(const BuiltImage& image, InstanceStep step = InstanceStep::kBinary64);
  void set_instance_step(InstanceStep step) { step_ = step; }

  // Adds an object: its bottom-level tree (over triangle ids) and one T_delta per triangle slot
  // (std::nullopt = degenerate, never listed). Returns its index.
  std::uint32_t add_object(const KdTree& tree, std::span<const std::optional<Affine64>> matrices);
  // Adds an instance of object `object`; returns its index.
  std::uint32_t add_instance(std::uint32_t object, const Affine64& world_to_object,
                             std::uint32_t id);
  // The top-level tree over instance indices.
  void set_top(const KdTree& tree);

  std::span<const FloatInstance> instances() const { return instances_; }
  std::span<const FloatObject> objects() const { return objects_; }
  const Aabb& bounds() const { return top_bounds_; }
  // T_delta of triangle `triangle` of object `object` in binary32 (all zero for a dropped slot).
  const Affine32& t_delta(std::uint32_t object, std::uint32_t triangle) const {
    return triangles_[objects_[object].matrix_base + triangle];
  }

  // Closest hit with t_min < t < t_max. Ties (docs/shading.md section 3): a candidate with
  // t == t_best replaces the best hit when its (instance, triangle) is lexicographically smaller,
  // so the result does not depend on traversal order. any_hit: stop at the first accepted hit
  // (shadow rays).
  FloatHit trace(const FloatRay& ray, float t_min, float t_max, bool any_hit = false,
                 FloatTraceStats* stats = nullptr) const;

 private:
  std::uint32_t append_tree(const KdTree& tree, std::uint32_t item_offset);
  template <bool kAnyHit>
  void trace_object(std::uint32_t instance, const FloatRay& world, float t_min, FloatHit& hit,
                    FloatTraceStats& stats) const;

  std::vector<FloatNode> nodes_;
  std::vector<std::uint32_t> items_;
  std::vector<Affine32> triangles_;
  std::vector<FloatObject> objects_;
  std::vector<FloatInstance> instances_;
  std::uint32_t top_root_ = 0;
  InstanceStep step_ = InstanceStep::kBinary64;
  bool has_top_ = false;
  Aabb top_bounds_;
};

// Single ray against the image (builds a FloatScene; for many rays build one and call trace).
FloatHit trace_float(const FloatScene& scene, const FloatRay& ray, float t_min = 0.0f,
                     float t_max = std::numeric_limits<float>::infinity());

// The unit-triangle test of paper section 2.1.2 on one triangle, in binary32 with the datapath's
// op order: O' = T.O and D' = T.D as (m0*x + m1*y) + (m2*z + t), t = -O'z / D'z,
// u = O'x + t*D'x, v = O'y + t*D'y; accepted when u >= 0, v >= 0, u + v <= 1 and
// t_min < t < t_best and D'z != 0 (decision D13). Returns true and fills t, u, v, cos when
// accepted. (FloatScene::trace adds the tie rule for t == t_best.)
bool intersect_unit_triangle(const Affine32& t_delta, const FloatRay& ray, float t_min,
                             float t_best, float& t, float& u, float& v, float& cos);

// The refracted direction (docs/shading.md section 7; docs/shading.md with the sign of D12) of
// a ray with direction D at a surface whose normal n faces the ray, eta = n1 / n2, in binary32 in
// the RGS's op order: c = -dot(n, D), mu = (eta*c - sqrt((1 - eta*eta)*(dot(D, D)*dot(n, n)) +
// (eta*c)*(eta*c))) / dot(n, n), direction_r = (D_r*eta + n_r*mu) + (D_r*0 + 0), which has the
// length of D. Neither vector needs unit length. Returns false (direction untouched) under total
// internal reflection: a negative radicand.
bool refract_float(const glm::vec3& d, const glm::vec3& n, float eta, glm::vec3& direction);

// The primary ray of pixel (x, y) from T_init = [Cr, Cu, Cd; Cp] (host/primary_rays.h, decision D8:
// the host has folded scale and pixel-centre offset into the basis): origin Cp, direction
// (Cr*x + Cu*y) + (Cd*1 + 0), in binary32.
FloatRay primary_ray(const PrimaryBasis32& camera, int x, int y);
// The primary rays of a width x height frame, row-major (what other tracers are handed to trace
// the same rays, e.g. Embree in the benchmarks).
std::vector<FloatRay> primary_rays(const PrimaryBasis32& camera, int width, int height);

// Render options (docs/shading.md section 1). The defaults are the paper's Table 3 setting:
// primary rays and textured shading, no shadow or secondary rays. Resolution, camera, ambient,
// background, epsilon and max depth come from the image (ImageParams, FrameRegisters).
struct FloatParams {
  bool shade = true;       // false: hit records only, the image stays black
  bool shadows = false;    // shadow rays towards every light
  bool secondary = false;  // reflection, transparency and refraction rays up to the depth bound
  int max_depth = -1;      // secondary-ray depth bound, -1 = FrameRegisters::max_depth
  InstanceStep instance_step = InstanceStep::kBinary64;  // render_float(image, ...) only
};

// Per pixel: the closest hit and the world-space primary ray (what a hit EXR stores).
struct FloatPixel {
  FloatHit hit;
  std::uint32_t instance_id = kFloatNoHit;  // glTF node index of hit.instance, miss: ~0
  FloatRay ray;
};

struct FloatFrame {
  int width = 0;
  int height = 0;
  std::vector<FloatPixel> pixels;  // row-major, row 0 at the top
  std::vector<std::uint8_t> rgb;   // 3 bytes per pixel, row 0 at the top
  FloatTraceStats stats;           // primary rays only
  const FloatPixel& at(int x, int y) const {
    return pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                  static_cast<std::size_t>(x)];
  }
};

// Renders the image's camera at the image's resolution. `scene` supplies the lights' binary32
// positions (the image holds them in its own format); everything else is read from `image`.
FloatFrame render_float(const BuiltImage& image, const Scene& scene, const FloatParams& params);
// The same with a FloatScene built beforehand from `image` (benchmarks, repeated frames).
FloatFrame render_float(const FloatScene& float_scene, const BuiltImage& image, const Scene& scene,
                        const FloatParams& params);

}  // namespace saarcor::host
