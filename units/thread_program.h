// One DynRTP thread: a packet of P rays and all its state (DESIGN.md section 5: rays in world and
// current space, closest hit per ray, traversal stack, current level, list cursor, mailbox), and
// its control flow as an explicit state machine, the "thread program" (paper section 3.1, Figure 2,
// paths a-g; docs/functional-model.md). `request()` says which unit the thread needs next and
// what for; `execute()` performs that unit's work with the unit's datapath (units/datapath.h) and
// moves to the next state. The functional model runs a thread to completion; the cycle model
// queues the thread at the requested unit and calls execute() when the unit serves it. Both run
// the same code in the same per-thread order, so their results are bit-identical by construction.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "fixedfloat/float.h"
#include "memif/image_format.h"
#include "units/datapath.h"
#include "units/huge_pages.h"
#include "units/mailbox.h"
#include "units/shading.h"

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
  // Every datapath step on encodings in the paper's op order (units/datapath.h), none on the
  // binary64 fast paths: slower, the same results. The fast paths' independent check
  // (testbench/reference_datapath_test.cpp compares both frames step by step).
  bool reference_datapath = false;
  bool shade = true;       // run the RGS; false leaves the image black (hit records only)
  bool shadows = false;    // shadow rays (docs/shading.md 6.4); Table 3 setting: off
  bool secondary = false;  // reflection and transparency rays; Table 3 setting: off
  int max_depth = -1;      // secondary-ray depth bound, -1 = FrameRegisters::max_depth
  ff::Mode mode{};         // rounding of every FP unit
};

// Work counted per ray (DESIGN.md section 5; issue 4).
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

enum class RayKind : std::uint8_t { kPrimary = 0, kShadow = 1, kReflection = 2, kTransparency = 3 };
inline constexpr int kRayKinds = 4;
inline const char* ray_kind_name(RayKind k) {
  constexpr const char* kNames[] = {"primary", "shadow", "reflection", "transparency"};
  return kNames[static_cast<int>(k)];
}

// The hardware units of one DynRTP a thread may ask for.
enum class UnitId : std::uint8_t {
  kRgs,
  kTransformation,
  kTraversal,
  kList,
  kIntersection,
  kNone,
};
inline const char* unit_name(UnitId u) {
  constexpr const char* kNames[] = {"rgs",  "transformation", "traversal",
                                    "list", "intersection",   "none"};
  return kNames[static_cast<int>(u)];
}

// The states of the thread program. Each names the unit that serves it.
enum class Phase : std::uint8_t {
  kGenerate,           // transformation (path a): R' through the RGS's T into world rays
  kClipTop,            // traversal: one face of the scene box (6 steps, D29)
  kTraverse,           // traversal (paths b, f): one kd-node step of the packet
  kList,               // list (path c): one list entry, mailboxed at the top level
  kTransformObject,    // transformation (path d): world -> object with the instance matrix
  kClipBottom,         // traversal: one face of the object box (6 steps)
  kTransformTriangle,  // transformation (path d): object -> unit-triangle space with T_delta
  kIntersect,          // intersection (path e): the packet's rays one per cycle
  kShadeSurface,       // RGS (path g): the surface hits of a primary/secondary packet
  kShadeLight,         // RGS: cosines of one light from its generated shadow rays
  kShadeShadow,        // RGS: shadow-ray results of one light
  kDone,
};
inline const char* phase_name(Phase p) {
  constexpr const char* kNames[] = {
      "generate",         "clip_top",    "traverse",           "list",
      "transform_object", "clip_bottom", "transform_triangle", "intersect",
      "shade_surface",    "shade_light", "shade_shadow",       "done"};
  return kNames[static_cast<int>(p)];
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
  return UnitId::kNone;
}

// What the thread asks of a unit next: enough for a cycle model to fetch the item through the
// unit's cache and to know how many pipeline slots the work takes.
struct Request {
  UnitId unit = UnitId::kNone;
  Phase phase = Phase::kDone;
  std::uint32_t item = memif::kNone;  // kTraverse: node; kList: list entry; kTransform*: first
                                      // matrix row; kClip*: face 0..5; otherwise kNone
  int steps = 0;           // transformation steps (n+1 or 2n), intersection cycles (P), else 1
  std::uint64_t mask = 0;  // the rays concerned
};

// Unit transactions as the datapaths see them (units/unit_vectors.h: the vectors an RTL unit is
// checked against). Null in every model run; the capture sets it on a functional run.
template <class F>
class UnitTap {
 public:
  virtual ~UnitTap() = default;
  // One ray's lane of an inner kd-node step (traversal_lane's operands and results).
  virtual void traversal(F split, F o_axis, F d_axis, F tn, F tf, bool go_near, bool go_far,
                         F near_tf, F far_tn) = 0;
  // One matrix-vector step of ray generation or of an object or triangle transformation
  // (transform_step).
  virtual void transformation(const Mat34<F>& m, const Vec3<F>& in, bool translate,
                              const Vec3<F>& out) = 0;
  // One ray's unit-triangle intersection (intersect_unit_triangle).
  virtual void intersection(const Ray<F>& ray, const Candidate<F>& c) = 0;
};

// The float units of one DynRTP, each with its own counters (paper Table 2). The RGS FP helper is
// DIGEST D10's optional shading helper (cosines: mul, sqrt, div).
template <class F>
class PipelineUnits {
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

  // Work counted per unit, in the unit's own steps.
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
  // (HugePageAllocator: a frame's buffers are first touched in 2 MiB pages.)
  std::vector<Pixel, HugePageAllocator<Pixel>> pixels;
  std::vector<std::array<std::uint32_t, 3>, HugePageAllocator<std::array<std::uint32_t, 3>>>
      colour_sum;  // sum of weight * colour (docs 7)
  std::array<RayCounters, kRayKinds> by_kind{};
  std::array<std::uint64_t, kRayKinds> rays_issued{};
  std::array<std::uint64_t, kRayKinds> rays_returned{};

  void reset(int w, int h) {
    width = w;
    height = h;
    pixels.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), Pixel{});
    colour_sum.assign(pixels.size(), {0u, 0u, 0u});
    by_kind = {};
    rays_issued = {};
    rays_returned = {};
  }
};

// Direct reads of kd-nodes and list entries from the scene banks: what MemoryImage::node and
// list_entry compute (item i of a type in bank 3 + i mod 3 at word base[type] + (i div 3) * words),
// with the bank addresses taken once, and host prefetches of items the thread will read soon
// (no effect on results). Refreshed at every primary packet, so an image rebuilt between frames
// is read afresh.
class SceneView {
 public:
  void refresh(const memif::MemoryImage& image) {
    for (int b = 0; b < memif::kSceneBanks; ++b)
      bank_[static_cast<std::size_t>(b)] = image.bank(memif::kFirstSceneBank + b).data();
    node_base_ = image.regions().base[static_cast<std::size_t>(memif::ItemType::kNode)];
    list_base_ = image.regions().base[static_cast<std::size_t>(memif::ItemType::kList)];
    row_base_ = image.regions().base[static_cast<std::size_t>(memif::ItemType::kRow)];
    row_words_ = static_cast<std::uint32_t>(image.item_words(memif::ItemType::kRow));
  }
  std::uint32_t list_entry(std::uint32_t index) const {
    return bank_[index % memif::kSceneBanks][list_base_ + index / memif::kSceneBanks];
  }
  // The words of matrix row `index`.
  const std::uint32_t* row_words(std::uint32_t index) const {
    return bank_[index % memif::kSceneBanks] + row_base_ +
           (index / memif::kSceneBanks) * row_words_;
  }
  void prefetch_list(std::uint32_t index) const {
    __builtin_prefetch(bank_[index % memif::kSceneBanks] + list_base_ + index / memif::kSceneBanks);
  }
  // Rows first .. first + n - 1 (a row may straddle two host cache lines: both ends).
  void prefetch_rows(std::uint32_t first, std::uint32_t n) const {
    for (std::uint32_t r = first; r < first + n; ++r) {
      const std::uint32_t* w =
          bank_[r % memif::kSceneBanks] + row_base_ + (r / memif::kSceneBanks) * row_words_;
      __builtin_prefetch(w);
      __builtin_prefetch(w + row_words_ - 1u);
    }
  }
  memif::KdNode node(std::uint32_t index) const {
    const std::uint32_t* w = node_words(index);
    return memif::decode_node(w[0], w[1]);
  }
  void prefetch_node(std::uint32_t index) const { __builtin_prefetch(node_words(index)); }

 private:
  const std::uint32_t* node_words(std::uint32_t index) const {
    return bank_[index % memif::kSceneBanks] + node_base_ + (index / memif::kSceneBanks) * 2u;
  }
  std::array<const std::uint32_t*, memif::kSceneBanks> bank_{};
  std::uint32_t node_base_ = 0, list_base_ = 0, row_base_ = 0, row_words_ = 3;
};

