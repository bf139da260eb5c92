// The packet a DynRTP thread carries through the units (docs/cycle-model.md): per lane the ray in
// world, current and unit-triangle space, the closest hit and the ray's counters; the binary64
// values the traversal unit works on; what the RGS hands the transformation unit to generate a
// packet (path a). The state each unit keeps besides is that unit's slice (units/*_step.h), all
// held together by units/packet_state.h.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

#include "memif/image_format.h"
#include "units/datapath.h"
#include "units/lane_values.h"
#include "units/program_types.h"

namespace saarcor::units {

// The level of the two-level kd-tree a packet traverses (paper section 3.1: top level over the
// objects, bottom level over an object's triangles; one stack for both).
enum class Level : std::uint8_t { kTop, kBottom };

// What the RGS hands the transformation unit for one lane (path a): T and R'.
template <class F>
struct GenLane {
  bool valid = false;
  std::uint32_t pixel = memif::kNone;
  std::uint32_t weight = 0;
  Mat34<F> t{};
  Vec3<F> ro{}, rd{};
};

// A packet to generate: its kind, recursion depth, whether its rays share one origin (the n+1
// rule), and its lanes.
template <class F>
struct GenPacket {
  RayKind kind = RayKind::kPrimary;
  std::uint32_t depth = 0;
  bool shared_origin = false;
  std::vector<GenLane<F>> lanes;
};

template <class F>
struct Lane {
  bool valid = false;  // carries a ray of the current packet
  bool done = false;   // any-hit satisfied (shadow rays, D15)
  std::uint32_t pixel = memif::kNone;
  std::uint32_t weight = 0;
  Ray<F> world, current, tri;
  HitRecord<F> hit;  // hit.t = t_best (starts at the ray's t_max)
  RayCounters counters;
};

// The traversal unit keeps the segments as binary64 values: every one is the exact value of an
// encoding of F (lane_values.h), so the encodings are recovered exactly where a step reads them,
// and a compare of two values is the compare of their encodings. The fast datapath also keeps
// O and 1/D per axis of the world and of the current (object) ray (FastDatapath::axis_values, for
// traversal_pair64); the reference datapath reads the rays' encodings instead. Kept per packet as
// arrays over the lanes, so two lanes go through one vector op; slots from P up to the next even
// count are padding, computed along and never used. A lane's tn,
// tf are meaningful only while it is in the packet's mask: it enters the mask only where they are
// set (start of a sign group, pop, the near child), so whole-array copies may overwrite the others.
template <int kLanes>
using Slots = std::array<double, kLanes>;
template <int kLanes>
struct alignas(16) LaneValues {
  std::array<Slots<kLanes>, 3> world_o{}, world_inv{}, o{}, inv{};
  Slots<kLanes> tn{}, tf{};            // segment of the node being visited
  Slots<kLanes> clip_tn{}, clip_tf{};  // the level's clipped segment (restart of a sign group)
  Slots<kLanes> t_best{};              // value of hit.t
};

inline bool lane_in(std::uint64_t mask, int i) {
  return ((mask >> i) & 1u) != 0;
}
inline V2d load2(const double* p) {
  V2d v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store2(double* p, V2d v) {
  std::memcpy(p, &v, sizeof v);
}

// The lanes' decisions at an inner kd-node (a datapath's decide): which go near, which go far, and
// their new segments.
template <int kLanes>
struct TraversalDecision {
  std::uint64_t near_mask = 0, far_mask = 0;
  alignas(16) Slots<kLanes> near_tf, far_tn;  // slots 0..P-1 (rounded up to even) set
};

// D: the datapath policy (units/fast_datapath.h or units/reference_datapath.h).
template <class F, int kLanes, class D>
struct PacketState;

}  // namespace saarcor::units
