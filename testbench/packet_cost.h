// A per-packet cost known for every packet of a frame without the cycle simulation: the work of
// one ray through the packet's centre (four, through its quadrants', for packets of 16 rays or
// more), traced by a plain binary32 traversal of the memory image's own kd-trees
// (docs/sampling.md, decisions D53 and D54). The sampled simulation's regression estimator
// (testbench/sampling.h) fits the windows' charged cycles on its features: the windows measure
// cycles, this says where the frame's work lies between them. It costs 0.2-3.5 % of the full cycle
// run, where the fp24 functional model over every ray costs a quarter of it.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "memif/image_format.h"
#include "units/program_types.h"

namespace saarcor {

// What one ray cost, in the traversal's units (both levels of the kd-trees).
struct RayCost {
  bool box = false;              // the ray meets the scene's box (FrameRegisters::scene_min/max)
  bool hit = false;              // it hits a triangle
  std::uint32_t steps = 0;       // inner kd-node steps
  std::uint32_t leaves = 0;      // leaves visited
  std::uint32_t lists = 0;       // list entries read
  std::uint32_t transforms = 0;  // world -> object transformations (instances entered)
  std::uint32_t tests = 0;       // ray-triangle tests
  // With shadow rays (units::FunctionalParams::shadows): the shadow rays the RGS would trace for
  // the hits, one a light that lights a hit, and their kd steps and triangle tests (any hit).
  std::uint32_t shadow_rays = 0;
  std::uint32_t shadow_steps = 0;
  std::uint32_t shadow_tests = 0;
  // With secondary rays: the reflection, transparency and refraction rays the hits spawn (a
  // refraction ray traced straight on), and their steps and tests.
  std::uint32_t secondary_rays = 0;
  std::uint32_t secondary_steps = 0;
  std::uint32_t secondary_tests = 0;
};

// Which rays beside the primary ones a frame traces (units::FunctionalParams).
struct CostPaths {
  bool shadows = false;
  bool secondary = false;
  std::uint32_t max_depth = 0;  // secondary-ray depth bound (FrameRegisters::max_depth)
};
// The paths a frame rendered with `shading` traces.
CostPaths cost_paths(const memif::MemoryImage& image, const units::FunctionalParams& shading);

// What the sampled simulation's cycles estimate is fitted on, per packet (testbench/sampling.h
// estimate_cycles): a constant (the box test and the RGS's work every packet has), kd-tree steps,
// triangle tests, leaves, list entries, transformations, whether the packet meets the scene's
// box, and the shadow and secondary rays with their steps and tests. Each kind of work takes its
// own unit's cycles, so each gets its own coefficient (a feature without spread over the windows,
// the shadow rays' when none are traced, drops out of the fit).
inline constexpr int kCostFeatures = 13;
using CostFeatures = std::array<double, kCostFeatures>;
CostFeatures cost_features(const RayCost& c);

// The image's trees, instances and triangle matrices read once into binary32, for tracing rays
// on the host. Matrices are decoded when a ray first needs them.
class PacketCostModel {
 public:
  explicit PacketCostModel(const memif::MemoryImage& image);
  // Where a ray hit: the instance, its triangle's first matrix row and the ray's t.
  struct Hit {
    std::uint32_t instance = 0, triangle_row = 0;
    float t = 0;
  };
  // The work of the ray origin + t * direction, 0 < t < t_max, to its closest hit (any hit: to the
  // first, as a shadow ray). `hit`, if given, receives where it hit.
  RayCost trace(const std::array<float, 3>& origin, const std::array<float, 3>& direction,
                float t_max = std::numeric_limits<float>::infinity(), bool any_hit = false,
                Hit* hit = nullptr) const;
  // The ray of the (possibly fractional) pixel position (x, y) from the camera registers, and the
  // rays its hit spawns on `paths`: shadow rays towards each light that lights a hit (the RGS's
  // rule: the normal, facing the ray, points towards the light), from the light with
  // t < 1 - 1/512; reflection, transparency and refraction children while their weight is above
  // 0 and the depth below the bound (docs/shading.md section 7).
  RayCost trace_pixel(double x, double y, const CostPaths& paths = {}) const;

 private:
  static constexpr std::uint32_t kUnread = ~0u;
  struct Node {
    std::uint32_t bits = kUnread;  // axis (0..2) or 3 = leaf in bits 0..1; empty flags in 2..3
    std::uint32_t child = 0;       // inner: left child (right = child + 1); leaf: first list entry
    float split = 0;               // inner
    std::uint32_t count = 0;       // leaf: list entries
  };
  struct Instance {
    std::array<std::array<float, 4>, 3> world_to_object{};
    std::uint32_t root = 0;
    std::uint32_t triangle_rows = 0;
    std::uint32_t shading_base = 0;
    std::array<float, 3> lo{}, hi{};
  };
  struct Ray {
    std::array<float, 3> o{}, d{}, inv{};  // inv: 1 / d, the slab distances' factors
  };
  static Ray make_ray(const std::array<float, 3>& o, const std::array<float, 3>& d);
  // The node, read from the image on the first visit (inline: the traversal's every step).
  const Node& node(std::uint32_t index) const {
    if (nodes_[index].bits == kUnread) [[unlikely]]
      read_node(index);
    return nodes_[index];
  }
  void read_node(std::uint32_t index) const;
  template <class Visit>
  void traverse(std::uint32_t root, const Ray& r, float t0, float t1, RayCost& c, Visit&& v) const;
  // Returns true when a hit ends the ray (any hit).
  bool trace_instance(std::uint32_t instance, const Ray& world, float& t_best, bool any_hit,
                      RayCost& c, Hit* hit) const;
  // What the RGS makes of a hit of the ray o + t d: its shadow rays and its children.
  void shade(const std::array<float, 3>& o, const std::array<float, 3>& d, const Hit& hit,
             std::uint32_t weight, std::uint32_t depth, const CostPaths& paths, RayCost& c) const;
  const std::array<std::array<float, 4>, 3>& triangle(std::uint32_t first_row) const;
  float decode(std::uint32_t bits) const;

  const memif::MemoryImage& image_;
  mutable std::vector<Node> nodes_;
  std::vector<Instance> instances_;
  // The triangle matrices read so far, and by first row their place there (-1: not yet read).
  mutable std::vector<std::array<std::array<float, 4>, 3>> matrices_;
  mutable std::vector<std::int32_t> slots_;
  std::array<float, 3> scene_lo_{}, scene_hi_{};
  std::array<float, 3> cam_r_{}, cam_u_{}, cam_d_{}, cam_p_{};
  std::vector<std::array<float, 3>> lights_;  // the lights' positions
  float epsilon_ = 0;                         // the secondary rays' offset, in units of |D|
};

// Adds b's counts to a's (box and hit: either).
RayCost& operator+=(RayCost& a, const RayCost& b);

// The cost of every packet of the image's frame in the RGC's order (packets of `packet` rays,
// units::packet_tiling): the ray through the centre of the packet's tile, clipped to the image;
// for packets of 16 rays or more, the sum of the rays through its four quadrants' centres; with
// each the rays its hit spawns on `paths`.
std::vector<RayCost> packet_costs(const memif::MemoryImage& image, int packet,
                                  const CostPaths& paths = {});

}  // namespace saarcor