// kLanes: the capacity of the packet arrays (>= P). A packet's per-lane values are kept field by
// field over kLanes slots, so a small capacity keeps a small packet's values in a few cache lines:
// the cycle model interleaves 64 programs, whose state has mostly left the L1 cache by the time a
// unit serves the thread again (P = 4 in 4 slots instead of 64: ~4% of a cycle-model frame).
template <class F, int kLanes = kMaxPacket>
class ThreadProgram {
  static_assert(kLanes >= 2 && kLanes <= kMaxPacket && (kLanes & (kLanes - 1)) == 0);

 public:
  ThreadProgram(const memif::MemoryImage& image, const FunctionalParams& params,
                PipelineUnits<F>& units, FrameSink& sink)
      : image_(image),
        params_(params),
        u_(units),
        sink_(sink),
        p_(params.packet),
        mailbox_(params.mailbox),
        tri_mailbox_(params.triangle_mailbox) {
    if (!(F::kFormat == image.format()))
      throw std::runtime_error("functional model: the image's float format " +
                               ff::format_name(image.format()) + " does not match the model's " +
                               ff::format_name(F::kFormat));
    if (p_ < 1 || p_ > kMaxPacket || (p_ & (p_ - 1)) != 0)
      throw std::runtime_error("functional model: packet width " + std::to_string(p_) +
                               " is not a power of two in 1..64");
    if (p_ > kLanes) throw std::logic_error("thread program: packet wider than its lane capacity");
    if (params.stack_depth < 1)
      throw std::runtime_error("functional model: stack depth must be at least 1");
    if (params.clip_faces_per_step < 1 || params.clip_faces_per_step > 6)
      throw std::runtime_error("functional model: clip faces per step " +
                               std::to_string(params.clip_faces_per_step) + " outside 1..6");
    lanes_.resize(static_cast<std::size_t>(p_));
    surf_.resize(static_cast<std::size_t>(p_));
    stack_node_.resize(static_cast<std::size_t>(params.stack_depth));
    stack_mask_.resize(static_cast<std::size_t>(params.stack_depth));
    slots_ = p_ + (p_ & 1);
    stack_t_.resize(static_cast<std::size_t>(params.stack_depth) * 2u *
                    static_cast<std::size_t>(slots_));
    const auto& regs = image.registers();
    max_depth_ =
        params.max_depth >= 0 ? static_cast<std::uint32_t>(params.max_depth) : regs.max_depth;
    for (int i = 0; i < 3; ++i) {
      cam_[i] = {F::from_bits(regs.cam_r[i]), F::from_bits(regs.cam_u[i]),
                 F::from_bits(regs.cam_d[i]), F::from_bits(regs.cam_p[i])};
      scene_lo_[i] = F::from_bits(regs.scene_min[i]);
      scene_hi_[i] = F::from_bits(regs.scene_max[i]);
    }
    epsilon_ = F::from_bits(regs.epsilon);
    // The binary64 paths decide only for nearest-even; reference_datapath turns them all off.
    nearest_ = !params.reference_datapath && params.mode.rounding == ff::Rounding::kNearestEven;
    cam_values_ = matrix_values(cam_);
    shadow_t_max_ = F::from_double(1.0 - 1.0 / 512.0);
  }

  // The RGC hands the thread the primary packet of pixels `pixel[i]` (memif::kNone = empty lane).
  void start_primary(const std::vector<std::uint32_t>& pixel) {
    pending_size_ = 0;
    scene_.refresh(image_);
    normal_instance_ = memif::kNone;
    const auto width = static_cast<std::uint32_t>(sink_.width);
    Packet& pk = gen_;  // built in place (begin_packet's copy is then a self-assignment)
    pk.kind = RayKind::kPrimary;
    pk.depth = 0;
    pk.shared_origin = params_.shared_origin;
    pk.lanes.assign(lanes_.size(), GenLane{});
    for (int i = 0; i < p_; ++i) {
      auto& g = pk.lanes[static_cast<std::size_t>(i)];
      g.t = cam_;
      g.ro = {F::zero(), F::zero(), F::zero()};
      const std::uint32_t px = i < static_cast<int>(pixel.size()) ? pixel[i] : memif::kNone;
      if (px == memif::kNone) continue;
      g.valid = true;
      g.pixel = px;
      g.weight = 255;
      // The pixel coordinates as F (exact binary64 integers, rounded once: as F::from_int).
      g.rd = {u_.raw.from_double(static_cast<double>(px % width)),
              u_.raw.from_double(static_cast<double>(px / width)), F::one()};
    }
    begin_packet(pk);
  }

  bool done() const { return phase_ == Phase::kDone; }
  Phase phase() const { return phase_; }

  Request request() const {
    Request r;
    r.phase = phase_;
    r.unit = phase_unit(phase_);
    r.steps = 1;
    switch (phase_) {
      case Phase::kGenerate:
        r.mask = valid_mask();
        r.steps = transform_steps();
        break;
      case Phase::kClipTop:
      case Phase::kClipBottom:
        r.item = static_cast<std::uint32_t>(clip_face_);
        r.mask = clip_mask_;
        break;
      case Phase::kTraverse:
        r.item = node_;
        r.mask = mask_;
        break;
      case Phase::kList: {
        const ListCursor& c = level_ == Level::kTop ? top_list_ : bottom_list_;
        r.item = c.next;
        r.mask = c.mask;
        break;
      }
      case Phase::kTransformObject:
        r.item = image_.registers().instance_row_base + memif::kInstanceRows * instance_;
        r.mask = entry_mask_;
        r.steps = transform_steps();
        break;
      case Phase::kTransformTriangle:
        r.item = header_.triangle_row_base + memif::kTriangleRows * triangle_;
        r.mask = entry_mask_;
        r.steps = transform_steps();
        break;
      case Phase::kIntersect:
        r.mask = entry_mask_;
        r.steps = p_;
        break;
      case Phase::kShadeSurface:
      case Phase::kShadeLight:
      case Phase::kShadeShadow:
        r.mask = valid_mask();
        break;
      case Phase::kDone:
        r.steps = 0;
        break;
    }
    return r;
  }

  // Performs the requested unit's work and advances the program.
  void execute() {
    switch (phase_) {
      case Phase::kGenerate:
        return do_generate();
      case Phase::kClipTop:
      case Phase::kClipBottom:
        return do_clip();
      case Phase::kTraverse:
        return do_traverse();
      case Phase::kList:
        return do_list();
      case Phase::kTransformObject:
        return do_transform_object();
      case Phase::kTransformTriangle:
        return do_transform_triangle();
      case Phase::kIntersect:
        return do_intersect();
      case Phase::kShadeSurface:
        return do_shade_surface();
      case Phase::kShadeLight:
        return do_shade_light();
      case Phase::kShadeShadow:
        return do_shade_shadow();
      case Phase::kDone:
        return;
    }
  }

  // Runs to completion (the functional model). Returns the number of requests served.
  std::uint64_t run() {
    std::uint64_t n = 0;
    while (phase_ != Phase::kDone) {
      // Runs of traversal steps without the dispatch (the same steps as execute()).
      if (phase_ == Phase::kTraverse) {
        do {
          do_traverse();
          ++n;
        } while (phase_ == Phase::kTraverse);
        continue;
      }
      execute();
      ++n;
    }
    return n;
  }

  RayKind kind() const { return kind_; }
  int packet_width() const { return p_; }

 private:
  enum class Level : std::uint8_t { kTop, kBottom };

  // What the RGS hands the transformation unit for one lane (path a): T and R'.
  struct GenLane {
    bool valid = false;
    std::uint32_t pixel = memif::kNone;
    std::uint32_t weight = 0;
    Mat34<F> t{};
    Vec3<F> ro{}, rd{};
  };
  struct Packet {
    RayKind kind = RayKind::kPrimary;
    std::uint32_t depth = 0;
    bool shared_origin = false;
    std::vector<GenLane> lanes;
  };

  struct Lane {
    bool valid = false;  // carries a ray of the current packet
    bool done = false;   // any-hit satisfied (shadow rays, D15)
    std::uint32_t pixel = memif::kNone;
    std::uint32_t weight = 0;
    Ray<F> world, current, tri;
    HitRecord<F> hit;  // hit.t = t_best (starts at the ray's t_max)
    RayCounters counters;
  };

  // The traversal unit works on binary64 values (datapath.h, traversal_lane64): O and 1/D per
  // axis of the world and of the current (object) ray, and the segments. Every one is the exact
  // value of an encoding of F, so the encodings are recovered exactly where the encoding path is
  // needed. Kept per packet as arrays over the lanes, so two lanes go through one vector op
  // (datapath.h, traversal_pair64); slots from P up to the next even count are padding, computed
  // along and never used. A lane's tn, tf are meaningful only while it is in the packet's mask:
  // it enters the mask only where they are set (start of a sign group, pop, the near child), so
  // whole-array copies may overwrite the others.
  using Slots = std::array<double, kLanes>;
  struct alignas(16) LaneValues {
    std::array<Slots, 3> world_o{}, world_inv{}, o{}, inv{};
    Slots tn{}, tf{};            // segment of the node being visited
    Slots clip_tn{}, clip_tf{};  // the level's clipped segment (restart of a sign group)
    Slots t_best{};              // value of hit.t
  };

