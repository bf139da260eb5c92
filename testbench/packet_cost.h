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
#include <vector>

#include "memif/image_format.h"

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
};

// What the sampled simulation's cycles estimate is fitted on, per packet (testbench/sampling.h
// estimate_cycles): a constant (the box test and the RGS's work every packet has), kd-tree steps,
// triangle tests, leaves, list entries, transformations, and whether the packet meets the scene's
// box. Each kind of work takes its own unit's cycles, so each gets its own coefficient.
inline constexpr int kCostFeatures = 7;
using CostFeatures = std::array<double, kCostFeatures>;
CostFeatures cost_features(const RayCost& c);

// The image's trees, instances and triangle matrices read once into binary32, for tracing rays
// on the host. Matrices are decoded when a ray first needs them.
class PacketCostModel {
 public:
  explicit PacketCostModel(const memif::MemoryImage& image);
  // The work of the ray origin + t * direction, t > 0, to its closest hit.
  RayCost trace(const std::array<float, 3>& origin, const std::array<float, 3>& direction) const;
  // The ray of the (possibly fractional) pixel position (x, y) from the camera registers.
  RayCost trace_pixel(double x, double y) const;

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
  void trace_instance(std::uint32_t instance, const Ray& world, float& t_best, RayCost& c) const;
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
};

// Adds b's counts to a's (box and hit: either).
RayCost& operator+=(RayCost& a, const RayCost& b);

// The cost of every packet of the image's frame in the RGC's order (packets of `packet` rays,
// units::packet_tiling): the ray through the centre of the packet's tile, clipped to the image;
// for packets of 16 rays or more, the sum of the rays through its four quadrants' centres.
std::vector<RayCost> packet_costs(const memif::MemoryImage& image, int packet);

}  // namespace saarcor
