// What a thread program and the models around it share (docs/cycle-model.md; paper section 3.1,
// Figure 2): the model's functional parameters, the per-ray work counters, the ray kinds, the
// DynRTP units a thread asks for and the phases that name them, the request a thread hands a unit,
// the capture tap for unit transactions, the float units with their counters, and the frame sink
// the RGS writes. The thread program itself is units/thread_program.h; each unit's semantics is in
// its own *_step.h.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "fixedfloat/float.h"
#include "hw/huge_pages.h"
#include "memif/image_format.h"
#include "memif/request.h"
#include "units/datapath.h"
#include "units/unit_fp.h"

namespace saarcor::units {

inline constexpr int kMaxPacket = 64;  // lane masks are 64-bit

struct FunctionalParams {
  int packet = 4;             // P rays per packet (thread); a power of two, 1..64
  int stack_depth = 64;       // traversal stack entries per packet (D26)
  int mailbox = 8;            // object mailbox entries per thread (D28), 0 = off
  int triangle_mailbox = 8;   // triangle mailbox entries (bottom-level lists), 0 = off
  bool shared_origin = true;  // the n+1 rule for packets with one origin (D31)
  // Box clips: when every ray of the packet starts inside the box, its entry faces cannot raise
  // tn above 0, so the traversal unit divides for the three exit faces only (3 steps, not 6).
  bool clip_exit_only = true;
  // Children an inner node flags empty (memif::KdNode) are not stepped into: the traversal unit
  // sees the flags with the parent's fetch, so an empty leaf costs no traversal step.
  bool skip_empty = true;
  // Box faces a clip step divides for: 1 = one divider per ray (Table 2's 4 dividers for a 4-ray
  // packet); k > 1 models a traversal unit with k dividers per ray (1..6).
  int clip_faces_per_step = 1;
  bool shade = true;       // run the RGS; false leaves the image black (hit records only)
  bool shadows = false;    // shadow rays (docs/shading.md 6.4); Table 3 setting: off
  bool secondary = false;  // reflection, transparency and refraction rays; Table 3 setting: off
  int max_depth = -1;      // secondary-ray depth bound, -1 = FrameRegisters::max_depth
  ff::Mode mode{};         // rounding of every FP unit
};

// Work counted per ray (docs/cycle-model.md).
struct RayCounters {
  std::uint64_t traversal_steps = 0;  // kd-node visits in which the ray was active
  std::uint64_t list_entries = 0;     // list entries fetched for the ray
  std::uint64_t mailbox_skips = 0;    // entries skipped because the ray already visited them
  std::uint64_t transformations = 0;  // ray transforms (generation, object, triangle)
  std::uint64_t intersections = 0;    // unit-triangle tests
  RayCounters& operator+=(const RayCounters& o) {
    traversal_steps += o.traversal_steps;
    list_entries += o.list_entries;
    mailbox_skips += o.mailbox_skips;
    transformations += o.transformations;
    intersections += o.intersections;
    return *this;
  }
  friend bool operator==(const RayCounters&, const RayCounters&) = default;
};

// A counter declared once (gem5's ADD_STAT): the name every report gives it, its unit, one line of
// description, and where it lives. The reports, stats.txt and the copies between the models all
// follow these tables, so a counter added to a struct and its table is reported everywhere.
template <class S>
struct CounterDecl {
  const char* name;
  const char* unit;
  const char* desc;
  std::uint64_t S::*member;
};

inline constexpr CounterDecl<RayCounters> kRayCounterDecls[] = {
    {"traversal_steps", "steps", "kd-tree traversal steps (inner, leaf and clip)",
     &RayCounters::traversal_steps},
    {"list_entries", "entries", "list entries read (objects and triangles)",
     &RayCounters::list_entries},
    {"mailbox_skips", "entries", "list entries skipped by the mailbox",
     &RayCounters::mailbox_skips},
    {"transformations", "steps", "rays transformed (into object or unit-triangle space)",
     &RayCounters::transformations},
    {"intersections", "tests", "ray-triangle intersection tests", &RayCounters::intersections},
};

enum class RayKind : std::uint8_t {
  kPrimary = 0,
  kShadow = 1,
  kReflection = 2,
  kTransparency = 3,
  kRefraction = 4,
};
inline constexpr int kRayKinds = 5;
inline const char* ray_kind_name(RayKind k) {
  constexpr const char* kNames[] = {"primary", "shadow", "reflection", "transparency",
                                    "refraction"};
  return kNames[static_cast<int>(k)];
}

// The hardware units of one DynRTP a thread may ask for: the five of Figure 2, then kNone (no unit:
// the thread is done). A unit added to the model takes an id after kNone from add_unit() below
// (README "adding a unit").
enum class UnitId : std::uint8_t {
  kRgs,
  kTransformation,
  kTraversal,
  kList,
  kIntersection,
  kNone,
};
// Unit ids: Figure 2's five, kNone and the added units (the slots of a DynRTP's unit arrays).
inline constexpr int kMaxUnits = 8;

// The states of the thread program. Each names the unit that serves it. A unit added to the model
// serves phases numbered after kDone (add_unit()).
enum class Phase : std::uint8_t {
  kGenerate,           // transformation (path a): R' through the RGS's T into world rays
  kClipTop,            // traversal: one face of the scene box (6 steps, D29)
  kTraverse,           // traversal (paths b, f): one kd-node step of the packet
  kList,               // list (path c): one list entry, mailboxed at the top level
  kTransformObject,    // transformation (path d): world -> object with the instance matrix
  kClipBottom,         // traversal: one face of the object box (6 steps)
  kTransformTriangle,  // transformation (path d): object -> unit-triangle space with T_delta
  kIntersect,          // intersection (path e): the packet's rays one per cycle
  kPop,                // traversal (f, list -> traversal): the stack's pop after a list ended
  kShadeSurface,       // RGS (path g): the surface hits of a primary/secondary packet
  kShadeLight,         // RGS: cosines of one light from its generated shadow rays
  kShadeShadow,        // RGS: shadow-ray results of one light
  kDone,
};
inline constexpr int kMaxPhases = 32;  // Phase values: the thread program's, kDone, the added ones

// A unit added to the DynRTP beyond Figure 2's five: its id and the phases it serves, numbered
// from `first_phase` in the order add_unit() was given their names.
struct AddedUnit {
  UnitId id = UnitId::kNone;
  Phase first_phase = Phase::kDone;
  Phase phase(int k) const { return static_cast<Phase>(static_cast<int>(first_phase) + k); }
};
// Registers an added unit under `name` with the names of the phases it serves; from then on
// unit_name, phase_name and phase_unit know them. Throws std::logic_error when a name is taken or
// the ids (kMaxUnits) or phases (kMaxPhases) are used up. Register before any run starts (a
// test's or a tool's start); the lookups below may then be called from any thread.
AddedUnit add_unit(const std::string& name, const std::vector<std::string>& phases);
// The added units' names and phases ("?" and kNone for a value nobody registered).
const char* added_unit_name(UnitId u);
const char* added_phase_name(Phase p);
UnitId added_phase_unit(Phase p);

inline const char* unit_name(UnitId u) {
  constexpr const char* kNames[] = {"rgs",  "transformation", "traversal",
                                    "list", "intersection",   "none"};
  return u <= UnitId::kNone ? kNames[static_cast<int>(u)] : added_unit_name(u);
}
inline const char* phase_name(Phase p) {
  constexpr const char* kNames[] = {
      "generate",    "clip_top",           "traverse",  "list", "transform_object",
      "clip_bottom", "transform_triangle", "intersect", "pop",  "shade_surface",
      "shade_light", "shade_shadow",       "done"};
  return p <= Phase::kDone ? kNames[static_cast<int>(p)] : added_phase_name(p);
}
inline UnitId phase_unit(Phase p) {
  switch (p) {
    case Phase::kGenerate:
    case Phase::kTransformObject:
    case Phase::kTransformTriangle:
      return UnitId::kTransformation;
    case Phase::kClipTop:
    case Phase::kTraverse:
    case Phase::kClipBottom:
    case Phase::kPop:
      return UnitId::kTraversal;
    case Phase::kList:
      return UnitId::kList;
    case Phase::kIntersect:
      return UnitId::kIntersection;
    case Phase::kShadeSurface:
    case Phase::kShadeLight:
    case Phase::kShadeShadow:
      return UnitId::kRgs;
    case Phase::kDone:
      return UnitId::kNone;
  }
  return added_phase_unit(p);
}

// What the thread asks of a unit next: enough for a cycle model to fetch the item through the
// unit's cache and to know how many pipeline slots the work takes.
struct Request {
  UnitId unit = UnitId::kNone;
  Phase phase = Phase::kDone;
  std::uint32_t item = memif::kNone;  // kTraverse: node; kList: list entry (kNone: the list is
                                      // done, nothing to read); kTransform*: first matrix row;
                                      // kClip*: face 0..5; otherwise kNone
  int steps = 0;           // transformation steps (n+1 or 2n), intersection cycles (P), else 1
  std::uint64_t mask = 0;  // the rays concerned
  // The pop engine's cycles of the request executed last (the traversal unit's stack, read one
  // entry per cycle): 1 + the entries it dropped when that request ended in a pop, else 0.
  std::uint16_t pop_cycles = 0;
};

// One memory access of the RGS (docs/memory-image.md, docs/memif.md and docs/shading.md;
// docs/shading.md "Shading traffic"): a read of `words` consecutive shading-bank words, or a
// one-word write of a finished pixel into a frame-buffer bank. Reads come in dependent waves: the
// shading record and the light records (0) name the material (1), which names the texels (2); a
// wave is read once the one before it has arrived. The thread program lists a request's accesses as
// it executes it (RgsStep::memory()); the cycle model's RGS issues them through the memory
// controller.
struct RgsAccess {
  std::uint32_t offset = 0;  // word offset within `bank`
  std::uint32_t data = 0;    // the word written (writes only)
  std::uint8_t bank = memif::kShadingBank;
  std::uint8_t words = 1;  // 1..memif::kMaxRequestWords (writes: 1)
  std::uint8_t wave = 0;   // read dependency wave: 0 record/light, 1 material, 2 texels
  bool write = false;
};

// A pixel channel from its weighted colour sum (docs/shading.md section 7): the sum / 255, rounded
// and clamped to 8 bits.
inline std::uint8_t pixel_channel(std::uint32_t colour_sum) {
  return static_cast<std::uint8_t>(std::min<std::uint32_t>(255u, (colour_sum + 127u) / 255u));
}
// A finished pixel as the RGS writes it into the frame buffer: R, G, B in bits 0..7, 8..15,
// 16..23 (the shading bank's RGB8 packing).
inline std::uint32_t pixel_word(const std::array<std::uint32_t, 3>& colour_sum) {
  std::uint32_t w = 0;
  for (int k = 0; k < 3; ++k)
    w |= std::uint32_t{pixel_channel(colour_sum[static_cast<std::size_t>(k)])} << (8 * k);
  return w;
}

// Unit transactions as the datapaths see them (units/unit_vectors.h: the vectors an RTL unit is
// checked against; units/request_trace.h: the per-request trace). Null in every model run but a
// capture or a traced one. `lane` is the packet lane (0..P-1) the transaction is for; -1 for a
// packet's shared origin (one step for every lane, D31).
template <class F>
class UnitTap {
 public:
  virtual ~UnitTap() = default;
  // One ray's lane of an inner kd-node step (traversal_lane's operands and results).
  virtual void traversal(int lane, F split, F o_axis, F d_axis, F tn, F tf, bool go_near,
                         bool go_far, F near_tf, F far_tn) = 0;
  // One matrix-vector step of ray generation or of an object or triangle transformation
  // (transform_step).
  virtual void transformation(int lane, const Mat34<F>& m, const Vec3<F>& in, bool translate,
                              const Vec3<F>& out) = 0;
  // One ray's unit-triangle intersection (intersect_unit_triangle).
  virtual void intersection(int lane, const Ray<F>& ray, const Candidate<F>& c) = 0;
};

// Work counted per unit, in the unit's own steps: the thread program counts it in PipelineUnits
// and the frame reports it (UnitStats) as the same struct.
struct UnitCounts {
  std::uint64_t traversal_steps = 0;       // kd-node steps (inner + leaf + empty)
  std::uint64_t inner_steps = 0;           // steps on inner nodes (P add, P div, 3P cmp)
  std::uint64_t clip_steps = 0;            // box-face steps (P add, P div, P (+P) cmp)
  std::uint64_t clips = 0;                 // box clips (scene box or object box)
  std::uint64_t exit_only_clips = 0;       // of them, exit faces only (origins inside the box)
  std::uint64_t list_steps = 0;            // list entries fetched
  std::uint64_t transformation_steps = 0;  // ray transformation steps (generation, object, tri)
  std::uint64_t shading_transformation_steps = 0;  // normal and dot-product steps of the RGS
  std::uint64_t intersection_packets = 0;          // packets intersected (P rays each)
  std::uint64_t sub_packets = 0;       // masked sub-packets from mixed direction signs (D27)
  std::uint64_t stack_drops = 0;       // stack entries dropped at the pop: every ray terminated
  std::uint64_t empty_leaf_steps = 0;  // of traversal_steps, on leaves without items
  std::uint64_t pop_steps = 0;         // pop requests of the traversal unit after a list (D49)
  std::uint64_t list_returns = 0;      // list unit steps without an entry: the list was done (D49)
};

inline constexpr CounterDecl<UnitCounts> kUnitCounterDecls[] = {
    {"traversal_steps", "steps", "kd-tree traversal steps (inner, leaf and clip)",
     &UnitCounts::traversal_steps},
    {"inner_steps", "steps", "inner-node steps of the traversal unit", &UnitCounts::inner_steps},
    {"clip_steps", "steps", "box-clip steps of the traversal unit", &UnitCounts::clip_steps},
    {"clips", "clips", "box clips", &UnitCounts::clips},
    {"exit_only_clips", "clips", "box clips on the exit faces only", &UnitCounts::exit_only_clips},
    {"list_steps", "steps", "list unit steps", &UnitCounts::list_steps},
    {"transformation_steps", "steps", "transformation unit steps",
     &UnitCounts::transformation_steps},
    {"shading_transformation_steps", "steps", "transformation unit steps for shading",
     &UnitCounts::shading_transformation_steps},
    {"intersection_packets", "packets", "packets through the intersection unit",
     &UnitCounts::intersection_packets},
    {"sub_packets", "packets", "packets split by the traversal", &UnitCounts::sub_packets},
    {"stack_drops", "entries", "traversal stack entries dropped", &UnitCounts::stack_drops},
    {"empty_leaf_steps", "steps", "steps into empty leaves", &UnitCounts::empty_leaf_steps},
    {"pop_steps", "steps", "pop requests of the traversal unit after a list ended",
     &UnitCounts::pop_steps},
    {"list_returns", "steps", "list unit steps that found the list done (no entry read)",
     &UnitCounts::list_returns},
};

// The float units of one DynRTP, each with its own counters (paper Table 2). The RGS FP helper is
// decision D10's optional shading helper (cosines: mul, sqrt, div; the refraction factor mu).
template <class F>
class PipelineUnits : public UnitCounts {
 public:
  explicit PipelineUnits(ff::Mode mode = {})
      : traversal(mode, &traversal_ops),
        transformation(mode, &transformation_ops),
        intersection(mode, &intersection_ops),
        rgs(mode, &rgs_ops),
        raw(mode),
        direct(mode) {}
  PipelineUnits(const PipelineUnits&) = delete;
  PipelineUnits& operator=(const PipelineUnits&) = delete;