  // The RGS's per-lane surface context while it shades a packet's hits.
  struct Surface {
    bool hit = false;
    std::uint32_t pixel = memif::kNone;
    std::uint32_t weight = 0;
    std::uint32_t depth = 0;
    Ray<F> ray;
    HitRecord<F> rec;
    Vec3<F> n{};
    F nn{}, kk{}, rr{};
    Vec3<F> r{};  // reflected view direction (specular)
    bool spec = false;
    memif::MaterialRecord mat;
    Rgb8 base{}, spec_rgb{};
    std::array<std::uint32_t, 3> acc{};
    F cos{}, cos_s{};
    bool lit = false, highlight = false;
  };

  struct ListCursor {
    std::uint32_t next = 0, end = 0;
    std::uint64_t mask = 0;
  };

  std::uint64_t valid_mask() const {
    std::uint64_t m = 0;
    for (int i = 0; i < p_; ++i)
      if (lanes_[static_cast<std::size_t>(i)].valid) m |= std::uint64_t{1} << i;
    return m;
  }
  int transform_steps() const { return shared_origin_ ? p_ + 1 : 2 * p_; }
  // One ray transformation of the packet: 9 mul and 9 add per step (n+1 or 2n steps, D30/D31).
  void count_transform() {
    const auto steps = static_cast<std::uint64_t>(transform_steps());
    u_.transformation_steps += steps;
    PipelineUnits<F>::count(u_.transformation_ops, 9 * steps, 9 * steps, 0, 0);
  }
  Lane& lane(int i) { return lanes_[static_cast<std::size_t>(i)]; }
  // O and 1/D (traversal_reciprocal) of every lane's ray `ray`, the reciprocals two lanes per
  // division (the same binary64 quotients). Lanes outside the level's mask get values nothing
  // reads.
  void set_axis_values(std::array<Slots, 3>& o, std::array<Slots, 3>& inv, Ray<F> Lane::*ray) {
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    for (int i = 0; i < p_; i += 2) {
      const Ray<F>& a = lane(i).*ray;
      const Ray<F>& b = lane(i + 1 < p_ ? i + 1 : i).*ray;
      const auto s = static_cast<std::size_t>(i);
      for (std::size_t k = 0; k < 3; ++k) {
        const int c = static_cast<int>(k);
        o[k][s] = value(a.o[c]);
        o[k][s + 1] = value(b.o[c]);
        // Decoded as if normal; lanes whose D is not normal (or truncation) get NaN.
        const V2d r = 1.0 / decode_pair<F>(a.d[c].bits, b.d[c].bits);
        inv[k][s] =
            nearest_ && ff::fast::is_normal<F::kExpBits, F::kManBits>(a.d[c].bits) ? r[0] : kNaN;
        inv[k][s + 1] =
            nearest_ && ff::fast::is_normal<F::kExpBits, F::kManBits>(b.d[c].bits) ? r[1] : kNaN;
      }
    }
  }
  // O and 1/D of the current level's rays.
  const std::array<Slots, 3>& level_o() const { return level_ == Level::kTop ? v_.world_o : v_.o; }
  const std::array<Slots, 3>& level_inv() const {
    return level_ == Level::kTop ? v_.world_inv : v_.inv;
  }
  static V2d load2(const double* p) {
    V2d v;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  static void store2(double* p, V2d v) { std::memcpy(p, &v, sizeof v); }
  // Copies the slots in use, a pair at a time (P = 4: two vector moves, no library call).
  void copy_slots(double* dst, const double* src) const {
    for (int i = 0; i < slots_; i += 2)
      store2(dst + i, load2(src + i));
  }
  double value(F x) const { return value_of(x, u_.raw.mode().subnormals); }

  // A transformation step (transform_step) through the binary64 path where it decides.
  using Mat64 = MatrixValues<F>;
  Mat64 matrix_values(const Mat34<F>& m) const {
    bool normal = true;  // every entry zero or normal: decoded two at a time (the same values)
    for (const auto& r : m)
      for (const F x : r)
        normal &= normal_or_zero(x);
    if (!normal) {
      Mat64 v = units::matrix_values(m, u_.raw.mode().subnormals);
      v.nearest = nearest_;
      return v;
    }
    Mat64 v;
    for (std::size_t r = 0; r < 3; ++r) {
      const auto& row = m[static_cast<int>(r)];
      for (int c = 0; c < 4; c += 2) {
        const V2d x = decode_pair<F>(row[c].bits, row[c + 1].bits);
        v.m[r][static_cast<std::size_t>(c)] = x[0];
        v.m[r][static_cast<std::size_t>(c + 1)] = x[1];
      }
      v.linear.include(row[0]);
      v.linear.include(row[1]);
      v.linear.include(row[2]);
      v.translation.include(row[3]);
    }
    v.nearest = nearest_;
    return v;
  }
  // One vector: the two-lane path with both lanes the same (fewer moves than the scalar path).
  Vec3<F> transform(const Mat34<F>& m, const Mat64& mv, const Vec3<F>& v, bool translate) const {
    if (!transform_decides<F>(mv, v, translate)) return transform_step(u_.raw, m, v, translate);
    const V2d x[3] = {decode_pair<F>(v[0].bits, v[0].bits), decode_pair<F>(v[1].bits, v[1].bits),
                      decode_pair<F>(v[2].bits, v[2].bits)};
    V2u r[3];
    transform_pair64<F>(mv, x, translate, r);
    return lane_of<F>(r, 0);
  }
  // As read_row / read_matrix (datapath.h), through the cached bank addresses, with the row's
  // packing known at compile time (fixedfloat/pack.h: four 24-bit fields in three words for
  // formats up to 24 bits, else one word each).
  std::array<F, 4> row(std::uint32_t index) const {
    const std::uint32_t* w = scene_.row_words(index);
    constexpr std::uint32_t kMask = F::kFormat.bits_mask();
    if constexpr (ff::row_words(F::kFormat) == 3) {
      return {F{w[0] & kMask}, F{((w[0] >> 24) | (w[1] << 8)) & kMask},
              F{((w[1] >> 16) | (w[2] << 16)) & kMask}, F{(w[2] >> 8) & kMask}};
    } else {
      return {F{w[0] & kMask}, F{w[1] & kMask}, F{w[2] & kMask}, F{w[3] & kMask}};
    }
  }
  Mat34<F> matrix(std::uint32_t first_row) const {
    return {row(first_row), row(first_row + 1), row(first_row + 2)};
  }
  // out(i) = m * in(i) (a transformation step) for the lanes in `mask`: two lanes at a time on
  // values where transform_decides holds for both or one of them, the others on encodings.
  template <class In, class Out>
  void transform_masked(const Mat34<F>& m, const Mat64& mv, std::uint64_t mask, bool translate,
                        In in, Out out) {
    for (int i = 0; i < p_; i += 2) {
      const int j = i + 1 < p_ ? i + 1 : i;
      const bool a = has(mask, i), b = j != i && has(mask, j);
      if (!(a | b)) continue;
      const Vec3<F>& va = in(i);
      const Vec3<F>& vb = in(j);
      const bool da = a && transform_decides<F>(mv, va, translate);
      const bool db = b && transform_decides<F>(mv, vb, translate);
      if (da | db) {
        const V2d x[3] = {decode_pair<F>(va[0].bits, vb[0].bits),
                          decode_pair<F>(va[1].bits, vb[1].bits),
                          decode_pair<F>(va[2].bits, vb[2].bits)};
        V2u r[3];
        transform_pair64<F>(mv, x, translate, r);
        if (da) out(i) = lane_of<F>(r, 0);
        if (db) out(j) = lane_of<F>(r, 1);
      }
      if (a && !da) out(i) = transform_step(u_.raw, m, in(i), translate);
      if (b && !db) out(j) = transform_step(u_.raw, m, in(j), translate);
    }
  }
  F encoding(double v) const { return u_.raw.from_double(v); }  // exact: v is a value of F
  static bool has(std::uint64_t m, int i) { return ((m >> i) & 1u) != 0; }

  // ---- packet start (path a) ------------------------------------------------------------------
  void begin_packet(const Packet& pk) {
    mailbox_.clear();  // a mailbox belongs to one packet's rays (D28)
    kind_ = pk.kind;
    depth_ = pk.depth;
    shared_origin_ = pk.shared_origin;
    gen_ = pk;
    for (int i = 0; i < p_; ++i)
      traversal_steps_[static_cast<std::size_t>(i)] = 0;
    for (int i = 0; i < p_; ++i) {
      Lane& l = lane(i);
      const GenLane& g = pk.lanes[static_cast<std::size_t>(i)];
      static const Lane kClear{};
      l = kClear;  // a copy of the defaults: Lane{} compiles to a string store that costs more
      l.valid = g.valid;
      l.pixel = g.pixel;
      l.weight = g.weight;
    }
    phase_ = Phase::kGenerate;
  }

  void do_generate() {
    count_transform();
    const auto& g0 = gen_.lanes[0];
    Vec3<F> shared{};
    const Mat64 mv0 = g0.t == cam_ ? cam_values_ : matrix_values(g0.t);
    if (shared_origin_) shared = transform(g0.t, mv0, g0.ro, true);
    // Lanes usually share T (primary rays: the camera's): those with lane 0's T two at a time,
    // the others one by one, T decoded once per distinct T.
    std::uint64_t same = 0, other = 0;
    for (int i = 0; i < p_; ++i) {
      Lane& l = lane(i);
      const GenLane& g = gen_.lanes[static_cast<std::size_t>(i)];
      if (!l.valid || shared_origin_) l.world.o = shared;
      if (l.valid) (g.t == g0.t ? same : other) |= std::uint64_t{1} << i;
    }
    const auto gen = [&](int i) -> const GenLane& {
      return gen_.lanes[static_cast<std::size_t>(i)];
    };
    if (!shared_origin_)
      transform_masked(
          g0.t, mv0, same, true, [&](int i) -> const Vec3<F>& { return gen(i).ro; },
          [&](int i) -> Vec3<F>& { return lane(i).world.o; });
    transform_masked(
        g0.t, mv0, same, false, [&](int i) -> const Vec3<F>& { return gen(i).rd; },
        [&](int i) -> Vec3<F>& { return lane(i).world.d; });
    if (other != 0) {
      Mat34<F> mt = g0.t;
      Mat64 mv = mv0;
      for (int i = 0; i < p_; ++i) {
        if (!has(other, i)) continue;
        const GenLane& g = gen(i);
        if (!(g.t == mt)) {
          mt = g.t;
          mv = matrix_values(g.t);
        }
        if (!shared_origin_) lane(i).world.o = transform(g.t, mv, g.ro, true);
        lane(i).world.d = transform(g.t, mv, g.rd, false);
      }
    }
    if (u_.tap != nullptr) [[unlikely]]
      tap_generate(shared);
    for (int i = 0; i < p_; ++i) {
      Lane& l = lane(i);
      l.current = l.world;
      l.hit = HitRecord<F>{};
      if (kind_ == RayKind::kShadow) l.hit.t = shadow_t_max_;
      v_.t_best[static_cast<std::size_t>(i)] = value(l.hit.t);
      if (l.valid) ++l.counters.transformations;
    }
    set_axis_values(v_.world_o, v_.world_inv, &Lane::world);
    if (kind_ == RayKind::kShadow) {
      phase_ = Phase::kShadeLight;  // the RGS decides which shadow rays to trace
      return;
    }
    issue_rays();
  }

  void issue_rays() {
    for (int i = 0; i < p_; ++i)
      if (lane(i).valid) ++sink_.rays_issued[static_cast<int>(kind_)];
    start_level(Level::kTop);
  }

  // ---- levels, clipping and sign groups (D27, D29) --------------------------------------------
  void start_level(Level level) {
    level_ = level;
    clip_face_ = 0;
    // The box the six clip steps read: the scene box, or rows 4-5 of the instance record.
    if (level == Level::kTop) {
      box_lo_ = scene_lo_;
      box_hi_ = scene_hi_;
    } else {
      const auto rlo = row(instance_row_ + 4);
      const auto rhi = row(instance_row_ + 5);
      box_lo_ = {rlo[0], rlo[1], rlo[2]};
      box_hi_ = {rhi[0], rhi[1], rhi[2]};
    }
    if (level == Level::kTop) {
      clip_mask_ = 0;
      for (int i = 0; i < p_; ++i)
        if (lane(i).valid && !lane(i).done) clip_mask_ |= std::uint64_t{1} << i;
      for (int i = 0; i < p_; ++i)
        lane(i).current = lane(i).world;
      phase_ = Phase::kClipTop;
    } else {
      clip_mask_ = entry_mask_;
      phase_ = Phase::kClipBottom;
    }
    for (int i = 0; i < slots_; ++i) {
      v_.clip_tn[static_cast<std::size_t>(i)] = 0.0;
      v_.clip_tf[static_cast<std::size_t>(i)] = v_.t_best[static_cast<std::size_t>(i)];
    }
    // Faces in the order x entry, x exit, y entry, ...: the exit faces alone (odd faces) when every
    // ray starts inside the box (the comparators decide it with the first step).
    clip_stride_ = params_.clip_exit_only && origins_inside_box() ? 2 : 1;
    clip_face_ = clip_stride_ - 1;
    ++u_.clips;
    u_.exit_only_clips += clip_stride_ == 2 ? 1 : 0;
  }

  // True when every ray of the clip mask has its origin in the level's box (closed): its entry
  // distances are then <= 0 (or NaN, which keeps the bound) and leave tn at 0.
  bool origins_inside_box() const {
    for (std::uint64_t m = clip_mask_; m != 0; m &= m - 1) {
      const Lane& l = lanes_[static_cast<std::size_t>(std::countr_zero(m))];
      for (std::size_t k = 0; k < 3; ++k) {
        const double o = value(l.current.o[k]);
        if (!(o >= value(box_lo_[k]) && o <= value(box_hi_[k]))) return false;
      }
    }
    return true;
  }

  void do_clip() {
    ++u_.clip_steps;
    const auto lanes = static_cast<std::uint64_t>(p_);
    // The faces this step divides for: clip_faces_per_step of the sequence (all six, or the
    // three exit faces), fewer in the last step.
    const int left = (6 - clip_face_ + clip_stride_ - 1) / clip_stride_;
    const auto faces = static_cast<std::uint64_t>(std::min(left, params_.clip_faces_per_step));
    const bool first = clip_face_ == clip_stride_ - 1;
    const bool last = faces == static_cast<std::uint64_t>(left);
    // Per lane and face 1 add, 1 div, 1 cmp; the last face 1 more cmp (the empty-segment test).
    // With exit faces only, 2 more cmp per lane in the first step (origin against the box).
    const std::uint64_t cmp =
        faces * lanes + (last ? lanes : 0) + (clip_stride_ == 2 && first ? 2 * lanes : 0);
    PipelineUnits<F>::count(u_.traversal_ops, faces * lanes, 0, faces * lanes, cmp);
    // The face steps only change the lanes' clipped segments, which nothing reads before the
    // last face; so the first step computes all six (per lane in face order, the same results:
    // a skipped entry face leaves tn at 0) and saves the other passes over the packet.
    if (first) clip_box();
    clip_face_ += clip_stride_ * static_cast<int>(faces);
    if (!last) return;
    // Last face: a ray misses the box when its segment is empty (1 cmp per lane). Sign groups:
    // rays with equal direction signs share one front-to-back order (D27). Groups in increasing
    // sign-pattern order; each is a masked sub-packet traversed to the end.
    std::array<std::uint64_t, 8> by_pattern{};
    for (int i = 0; i < p_; ++i) {
      const Lane& l = lane(i);
      const auto k = static_cast<std::size_t>(i);
      if (!has(clip_mask_, i) || v_.clip_tf[k] < v_.clip_tn[k]) continue;
      const int s = (l.current.d[0].sign() ? 1 : 0) | (l.current.d[1].sign() ? 2 : 0) |
                    (l.current.d[2].sign() ? 4 : 0);
      by_pattern[static_cast<std::size_t>(s)] |= std::uint64_t{1} << i;
    }
    n_groups_ = 0;
    for (const std::uint64_t g : by_pattern)
      if (g != 0) groups_[n_groups_++] = g;
    if (n_groups_ > 1) u_.sub_packets += n_groups_ - 1;
    group_ = 0;
    stack_base_ = stack_size_;
    if (n_groups_ == 0) {
      finish_level();
      return;
    }
    start_group();
  }

  // The slab clip of the level's box (D29), faces 0..5: x entry, x exit, y entry, ... The entry
  // face is lo for a positive direction, hi for a negative one; the exit face the other.
  void clip_box() {
    const auto& fp = u_.direct;
    std::array<double, 3> lo_value, hi_value;
    for (std::size_t k = 0; k < 3; ++k) {
      lo_value[k] = value(box_lo_[k]);
      hi_value[k] = value(box_hi_[k]);
    }
    const auto& lo = level_o();
    const auto& inv = level_inv();
    // Two lanes at a time through the six faces on values; a lane that any face does not decide
    // there is redone alone from its start values (0, t_best), face by face as below.
    std::uint64_t redo = 0;
    for (int i = 0; i < p_; i += 2) {
      const std::uint64_t lanes = (clip_mask_ >> i) & 3u;
      if (lanes == 0) continue;
      const Lane& l0 = lane(i);
      const Lane& l1 = lane(i + 1 < p_ ? i + 1 : i);
      const auto s = static_cast<std::size_t>(i);
      V2i ok = {-1, -1};
      V2d tn = load2(&v_.clip_tn[s]), tf = load2(&v_.clip_tf[s]);
      for (int axis = 0; axis < 3; ++axis) {
        const auto k = static_cast<std::size_t>(axis);
        // Per lane: the entry face is lo for a positive direction (sign bit clear).
        const V2i neg = {l0.current.d[axis].sign() ? -1 : 0, l1.current.d[axis].sign() ? -1 : 0};
        const V2d lo_plane = {lo_value[k], lo_value[k]}, hi_plane = {hi_value[k], hi_value[k]};
        const V2d o = load2(&lo[k][s]), d = load2(&inv[k][s]);
        clip_face_pair64<F>(select2(neg, hi_plane, lo_plane), o, d, true, tn, tf, ok);
        clip_face_pair64<F>(select2(neg, lo_plane, hi_plane), o, d, false, tn, tf, ok);
      }
      const std::uint64_t decided = lanes & mask2(ok);
      if ((decided & 1u) != 0) {
        v_.clip_tn[s] = tn[0];
        v_.clip_tf[s] = tf[0];
      }
      if ((decided & 2u) != 0) {
        v_.clip_tn[s + 1] = tn[1];
        v_.clip_tf[s + 1] = tf[1];
      }
      redo |= (lanes & ~decided) << i;
    }
    for (; redo != 0; redo &= redo - 1) {
      const int i = std::countr_zero(redo);
      const auto s = static_cast<std::size_t>(i);
      const Lane& l = lane(i);
      double& clip_tn = v_.clip_tn[s];
      double& clip_tf = v_.clip_tf[s];
      for (int face = 0; face < 6; ++face) {
        const int axis = face / 2;
        const auto k = static_cast<std::size_t>(axis);
        const bool entry = (face % 2) == 0;
        const bool lo_face = entry != l.current.d[axis].sign();
        if (clip_face64<F>(lo_face ? lo_value[k] : hi_value[k], lo[k][s], inv[k][s], entry, clip_tn,
                           clip_tf))
          continue;
        F tn = encoding(clip_tn), tf = encoding(clip_tf);
        clip_face(fp, lo_face ? box_lo_[k] : box_hi_[k], l.current.o[axis], l.current.d[axis],
                  entry, tn, tf);
        clip_tn = value(tn);
        clip_tf = value(tf);
      }
    }
  }

  void start_group() {
    const std::uint64_t g = groups_[group_];
    // The other lanes' tn, tf are not read while they are outside the mask (LaneValues).
    copy_slots(v_.tn.data(), v_.clip_tn.data());
    copy_slots(v_.tf.data(), v_.clip_tf.data());
    node_ = level_ == Level::kTop ? image_.registers().top_root : header_.root;
    mask_ = g;
    // Groups of a level live on the stack one after another: a level keeps its base.
    phase_ = Phase::kTraverse;
  }

  // ---- traversal unit (paths b, f) -----------------------------------------------------------
  void do_traverse() {
    const auto& fp = u_.direct;
    ++u_.traversal_steps;
    const auto lanes = static_cast<std::uint64_t>(p_);
    PipelineUnits<F>::count(u_.traversal_ops, 0, 0, 0, lanes);  // termination, 1 cmp per lane
    const memif::KdNode node = scene_.node(node_);
    // Early termination at node entry (1 cmp per lane): t_best < tn leaves.
    std::uint64_t terminated = 0;
    for (int i = 0; i < p_; i += 2) {
      const auto s = static_cast<std::size_t>(i);
      terminated |= mask2(load2(&v_.t_best[s]) < load2(&v_.tn[s])) << i;
    }
    std::uint64_t active = mask_ & ~terminated;
    if (kind_ == RayKind::kShadow) active &= ~done_mask();
    for (int i = 0; i < p_; ++i)
      traversal_steps_[static_cast<std::size_t>(i)] += (active >> i) & 1u;
    if (active == 0) return pop();
    if (node.leaf) {
      if (node.count == 0) {
        ++u_.empty_leaf_steps;
        return pop();
      }
      for (std::uint32_t k = 0; k < node.count && k < 8u; ++k)
        scene_.prefetch_list(node.first + k);
      ListCursor& c = level_ == Level::kTop ? top_list_ : bottom_list_;
      c.next = node.first;
      c.end = node.first + node.count;
      c.mask = active;
      phase_ = Phase::kList;
      return;
    }
    ++u_.inner_steps;
    // Host-side prefetch of both children's node words (one of them is the next step's node,
    // the other may be pushed): no effect on results.
    scene_.prefetch_node(node.child_pair);
    scene_.prefetch_node(node.child_pair + 1);
    PipelineUnits<F>::count(u_.traversal_ops, lanes, 0, lanes, 2 * lanes);  // traversal_lane
    const int axis = static_cast<int>(node.axis);
    const F split = F::from_bits(node.split);
    // The group's shared direction sign on this axis picks the near child.
    const bool neg = lane(std::countr_zero(active)).current.d[axis].sign();
    std::uint64_t near_mask = 0, far_mask = 0, fail = 0;
    alignas(16) Slots near_tf, far_tn;  // slots 0..P-1 (rounded up to even) set below
    const double split_value = value(split);
    const V2d split2 = {split_value, split_value};
    const auto a = static_cast<std::size_t>(axis);
    const Slots& o = level_o()[a];
    const Slots& inv = level_inv()[a];
    // Two lanes at a time on values (inactive lanes are computed along and dropped).
    for (int i = 0; i < p_; i += 2) {
      const auto s = static_cast<std::size_t>(i);
      const TraversalPair64 r = traversal_pair64<F>(split2, load2(&o[s]), load2(&inv[s]),
                                                    load2(&v_.tn[s]), load2(&v_.tf[s]));
      near_mask |= r.go_near << i;
      far_mask |= r.go_far << i;
      fail |= r.fail << i;
      store2(&near_tf[s], r.near_tf);
      store2(&far_tn[s], r.far_tn);
    }
    near_mask &= active;
    far_mask &= active;
    // Lanes the value path does not decide: the encoding path.
    for (std::uint64_t m = fail & active; m != 0; m &= m - 1) {
      const int i = std::countr_zero(m);
      const auto s = static_cast<std::size_t>(i);
      const Lane& l = lane(i);
      const TraversalLane<F> e = traversal_lane(fp, split, l.current.o[axis], l.current.d[axis],
                                                encoding(v_.tn[s]), encoding(v_.tf[s]));
      const std::uint64_t bit = std::uint64_t{1} << i;
      near_mask = e.go_near ? near_mask | bit : near_mask & ~bit;
      far_mask = e.go_far ? far_mask | bit : far_mask & ~bit;
      near_tf[s] = value(e.near_tf);
      far_tn[s] = value(e.far_tn);
    }
    if (u_.tap != nullptr) [[unlikely]]
      for (std::uint64_t m = active; m != 0; m &= m - 1) {
        const int i = std::countr_zero(m);
        const auto s = static_cast<std::size_t>(i);
        const Lane& l = lane(i);
        u_.tap->traversal(split, l.current.o[axis], l.current.d[axis], encoding(v_.tn[s]),
                          encoding(v_.tf[s]), has(near_mask, i), has(far_mask, i),
                          encoding(near_tf[s]), encoding(far_tn[s]));
      }
    const std::uint32_t near_child = neg ? node.child_pair + 1 : node.child_pair;
    const std::uint32_t far_child = neg ? node.child_pair : node.child_pair + 1;
    // An empty child is dropped here: its lanes are done with it (same results, no step).
    const bool skip_near = params_.skip_empty && (neg ? node.empty_right : node.empty_left);
    const bool skip_far = params_.skip_empty && (neg ? node.empty_left : node.empty_right);
    if (skip_near) near_mask = 0;
    if (skip_far) far_mask = 0;
    if (far_mask != 0 && near_mask != 0) {
      push(far_child, far_mask, far_tn);
      // Lanes outside near_mask leave the mask: their tf is not read (LaneValues).
      copy_slots(v_.tf.data(), near_tf.data());
      node_ = near_child;
      mask_ = near_mask;
    } else if (near_mask != 0) {
      // A skipped far child: the near segment ends at the plane, as when both are visited.
      if (skip_far) copy_slots(v_.tf.data(), near_tf.data());
      node_ = near_child;
      mask_ = near_mask;
    } else if (far_mask != 0) {
      if (skip_near) copy_slots(v_.tn.data(), far_tn.data());
      node_ = far_child;
      mask_ = far_mask;
    } else {
      pop();
    }
  }

  // Stack entry: node, mask, and per slot the far segment's tn, then per slot tf.
  void push(std::uint32_t node, std::uint64_t mask, const Slots& far_tn) {
    if (stack_size_ >= stack_node_.size())
      throw std::runtime_error("functional model: traversal stack overflow (depth " +
                               std::to_string(params_.stack_depth) +
                               "); the kd-trees are deeper than the stack");
    stack_node_[stack_size_] = node;
    stack_mask_[stack_size_] = mask;
    const auto n = static_cast<std::size_t>(slots_);
    double* t = &stack_t_[stack_size_ * 2u * n];
    copy_slots(t, far_tn.data());
    copy_slots(t + n, v_.tf.data());
    ++stack_size_;
  }

  // Pops the next node of the current group, or ends the group.
  void pop() {
    // Entries whose rays have all finished (any-hit) are dropped without a node fetch.
    if (kind_ == RayKind::kShadow) {
      const std::uint64_t done = done_mask();
      while (stack_size_ > stack_base_ && (stack_mask_[stack_size_ - 1] & ~done) == 0)
        --stack_size_;
    }
    // Early termination at the pop (paper section 3.1): the entry holds each ray's tn, so the
    // node-entry test (t_best < tn) runs on the stack's values before any node fetch, and an
    // entry whose rays have all terminated is dropped without a traversal step. The same lanes
    // terminate as at node entry, so every result is unchanged; what is saved is one node fetch
    // and one traversal slot per entry left behind a hit.
    while (stack_size_ > stack_base_ && entry_terminated(stack_size_ - 1)) {
      --stack_size_;
      ++u_.stack_drops;
    }
    // The compare of the entry popped below is its node-entry test, counted with its step.
    if (stack_size_ == stack_base_) return finish_group();
    --stack_size_;
    node_ = stack_node_[stack_size_];
    mask_ = stack_mask_[stack_size_];
    // Every slot: lanes outside the entry's mask are not read until set again (LaneValues).
    const auto n = static_cast<std::size_t>(slots_);
    const double* t = &stack_t_[stack_size_ * 2u * n];
    copy_slots(v_.tn.data(), t);
    copy_slots(v_.tf.data(), t + n);
    phase_ = Phase::kTraverse;
  }

  // True when every lane of stack entry e has its closest hit before the entry's tn.
  // 1 cmp per lane, counted with the drop (the stack's comparators, not a traversal step).
  bool entry_terminated(std::size_t e) {
    const double* tn = &stack_t_[e * 2u * static_cast<std::size_t>(slots_)];
    for (std::uint64_t m = stack_mask_[e]; m != 0; m &= m - 1) {
      const auto k = static_cast<std::size_t>(std::countr_zero(m));
      if (!(v_.t_best[k] < tn[k])) return false;
    }
    PipelineUnits<F>::count(u_.traversal_ops, 0, 0, 0, static_cast<std::uint64_t>(p_));
    return true;
  }

  std::uint64_t done_mask() const {
    std::uint64_t m = 0;
    for (int i = 0; i < p_; ++i)
      if (lanes_[static_cast<std::size_t>(i)].done) m |= std::uint64_t{1} << i;
    return m;
  }

  void finish_group() {
    if (++group_ < n_groups_) return start_group();
    finish_level();
  }

  void finish_level() {
    if (level_ == Level::kBottom) {
      // Back to the top level: its groups, stack base and list cursor were saved at entry.
      level_ = Level::kTop;
      groups_ = top_groups_;
      n_groups_ = top_n_groups_;
      group_ = top_group_;
      stack_base_ = top_stack_base_;
      for (int i = 0; i < p_; ++i)
        lane(i).current = lane(i).world;
      return list_continue();
    }
    phase_ = kind_ == RayKind::kShadow ? Phase::kShadeShadow : Phase::kShadeSurface;
    for (int i = 0; i < p_; ++i)
      if (lane(i).valid) ++sink_.rays_returned[static_cast<int>(kind_)];
  }

  // ---- mailboxed list unit (paths c, d) ------------------------------------------------------
  void list_continue() {
    ListCursor& c = level_ == Level::kTop ? top_list_ : bottom_list_;
    const std::uint64_t live = kind_ == RayKind::kShadow ? c.mask & ~done_mask() : c.mask;
    c.mask = live;
    if (c.next < c.end && live != 0) {
      phase_ = Phase::kList;
      return;
    }
    pop();
  }

  void prefetch_entry_rows(std::uint32_t entry) const {
    if (level_ == Level::kTop)
      scene_.prefetch_rows(image_.registers().instance_row_base + memif::kInstanceRows * entry,
                           memif::kInstanceRows);
    else
      scene_.prefetch_rows(header_.triangle_row_base + memif::kTriangleRows * entry,
                           memif::kTriangleRows);
  }

  void do_list() {
    ++u_.list_steps;
    ListCursor& c = level_ == Level::kTop ? top_list_ : bottom_list_;
    const std::uint32_t entry = scene_.list_entry(c.next++);
    // The matrix rows of this entry and of the next (its list entry was prefetched at the leaf).
    prefetch_entry_rows(entry);
    if (c.next < c.end) prefetch_entry_rows(scene_.list_entry(c.next));
    for (int i = 0; i < p_; ++i)
      lane(i).counters.list_entries += (c.mask >> i) & 1u;
    Mailbox& mb = level_ == Level::kTop ? mailbox_ : tri_mailbox_;
    const std::uint64_t todo = mb.filter(entry, c.mask);
    for (int i = 0; i < p_; ++i)
      lane(i).counters.mailbox_skips += ((c.mask & ~todo) >> i) & 1u;
    if (todo == 0) return list_continue();
    entry_mask_ = todo;
    if (level_ == Level::kTop) {
      instance_ = entry;
      phase_ = Phase::kTransformObject;
    } else {
      triangle_ = entry;
      phase_ = Phase::kTransformTriangle;
    }
  }

  // ---- transformation unit (path d) -----------------------------------------------------------
  // Transforms `in` of every lane with m (n+1 or 2n steps whatever the mask, D30).
  void transform_lanes(const Mat34<F>& m, Ray<F> Lane::*in, Ray<F> Lane::*out) {
    count_transform();
    Vec3<F> shared{};
    const Mat64 mv = matrix_values(m);
    if (shared_origin_) shared = transform(m, mv, (lanes_[0].*in).o, true);
    for (int i = 0; i < p_; ++i) {
      Lane& l = lane(i);
      if (!has(entry_mask_, i) || shared_origin_) (l.*out).o = shared;
      l.counters.transformations += (entry_mask_ >> i) & 1u;
    }
    if (!shared_origin_)
      transform_masked(
          m, mv, entry_mask_, true, [&](int i) -> const Vec3<F>& { return (lane(i).*in).o; },
          [&](int i) -> Vec3<F>& { return (lane(i).*out).o; });
    transform_masked(
        m, mv, entry_mask_, false, [&](int i) -> const Vec3<F>& { return (lane(i).*in).d; },
        [&](int i) -> Vec3<F>& { return (lane(i).*out).d; });
    if (u_.tap != nullptr) [[unlikely]]
      tap_transform(m, in, out);
  }
  // Ray generation's steps (R' through the RGS's T), as tap_transform's.
  void tap_generate(const Vec3<F>& shared) {
    const GenLane& g0 = gen_.lanes[0];
    if (shared_origin_) u_.tap->transformation(g0.t, g0.ro, true, shared);
    for (int i = 0; i < p_; ++i) {
      const Lane& l = lane(i);
      if (!l.valid) continue;
      const GenLane& g = gen_.lanes[static_cast<std::size_t>(i)];
      if (!shared_origin_) u_.tap->transformation(g.t, g.ro, true, l.world.o);
      u_.tap->transformation(g.t, g.rd, false, l.world.d);
    }
  }
  // The steps as the unit runs them: a shared origin once (lane 0's, which every lane holds),
  // else each entering lane's origin; each entering lane's direction.
  void tap_transform(const Mat34<F>& m, Ray<F> Lane::*in, Ray<F> Lane::*out) {
    if (shared_origin_) u_.tap->transformation(m, (lanes_[0].*in).o, true, (lanes_[0].*out).o);
    for (int i = 0; i < p_; ++i) {
      if (!has(entry_mask_, i)) continue;
      const Lane& l = lane(i);
      if (!shared_origin_) u_.tap->transformation(m, (l.*in).o, true, (l.*out).o);
      u_.tap->transformation(m, (l.*in).d, false, (l.*out).d);
    }
  }

  void do_transform_object() {
    instance_row_ = image_.registers().instance_row_base + memif::kInstanceRows * instance_;
    transform_lanes(matrix(instance_row_), &Lane::world, &Lane::current);
    set_axis_values(v_.o, v_.inv, &Lane::current);
    header_ = image_.instance_header(instance_);
    // Enter the bottom level: save the top level's groups and stack base (the top-level stack
    // entries stay below; the bottom level pushes above them, D26).
    top_groups_ = groups_;
    top_n_groups_ = n_groups_;
    top_group_ = group_;
    top_stack_base_ = stack_base_;
    tri_mailbox_.clear();
    start_level(Level::kBottom);
  }

  void do_transform_triangle() {
    transform_lanes(matrix(header_.triangle_row_base + memif::kTriangleRows * triangle_),
                    &Lane::current, &Lane::tri);
    phase_ = Phase::kIntersect;
  }

  // ---- intersection unit (paths e, f) --------------------------------------------------------
  void do_intersect() {
    const auto& fp = u_.raw;
    ++u_.intersection_packets;
    const auto lanes = static_cast<std::uint64_t>(p_);
    PipelineUnits<F>::count(u_.intersection_ops, 3 * lanes, 2 * lanes, lanes, 0);
    for (int i = 0; i < p_; ++i) {
      Lane& l = lane(i);
      if (!has(entry_mask_, i)) continue;
      const Candidate<F> c = intersect_unit_triangle(fp, l.tri);
      if (u_.tap != nullptr) [[unlikely]]
        u_.tap->intersection(l.tri, c);
      ++l.counters.intersections;
      if (!accepts(c, instance_, triangle_, l.hit)) continue;
      l.hit.t = c.t;
      v_.t_best[static_cast<std::size_t>(i)] = value(c.t);
      l.hit.u = c.u;
      l.hit.v = c.v;
      l.hit.c = c.c;
      l.hit.instance = instance_;
      l.hit.triangle = triangle_;
      if (kind_ == RayKind::kShadow) l.done = true;
    }
    list_continue();
  }

  // ---- RGS (path g): shading and new packets (docs/shading.md) --------------------------------
  // The RGS's arithmetic through the value paths of datapath.h where they decide, else the ops on
  // encodings; the ops are counted here per use (the same counts as UnitFp's per op).
  void count_shading_transform(std::uint64_t steps) {
    PipelineUnits<F>::count(u_.transformation_ops, 9 * steps, 9 * steps, 0, 0);
  }
  // A direction step (ops counted by the caller) as three dot products: each of its rows is
  // dot_step's expression with the row as the first vector. With a matrix per lane (T_shadow, T_R)
  // the rows' exponent ranges are cheaper than matrix_values for one step.
  Vec3<F> direction_step(const Mat34<F>& m, const Vec3<F>& v) const {
    ExponentRange rv;
    rv.include(v[0]);
    rv.include(v[1]);
    rv.include(v[2]);
    Vec3<F> out;
    for (int r = 0; r < 3; ++r) {
      const Vec3<F> row{m[r][0], m[r][1], m[r][2]};
      if (!dot_step64<F>(row, v, rv, nearest_, out[r])) out[r] = dot_step(u_.raw, row, v);
    }
    return out;
  }
  // A dot product on the transformation unit (a zero-translation row: 3 mul, 3 add).
  F shade_dot(const Vec3<F>& a, const Vec3<F>& b) {
    PipelineUnits<F>::count(u_.transformation_ops, 3, 3, 0, 0);
    F r;
    if (dot_step64<F>(a, b, nearest_, r)) return r;
    return dot_step(u_.raw, a, b);
  }
  // -x / sqrt(a * b) on the RGS helper (1 mul, 1 sqrt, 1 div).
  F cosine(F x, F a, F b) {
    PipelineUnits<F>::count(u_.rgs_ops, 0, 1, 1, 0);
    ++u_.rgs_ops.sqrt;
    const auto& fp = u_.raw;
    return fp.div(x.neg(), fp.sqrt(fp.mul(a, b)));
  }
  // k + k for k = n / d on the RGS helper (1 div, 1 add).
  F twice_quotient(F n, F d) {
    PipelineUnits<F>::count(u_.rgs_ops, 1, 0, 1, 0);
    const F k = u_.raw.div(n, d);
    return u_.raw.add(k, k);
  }

  void record_primary() {
    for (int i = 0; i < p_; ++i) {
      const Lane& l = lane(i);
      if (!l.valid) continue;
      auto& px = sink_.pixels[l.pixel];
      px.t = l.hit.hit() ? l.hit.t.bits : F::infinity().bits;
      px.u = l.hit.u.bits;
      px.v = l.hit.v.bits;
      px.cos = l.hit.c.bits;
      px.instance = l.hit.instance;
      px.triangle = l.hit.triangle;
      for (int k = 0; k < 3; ++k) {
        px.o[static_cast<std::size_t>(k)] = l.world.o[k].bits;
        px.d[static_cast<std::size_t>(k)] = l.world.d[k].bits;
      }
      px.counters = l.counters;
    }
  }

  void add_colour(std::uint32_t pixel, std::uint32_t weight, const Rgb8& c) {
    auto& s = sink_.colour_sum[pixel];
    for (int k = 0; k < 3; ++k)
      s[static_cast<std::size_t>(k)] += weight * c[k];
  }

  void account_counters() {
    for (int i = 0; i < p_; ++i) {
      Lane& l = lane(i);
      l.counters.traversal_steps += traversal_steps_[static_cast<std::size_t>(i)];
      traversal_steps_[static_cast<std::size_t>(i)] = 0;
      if (l.valid) sink_.by_kind[static_cast<int>(kind_)] += l.counters;
    }
  }

  void do_shade_surface() {
    account_counters();
    if (kind_ == RayKind::kPrimary) record_primary();
    if (!params_.shade) return next_packet();
    const auto& regs = image_.registers();
    const Rgb8 ambient = unpack_rgb(regs.ambient_rgb);
    const Rgb8 background = unpack_rgb(regs.background_rgb);
    static const Surface kClear{};
    for (int i = 0; i < p_; ++i) {
      const Lane& l = lane(i);
      Surface& s = surf_[static_cast<std::size_t>(i)];
      s = kClear;  // as Surface{}, without its string store (as in begin_packet)
      if (!l.valid) continue;
      s.pixel = l.pixel;
      s.weight = l.weight;
      s.depth = depth_;
      if (!l.hit.hit()) {
        add_colour(l.pixel, l.weight, background);
        continue;
      }
      s.hit = true;
      s.ray = l.world;
      s.rec = l.hit;
      const memif::InstanceHeader h = image_.instance_header(s.rec.instance);
      // World normal (D19): the triangle's unit normal (row 2 of T_delta) through M^T.
      const auto nrow = row(h.triangle_row_base + memif::kTriangleRows * s.rec.triangle + 2);
      if (s.rec.instance != normal_instance_) {  // hits of a packet mostly share the instance
        normal_instance_ = s.rec.instance;
        const Mat34<F> m = matrix(regs.instance_row_base + memif::kInstanceRows * s.rec.instance);
        for (int r = 0; r < 3; ++r)
          normal_m_[r] = {m[0][r], m[1][r], m[2][r], F::zero()};
        normal_mv_ = matrix_values(normal_m_);
      }
      count_shading_transform(1);
      s.n = transform(normal_m_, normal_mv_, Vec3<F>{nrow[0], nrow[1], nrow[2]}, false);
      if (is_pos_nonzero(s.rec.c))
        for (auto& x : s.n)
          x = x.neg();
      s.nn = shade_dot(s.n, s.n);
      u_.shading_transformation_steps += 1;  // normal step; the dots count below
      const memif::ShadingRecord rec = read_shading_record(image_, h.shading_base + s.rec.triangle);
      s.mat = read_material(image_, rec.material);
      s.base = base_colour(image_, rec, s.mat, fix16(s.rec.u), fix16(s.rec.v));
      const std::uint32_t shininess = s.mat.specular_rgb_shininess >> 24;
      s.spec_rgb = unpack_rgb(s.mat.specular_rgb_shininess);
      s.spec = shininess >= 1 && (s.mat.specular_rgb_shininess & 0xFFFFFFu) != 0;
      const bool reflect = params_.secondary && depth_ < max_depth_ && s.mat.reflectivity > 0;
      if (s.spec || reflect) s.kk = twice_quotient(shade_dot(s.ray.d, s.n), s.nn);
      if (s.spec) {
        const Mat34<F> tr = reflect_matrix(s.ray, s.n);
        count_shading_transform(1);
        s.r = direction_step(tr, Vec3<F>{F::one(), s.kk.neg(), F::zero()});
        s.rr = shade_dot(s.r, s.r);
        u_.shading_transformation_steps += 1;
      }
      for (int k = 0; k < 3; ++k)
        s.acc[static_cast<std::size_t>(k)] = mul8(s.base[k], ambient[k]);
    }
    light_ = 0;
    next_light();
  }

  // T_R = [D, N, D; O] (paper 2.2.2 with the erratum: translation O).
  static Mat34<F> reflect_matrix(const Ray<F>& ray, const Vec3<F>& n) {
    Mat34<F> t{};
    for (int r = 0; r < 3; ++r)
      t[r] = {ray.d[r], n[r], ray.d[r], ray.o[r]};
    return t;
  }

  std::uint64_t surface_hit_mask() const {
    std::uint64_t m = 0;
    for (int i = 0; i < p_; ++i)
      if (surf_[static_cast<std::size_t>(i)].hit) m |= std::uint64_t{1} << i;
    return m;
  }

  // Shadow rays of light `light_` through T_shadow = [L, O, D; 0], R' = ((1,0,0), (-1,1,t)).
  void next_light() {
    const auto& regs = image_.registers();
    if (light_ >= regs.light_count || surface_hit_mask() == 0) return finish_surface();
    const std::uint32_t a = regs.light_base + memif::kLightWords * light_;
    Vec3<F> pos;
    for (std::uint32_t k = 0; k < 3; ++k)
      pos[k] = F::from_bits(image_.word(memif::kShadingBank, a + k));
    light_rgb_ = unpack_rgb(image_.word(memif::kShadingBank, a + 3));
    Packet& pk = gen_;  // built in place, as in start_primary (no allocation per packet)
    pk.kind = RayKind::kShadow;
    pk.depth = depth_;
    pk.shared_origin = params_.shared_origin;
    pk.lanes.resize(lanes_.size());
    for (int i = 0; i < p_; ++i) {
      const Surface& s = surf_[static_cast<std::size_t>(i)];
      GenLane& g = pk.lanes[static_cast<std::size_t>(i)];
      for (int r = 0; r < 3; ++r)
        g.t[r] = {pos[r], s.ray.o[r], s.ray.d[r], F::zero()};
      g.ro = {F::one(), F::zero(), F::zero()};
      g.rd = {F::one().neg(), F::one(), s.rec.t};
      g.valid = s.hit;
      g.pixel = s.pixel;
      g.weight = 0;
    }
    begin_packet(pk);
    if (!params_.shadows) {
      // Without shadow rays only the directions are needed: n direction steps, no origin step.
      u_.shading_transformation_steps += static_cast<std::uint64_t>(p_);
      count_shading_transform(static_cast<std::uint64_t>(p_));
      for (int i = 0; i < p_; ++i) {
        const GenLane& g = gen_.lanes[static_cast<std::size_t>(i)];
        lane(i).world.d = direction_step(g.t, g.rd);
      }
      return do_shade_light();
    }
  }

  void do_shade_light() {
    std::uint64_t trace = 0;
    for (int i = 0; i < p_; ++i) {
      Surface& s = surf_[static_cast<std::size_t>(i)];
      s.lit = false;
      s.highlight = false;
      if (!s.hit) continue;
      const Vec3<F>& sd = lane(i).world.d;  // hit point - L
      const F ns = shade_dot(s.n, sd);
      const F ss = shade_dot(sd, sd);
      s.lit = is_neg_nonzero(ns);
      if (!s.lit) continue;
      s.cos = cosine(ns, s.nn, ss);
      if (s.spec) {
        const F rl = shade_dot(s.r, sd);
        s.highlight = is_neg_nonzero(rl);
        if (s.highlight) s.cos_s = cosine(rl, s.rr, ss);
      }
      trace |= std::uint64_t{1} << i;
    }
    u_.shading_transformation_steps += 1;
    if (!params_.shadows || trace == 0) {
      for (int i = 0; i < p_; ++i)
        lane(i).valid = false;
      return accumulate_light();
    }
    for (int i = 0; i < p_; ++i)
      lane(i).valid = has(trace, i);
    issue_rays();
  }

  void do_shade_shadow() {
    account_counters();
    accumulate_light();
  }

  // Diffuse and specular of light `light_` for the lit, unoccluded hits.
  void accumulate_light() {
    for (int i = 0; i < p_; ++i) {
      Surface& s = surf_[static_cast<std::size_t>(i)];
      if (!s.hit || !s.lit) continue;
      if (params_.shadows && lane(i).hit.hit()) continue;  // occluded
      const std::uint32_t wd = fix8(s.cos);
      for (int k = 0; k < 3; ++k)
        s.acc[static_cast<std::size_t>(k)] += (mul8(s.base[k], light_rgb_[k]) * wd) >> 8;
      if (s.spec && s.highlight) {
        const std::uint32_t p = specular_power(fix8(s.cos_s), s.mat.specular_rgb_shininess >> 24);
        for (int k = 0; k < 3; ++k)
          s.acc[static_cast<std::size_t>(k)] += (mul8(s.spec_rgb[k], light_rgb_[k]) * p) >> 8;
      }
    }
    ++light_;
    next_light();
  }

  // Local colour into the pixel, then reflection and transparency children (D37).
  void finish_surface() {
    // The children are built in the next two pending slots, whose lane vectors are kept from
    // earlier packets (no allocation per packet); the reflection packet is traced first.
    if (pending_.size() < pending_size_ + 2) pending_.resize(pending_size_ + 2);
    Packet& transp = pending_[pending_size_];
    Packet& refl = pending_[pending_size_ + 1];
    refl.kind = RayKind::kReflection;
    transp.kind = RayKind::kTransparency;
    refl.depth = transp.depth = depth_ + 1;
    refl.shared_origin = transp.shared_origin = false;
    refl.lanes.assign(lanes_.size(), GenLane{});
    transp.lanes.assign(lanes_.size(), GenLane{});
    bool any_refl = false, any_transp = false;
    for (int i = 0; i < p_; ++i) {
      const Surface& s = surf_[static_cast<std::size_t>(i)];
      if (!s.hit) continue;
      Rgb8 local{};
      for (int k = 0; k < 3; ++k)
        local[k] = std::min<std::uint32_t>(255u, s.acc[k]);
      const bool spawn = params_.secondary && depth_ < max_depth_;
      const std::uint32_t kr = spawn ? s.mat.reflectivity : 0u;
      const std::uint32_t kt = spawn ? s.mat.transparency : 0u;
      const std::uint32_t wl =
          params_.secondary ? mul8(s.weight, 255u - std::min(255u, kr + kt)) : s.weight;
      add_colour(s.pixel, wl, local);
      const std::uint32_t wr = mul8(s.weight, kr), wt = mul8(s.weight, kt);
      const Mat34<F> tr = reflect_matrix(s.ray, s.n);
      if (wr > 0) {
        GenLane& g = refl.lanes[static_cast<std::size_t>(i)];
        g = {true,
             s.pixel,
             wr,
             tr,
             {epsilon_.neg(), F::zero(), s.rec.t},
             {F::one(), s.kk.neg(), F::zero()}};
        any_refl = true;
      }
      if (wt > 0) {
        GenLane& g = transp.lanes[static_cast<std::size_t>(i)];
        g = {true,
             s.pixel,
             wt,
             tr,
             {epsilon_, F::zero(), s.rec.t},
             {F::one(), F::zero(), F::zero()}};
        any_transp = true;
      }
    }
    if (any_transp) ++pending_size_;
    if (any_refl) {
      if (!any_transp) std::swap(transp, refl);
      ++pending_size_;
    }
    next_packet();
  }

  void next_packet() {
    if (pending_size_ == 0) {
      phase_ = Phase::kDone;
      return;
    }
    --pending_size_;
    begin_packet(pending_[pending_size_]);  // copied into gen_: the slot may be rebuilt
  }

  const memif::MemoryImage& image_;
  const FunctionalParams& params_;
  PipelineUnits<F>& u_;
  FrameSink& sink_;
  int p_;
  std::uint32_t max_depth_ = 3;
  Mat34<F> cam_{};
  MatrixValues<F> cam_values_{};  // matrix_values(cam_): primary packets transform through it
  std::array<F, 3> scene_lo_{}, scene_hi_{};
  std::array<F, 3> box_lo_{}, box_hi_{};  // the current level's box (clip steps)
  F epsilon_{}, shadow_t_max_{};
  bool nearest_ = true;  // the binary64 paths (datapath.h) decide only for nearest-even

  Phase phase_ = Phase::kDone;
  RayKind kind_ = RayKind::kPrimary;
  std::uint32_t depth_ = 0;
  bool shared_origin_ = false;
  Packet gen_;
  // Child packets still to trace (a LIFO of pending_size_ entries); slots beyond it keep their
  // lane vectors for reuse.
  std::vector<Packet> pending_;
  std::size_t pending_size_ = 0;
  // M^T (zero translation) of the instance whose normals the RGS transformed last, and its values;
  // kNone: none yet in this primary packet's tree (the image may change between frames).
  std::uint32_t normal_instance_ = memif::kNone;
  Mat34<F> normal_m_{};
  Mat64 normal_mv_{};
  std::vector<Lane> lanes_;
  std::vector<Surface> surf_;
  std::uint32_t light_ = 0;
  Rgb8 light_rgb_{};

  Level level_ = Level::kTop;
  int clip_face_ = 0;
  int clip_stride_ = 1;  // 2: exit faces only (every origin inside the box)
  std::uint64_t clip_mask_ = 0;
  std::array<std::uint64_t, 8> groups_{}, top_groups_{};
  std::size_t n_groups_ = 0, top_n_groups_ = 0, group_ = 0, top_group_ = 0;
  std::size_t stack_base_ = 0, top_stack_base_ = 0;
  std::uint32_t node_ = 0;
  std::uint64_t mask_ = 0;
  std::vector<std::uint32_t> stack_node_;
  std::vector<std::uint64_t> stack_mask_;
  std::vector<double> stack_t_;  // per entry: far tn per slot, then tf per slot (values)
  int slots_ = 0;                // P rounded up to even: the slots of LaneValues in use
  LaneValues v_;
  // Per lane: traversal steps of the current packet, added to its counters when the packet's
  // counters are accounted (account_counters, before they are recorded).
  std::array<std::uint64_t, kLanes> traversal_steps_{};
  SceneView scene_;
  std::size_t stack_size_ = 0;  // entries in use (the vectors are allocated once)
  ListCursor top_list_, bottom_list_;
  Mailbox mailbox_, tri_mailbox_;
  std::uint64_t entry_mask_ = 0;
  std::uint32_t instance_ = 0, instance_row_ = 0, triangle_ = 0;
  memif::InstanceHeader header_;
};

}  // namespace saarcor::units
