// The transformation unit's semantics (paper sections 2.2-2.3; Figure 2 paths a and d;
// docs/cycle-model.md; decisions D30, D31): ray generation (the RGS's R' through its matrix T into
// world rays), world to object space with an instance's matrix, object to unit-triangle space with
// a triangle's T_delta. A ray transformation takes n+1 steps for a packet with one origin, 2n
// otherwise, whatever the mask (D30: a masked lane fires and its result is discarded). Timing:
// units/transformation.cpp (depth: fp mul + two adds); exact-cycle test:
// units/unit_timing_test.cpp (UnitTimingTransformation.*).
#pragma once

#include <cstdint>

#include "units/packet.h"

namespace saarcor::units {

template <class F, int kLanes, class D>
class TransformationStep {
 public:
  using State = PacketState<F, kLanes, D>;
  using Mat64 = typename State::Mat64;

  TransformationStep(const memif::MemoryImage& image, const State& t) {
    const auto& regs = image.registers();
    for (int i = 0; i < 3; ++i)
      cam_[i] = {F::from_bits(regs.cam_r[i]), F::from_bits(regs.cam_u[i]),
                 F::from_bits(regs.cam_d[i]), F::from_bits(regs.cam_p[i])};
    cam_values_ = t.matrix_values(cam_);
    shadow_t_max_ = F::from_double(1.0 - 1.0 / 512.0);
  }

  const Mat34<F>& camera() const { return cam_; }
  // The packet the RGS hands over next (path a), built in place by the RGS.
  GenPacket<F>& input() { return gen_; }
  const GenPacket<F>& input() const { return gen_; }

  // Steps of one ray transformation of the packet (D31: the n+1 rule for a shared origin).
  int steps(const State& t) const { return t.shared_origin ? t.p + 1 : 2 * t.p; }

  // The RGS hands the unit a packet to generate (path a): its lanes start afresh.
  void load(State& t, const GenPacket<F>& pk) {
    t.list.clear();  // a mailbox belongs to one packet's rays (D28)
    t.kind = pk.kind;
    t.depth = pk.depth;
    t.shared_origin = pk.shared_origin;
    gen_ = pk;
    for (int i = 0; i < t.p; ++i)
      t.traversal_steps[static_cast<std::size_t>(i)] = 0;
    for (int i = 0; i < t.p; ++i) {
      Lane<F>& l = t.lane(i);
      const GenLane<F>& g = pk.lanes[static_cast<std::size_t>(i)];
      static const Lane<F> kClear{};
      l = kClear;  // a copy of the defaults: Lane{} compiles to a string store that costs more
      l.valid = g.valid;
      l.pixel = g.pixel;
      l.weight = g.weight;
    }
    t.phase = Phase::kGenerate;
  }

  // Ray generation (path a): world rays from R' and T; shadow rays go back to the RGS, which
  // decides which to trace, the others to the traversal unit.
  void generate(State& t) {
    count(t);
    const GenLane<F>& g0 = gen_.lanes[0];
    Vec3<F> shared{};
    const Mat64 mv0 = g0.t == cam_ ? cam_values_ : t.matrix_values(g0.t);
    if (t.shared_origin) shared = t.transform(g0.t, mv0, g0.ro, true);
    generate_lanes(t, mv0, shared);
    if (t.u.tap != nullptr) [[unlikely]]
      tap_generate(t, shared);
    for (int i = 0; i < t.p; ++i) {
      Lane<F>& l = t.lane(i);
      l.current = l.world;
      l.hit = HitRecord<F>{};
      if (t.kind == RayKind::kShadow) l.hit.t = shadow_t_max_;
      t.v.t_best[static_cast<std::size_t>(i)] = t.value(l.hit.t);
      if (l.valid) ++l.counters.transformations;
    }
    t.set_axis_values(t.v.world_o, t.v.world_inv, &Lane<F>::world);
    if (t.kind == RayKind::kShadow) {
      t.phase = Phase::kShadeLight;  // the RGS decides which shadow rays to trace
      return;
    }
    t.traversal.issue(t);
  }

  // World to object space with the instance's matrix (path d), then the object's clip.
  void object(State& t) {
    transform_lanes(t, t.matrix(t.list.instance_row()), &Lane<F>::world, &Lane<F>::current);
    t.set_axis_values(t.v.o, t.v.inv, &Lane<F>::current);
    t.list.enter_object(t);
    t.traversal.enter_object(t);
  }

  // Object to unit-triangle space with the triangle's T_delta (path d), then the intersection.
  void triangle(State& t) {
    const auto& h = t.list.header();
    transform_lanes(t, t.matrix(h.triangle_row_base + memif::kTriangleRows * t.list.triangle()),
                    &Lane<F>::current, &Lane<F>::tri);
    t.phase = Phase::kIntersect;
  }

 private:
  // One ray transformation of the packet: 9 mul and 9 add per step (n+1 or 2n steps, D30/D31).
  void count(State& t) {
    const auto n = static_cast<std::uint64_t>(steps(t));
    t.u.transformation_steps += n;
    PipelineUnits<F>::count(t.u.transformation_ops, 9 * n, 9 * n, 0, 0);
  }

