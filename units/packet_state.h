// One DynRTP thread's state (docs/cycle-model.md): the packet every unit works on (lanes, binary64
// lane values, kind, depth, the phase that names the unit it waits for) and one slice per unit,
// each the unit's own state with its semantics (units/*_step.h). Besides, what the units share:
// matrix rows read through the scene view, and the datapath policy D's transformation kernels
// (units/fast_datapath.h: on binary64 values where they decide; units/reference_datapath.h: on
// encodings only). This header names no policy: each model's translation unit includes the one it
// instantiates.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "fixedfloat/pack.h"
#include "units/intersection_step.h"
#include "units/list_step.h"
#include "units/packet.h"
#include "units/rgs_step.h"
#include "units/scene_view.h"
#include "units/transformation_step.h"
#include "units/traversal_step.h"

namespace saarcor::units {

template <class F, int kLanes, class D>
struct PacketState {
  static_assert(kLanes >= 2 && kLanes <= kMaxPacket && (kLanes & (kLanes - 1)) == 0);
  using Float = F;
  using Datapath = D;
  static constexpr int kLaneCapacity = kLanes;
  using Mat64 = typename D::template Matrix<F>;  // what a transformation step reads of a matrix

  PacketState(const memif::MemoryImage& image_, const FunctionalParams& params_,
              PipelineUnits<F>& units, FrameSink& sink_)
      : image(checked(image_, params_)),
        params(params_),
        u(units),
        sink(sink_),
        p(params_.packet),
        slots(p + (p & 1)),
        // The fast datapath's binary64 paths decide only for nearest-even.
        nearest(params_.mode.rounding == ff::Rounding::kNearestEven),
        lanes(static_cast<std::size_t>(p)),
        transformation(image_, *this),
        traversal(image_, params_, slots),
        list(params_),
        rgs(image_, params_, p) {}
  PacketState(const PacketState&) = delete;
  PacketState& operator=(const PacketState&) = delete;

  // ---- the context: the memory image, parameters, float units, frame -------------------------
  const memif::MemoryImage& image;
  const FunctionalParams& params;
  PipelineUnits<F>& u;
  FrameSink& sink;
  const int p;      // packet width P
  const int slots;  // P rounded up to even: the slots of LaneValues in use
  const bool nearest;
  SceneView scene;

  // ---- the packet -----------------------------------------------------------------------------
  Phase phase = Phase::kDone;
  RayKind kind = RayKind::kPrimary;
  std::uint32_t depth = 0;
  bool shared_origin = false;
  std::vector<Lane<F>> lanes;
  LaneValues<kLanes> v;
  // Per lane: traversal steps of the current packet, added to its counters when the packet's
  // counters are accounted (RgsStep::account_counters, before they are recorded).
  std::array<std::uint64_t, kLanes> traversal_steps{};

  // ---- the units' slices ----------------------------------------------------------------------
  TransformationStep<F, kLanes, D> transformation;
  TraversalStep<F, kLanes, D> traversal;
  ListStep<F, kLanes, D> list;
  IntersectionStep<F, kLanes, D> intersection;
  RgsStep<F, kLanes, D> rgs;

  // ---- lanes ----------------------------------------------------------------------------------
  Lane<F>& lane(int i) { return lanes[static_cast<std::size_t>(i)]; }
  const Lane<F>& lane(int i) const { return lanes[static_cast<std::size_t>(i)]; }
  std::uint64_t valid_mask() const {
    std::uint64_t m = 0;
    for (int i = 0; i < p; ++i)
      if (lanes[static_cast<std::size_t>(i)].valid) m |= std::uint64_t{1} << i;
    return m;
  }
  std::uint64_t done_mask() const {
    std::uint64_t m = 0;
    for (int i = 0; i < p; ++i)
      if (lanes[static_cast<std::size_t>(i)].done) m |= std::uint64_t{1} << i;
    return m;
  }
  // Copies the slots in use, a pair at a time (P = 4: two vector moves, no library call).
  void copy_slots(double* dst, const double* src) const {
    for (int i = 0; i < slots; i += 2)
      store2(dst + i, load2(src + i));
  }

  // ---- values and encodings -------------------------------------------------------------------
  double value(F x) const { return value_of(x, u.raw.mode().subnormals); }
  F encoding(double x) const { return u.raw.from_double(x); }  // exact: x is a value of F

  // What the datapath keeps of every lane's ray `ray` for the traversal unit (D::axis_values).
  void set_axis_values(std::array<Slots<kLanes>, 3>& o, std::array<Slots<kLanes>, 3>& inv,
                       Ray<F> Lane<F>::*ray) {
    D::axis_values(*this, o, inv, ray);
  }

  // ---- matrices -------------------------------------------------------------------------------
  // As read_row / read_matrix (datapath.h), through the cached bank addresses, with the row's
  // packing known at compile time (fixedfloat/pack.h: four 24-bit fields in three words for
  // formats up to 24 bits, else one word each).
  std::array<F, 4> row(std::uint32_t index) const {
    const std::uint32_t* w = scene.row_words(index);
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
  // Transformation steps (transform_step) through the datapath's kernels: a matrix as the
  // datapath reads it, one vector, and out(i) = m * in(i) for the lanes in `mask`.
  Mat64 matrix_values(const Mat34<F>& m) const { return D::matrix(*this, m); }
  Vec3<F> transform(const Mat34<F>& m, const Mat64& mv, const Vec3<F>& x, bool translate) const {
    return D::transform(*this, m, mv, x, translate);
  }
  template <class In, class Out>
  void transform_masked(const Mat34<F>& m, const Mat64& mv, std::uint64_t mask, bool translate,
                        In in, Out out) {
    D::transform_masked(*this, m, mv, mask, translate, in, out);
  }

 private:
  // The parameters a thread cannot run with are refused before any slice is built.
  static const memif::MemoryImage& checked(const memif::MemoryImage& image,
                                           const FunctionalParams& params) {
    const int p = params.packet;
    if (!(F::kFormat == image.format()))
      throw std::runtime_error("functional model: the image's float format " +
                               ff::format_name(image.format()) + " does not match the model's " +
                               ff::format_name(F::kFormat));
    if (p < 1 || p > kMaxPacket || (p & (p - 1)) != 0)
      throw std::runtime_error("functional model: packet width " + std::to_string(p) +
                               " is not a power of two in 1..64");
    if (p > kLanes) throw std::logic_error("thread program: packet wider than its lane capacity");
    if (params.stack_depth < 1)
      throw std::runtime_error("functional model: stack depth must be at least 1");
    if (params.clip_faces_per_step < 1 || params.clip_faces_per_step > 6)
      throw std::runtime_error("functional model: clip faces per step " +
                               std::to_string(params.clip_faces_per_step) + " outside 1..6");
    return image;
  }
};

}  // namespace saarcor::units
