// One DynRTP thread's state (docs/cycle-model.md): the packet every unit works on (lanes, binary64
// lane values, kind, depth, the phase that names the unit it waits for) and one slice per unit,
// each the unit's own state with its semantics (units/*_step.h). Besides, the fast-path helpers
// the units share: matrix rows read through the scene view, transformation steps on binary64 values
// two lanes at a time where units/fast_paths.h decides, on encodings (units/datapath.h) otherwise.
#pragma once

#include <cstdint>
#include <limits>
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

template <class F, int kLanes>
struct PacketState {
  static_assert(kLanes >= 2 && kLanes <= kMaxPacket && (kLanes & (kLanes - 1)) == 0);
  using Mat64 = MatrixValues<F>;

  PacketState(const memif::MemoryImage& image_, const FunctionalParams& params_,
              PipelineUnits<F>& units, FrameSink& sink_)
      : image(checked(image_, params_)),
        params(params_),
        u(units),
        sink(sink_),
        p(params_.packet),
        slots(p + (p & 1)),
        // The binary64 paths decide only for nearest-even; reference_datapath turns them all off.
        nearest(!params_.reference_datapath && params_.mode.rounding == ff::Rounding::kNearestEven),
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
  TransformationStep<F, kLanes> transformation;
  TraversalStep<F, kLanes> traversal;
  ListStep<F, kLanes> list;
  IntersectionStep<F, kLanes> intersection;
  RgsStep<F, kLanes> rgs;

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

  // O and 1/D (traversal_reciprocal) of every lane's ray `ray`, the reciprocals two lanes per
  // division (the same binary64 quotients). Lanes outside the level's mask get values nothing
  // reads.
  void set_axis_values(std::array<Slots<kLanes>, 3>& o, std::array<Slots<kLanes>, 3>& inv,
                       Ray<F> Lane<F>::*ray) {
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    for (int i = 0; i < p; i += 2) {
      const Ray<F>& a = lane(i).*ray;
      const Ray<F>& b = lane(i + 1 < p ? i + 1 : i).*ray;
      const auto s = static_cast<std::size_t>(i);
      for (std::size_t k = 0; k < 3; ++k) {
        const int c = static_cast<int>(k);
        o[k][s] = value(a.o[c]);
        o[k][s + 1] = value(b.o[c]);
        // Decoded as if normal; lanes whose D is not normal (or truncation) get NaN.
        const V2d r = 1.0 / decode_pair<F>(a.d[c].bits, b.d[c].bits);
        inv[k][s] =
            nearest && ff::fast::is_normal<F::kExpBits, F::kManBits>(a.d[c].bits) ? r[0] : kNaN;
        inv[k][s + 1] =
            nearest && ff::fast::is_normal<F::kExpBits, F::kManBits>(b.d[c].bits) ? r[1] : kNaN;
      }
    }
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
  // A transformation step (transform_step) through the binary64 path where it decides.
  Mat64 matrix_values(const Mat34<F>& m) const {
    bool normal = true;  // every entry zero or normal: decoded two at a time (the same values)
    for (const auto& r : m)
      for (const F x : r)
        normal &= normal_or_zero(x);
    if (!normal) {
      Mat64 mv = units::matrix_values(m, u.raw.mode().subnormals);
      mv.nearest = nearest;
      return mv;
    }
    Mat64 mv;
    for (std::size_t r = 0; r < 3; ++r) {
      const auto& rw = m[static_cast<int>(r)];
      for (int c = 0; c < 4; c += 2) {
        const V2d x = decode_pair<F>(rw[c].bits, rw[c + 1].bits);
        mv.m[r][static_cast<std::size_t>(c)] = x[0];
        mv.m[r][static_cast<std::size_t>(c + 1)] = x[1];
      }
      mv.linear.include(rw[0]);
      mv.linear.include(rw[1]);
      mv.linear.include(rw[2]);
      mv.translation.include(rw[3]);
    }
    mv.nearest = nearest;
    return mv;
  }
  // One vector: the two-lane path with both lanes the same (fewer moves than the scalar path).
  Vec3<F> transform(const Mat34<F>& m, const Mat64& mv, const Vec3<F>& x, bool translate) const {
    if (!transform_decides<F>(mv, x, translate)) return transform_step(u.raw, m, x, translate);
    const V2d d[3] = {decode_pair<F>(x[0].bits, x[0].bits), decode_pair<F>(x[1].bits, x[1].bits),
                      decode_pair<F>(x[2].bits, x[2].bits)};
    V2u r[3];
    transform_pair64<F>(mv, d, translate, r);
    return lane_of<F>(r, 0);
  }
  // out(i) = m * in(i) (a transformation step) for the lanes in `mask`: two lanes at a time on
  // values where transform_decides holds for both or one of them, the others on encodings.
  template <class In, class Out>
  void transform_masked(const Mat34<F>& m, const Mat64& mv, std::uint64_t mask, bool translate,
                        In in, Out out) {
    for (int i = 0; i < p; i += 2) {
      const int j = i + 1 < p ? i + 1 : i;
      const bool a = lane_in(mask, i), b = j != i && lane_in(mask, j);
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
      if (a && !da) out(i) = transform_step(u.raw, m, in(i), translate);
      if (b && !db) out(j) = transform_step(u.raw, m, in(j), translate);
    }
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