  // Lanes usually share T (primary rays: the camera's): those with lane 0's T two at a time, the
  // others one by one, T decoded once per distinct T.
  void generate_lanes(State& t, const Mat64& mv0, const Vec3<F>& shared) {
    const GenLane<F>& g0 = gen_.lanes[0];
    std::uint64_t same = 0, other = 0;
    for (int i = 0; i < t.p; ++i) {
      Lane<F>& l = t.lane(i);
      const GenLane<F>& g = gen_.lanes[static_cast<std::size_t>(i)];
      if (!l.valid || t.shared_origin) l.world.o = shared;
      if (l.valid) (g.t == g0.t ? same : other) |= std::uint64_t{1} << i;
    }
    const auto gen = [&](int i) -> const GenLane<F>& {
      return gen_.lanes[static_cast<std::size_t>(i)];
    };
    if (!t.shared_origin)
      t.transform_masked(
          g0.t, mv0, same, true, [&](int i) -> const Vec3<F>& { return gen(i).ro; },
          [&](int i) -> Vec3<F>& { return t.lane(i).world.o; });
    t.transform_masked(
        g0.t, mv0, same, false, [&](int i) -> const Vec3<F>& { return gen(i).rd; },
        [&](int i) -> Vec3<F>& { return t.lane(i).world.d; });
    if (other == 0) return;
    Mat34<F> mt = g0.t;
    Mat64 mv = mv0;
    for (int i = 0; i < t.p; ++i) {
      if (!lane_in(other, i)) continue;
      const GenLane<F>& g = gen(i);
      if (!(g.t == mt)) {
        mt = g.t;
        mv = t.matrix_values(g.t);
      }
      if (!t.shared_origin) t.lane(i).world.o = t.transform(g.t, mv, g.ro, true);
      t.lane(i).world.d = t.transform(g.t, mv, g.rd, false);
    }
  }

  // Transforms `in` of every entering lane with m.
  void transform_lanes(State& t, const Mat34<F>& m, Ray<F> Lane<F>::*in, Ray<F> Lane<F>::*out) {
    count(t);
    const std::uint64_t mask = t.list.entry_mask();
    Vec3<F> shared{};
    const Mat64 mv = t.matrix_values(m);
    if (t.shared_origin) shared = t.transform(m, mv, (t.lanes[0].*in).o, true);
    for (int i = 0; i < t.p; ++i) {
      Lane<F>& l = t.lane(i);
      if (!lane_in(mask, i) || t.shared_origin) (l.*out).o = shared;
      l.counters.transformations += (mask >> i) & 1u;
    }
    if (!t.shared_origin)
      t.transform_masked(
          m, mv, mask, true, [&](int i) -> const Vec3<F>& { return (t.lane(i).*in).o; },
          [&](int i) -> Vec3<F>& { return (t.lane(i).*out).o; });
    t.transform_masked(
        m, mv, mask, false, [&](int i) -> const Vec3<F>& { return (t.lane(i).*in).d; },
        [&](int i) -> Vec3<F>& { return (t.lane(i).*out).d; });
    if (t.u.tap != nullptr) [[unlikely]]
      tap_transform(t, m, in, out);
  }

  // Ray generation's steps (R' through the RGS's T), as tap_transform's.
  void tap_generate(State& t, const Vec3<F>& shared) {
    const GenLane<F>& g0 = gen_.lanes[0];
    if (t.shared_origin) t.u.tap->transformation(-1, g0.t, g0.ro, true, shared);
    for (int i = 0; i < t.p; ++i) {
      const Lane<F>& l = t.lane(i);
      if (!l.valid) continue;
      const GenLane<F>& g = gen_.lanes[static_cast<std::size_t>(i)];
      if (!t.shared_origin) t.u.tap->transformation(i, g.t, g.ro, true, l.world.o);
      t.u.tap->transformation(i, g.t, g.rd, false, l.world.d);
    }
  }
  // The steps as the unit runs them: a shared origin once (lane 0's, which every lane holds),
  // else each entering lane's origin; each entering lane's direction.
  void tap_transform(State& t, const Mat34<F>& m, Ray<F> Lane<F>::*in, Ray<F> Lane<F>::*out) {
    if (t.shared_origin)
      t.u.tap->transformation(-1, m, (t.lanes[0].*in).o, true, (t.lanes[0].*out).o);
    for (int i = 0; i < t.p; ++i) {
      if (!lane_in(t.list.entry_mask(), i)) continue;
      const Lane<F>& l = t.lane(i);
      if (!t.shared_origin) t.u.tap->transformation(i, m, (l.*in).o, true, (l.*out).o);
      t.u.tap->transformation(i, m, (l.*in).d, false, (l.*out).d);
    }
  }

  Mat34<F> cam_{};
  Mat64 cam_values_{};  // matrix_values(cam_): primary packets transform through it
  F shadow_t_max_{};
  GenPacket<F> gen_;
};

}  // namespace saarcor::units