  ff::OpCounts traversal_ops, transformation_ops, intersection_ops, rgs_ops;
  UnitFp<F> traversal, transformation, intersection, rgs;
  // The same operators without counters, for the datapath steps the thread program counts in
  // bulk: every step's op count is fixed by the datapath whatever the mask (D30: a masked lane
  // fires and its result is discarded), so the counts are added where the step is issued.
  RawFp<F> raw;
  RawFp<F, false> direct;     // without the zero shortcuts: the traversal unit's few zeros
  UnitTap<F>* tap = nullptr;  // unit transaction capture (units/unit_vectors.h)

  static void count(ff::OpCounts& c, std::uint64_t add, std::uint64_t mul, std::uint64_t div,
                    std::uint64_t cmp) {
    c.add += add;
    c.mul += mul;
    c.div += div;
    c.cmp += cmp;
  }
};

// Where a thread's results go: the frame the RGC hands pixels from.
struct FrameSink {
  int width = 0;
  int height = 0;
  // Per pixel: the primary ray's closest hit (encodings), its world ray, its counters.
  struct Pixel {
    std::uint32_t t = 0, u = 0, v = 0, cos = 0;
    std::uint32_t instance = memif::kNone, triangle = memif::kNone;
    std::array<std::uint32_t, 3> o{}, d{};
    RayCounters counters;
  };
  // A pixel's record is written whole when its primary packet's rays return to the RGS
  // (RgsStep::record_primary) and its colour sum starts at zero, so neither buffer is written
  // before the run (hw::ZeroPageAllocator): a run touches the pages of the pixels it hands out,
  // and the record of a pixel never handed out (a sampled run's skipped packets) is zero bytes.
  using PixelBuffer = std::vector<Pixel, hw::ZeroPageAllocator<Pixel>>;
  using ColourBuffer = std::vector<std::array<std::uint32_t, 3>,
                                   hw::ZeroPageAllocator<std::array<std::uint32_t, 3>>>;
  PixelBuffer pixels;
  ColourBuffer colour_sum;  // sum of weight * colour (docs 7)
  std::array<RayCounters, kRayKinds> by_kind{};
  std::array<std::uint64_t, kRayKinds> rays_issued{};
  std::array<std::uint64_t, kRayKinds> rays_returned{};

  // `every_pixel`: the run hands out every packet (huge pages) or a few (small pages: a 2 MiB page
  // holds about 20 rows of a 1024-pixel frame).
  void reset(int w, int h, bool every_pixel = true) {
    width = w;
    height = h;
    const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    PixelBuffer(n).swap(pixels);  // fresh zero pages: a reused buffer would keep the last frame
    ColourBuffer(n).swap(colour_sum);
    hw::advise_pages(pixels.data(), n * sizeof(Pixel), every_pixel);
    hw::advise_pages(colour_sum.data(), n * sizeof(colour_sum[0]), every_pixel);
    by_kind = {};
    rays_issued = {};
    rays_returned = {};
  }
};

}  // namespace saarcor::units
