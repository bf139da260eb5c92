// The intersection unit's semantics (paper section 2.1.2; Figure 2 paths e and f;
// docs/cycle-model.md; decision D30): the unit-triangle test of every entering ray of the packet,
// one ray per cycle (P cycles), and the closest-hit update; a shadow ray is done at its first hit
// (any-hit). Then back to the list (path f). Timing: units/intersection.cpp (depth: div, mul, add,
// add, the hit tests); exact-cycle test: units/unit_timing_test.cpp (UnitTimingIntersection.*).
#pragma once

#include <cstdint>

#include "units/packet.h"

namespace saarcor::units {

template <class F, int kLanes, class D>
class IntersectionStep {
 public:
  using State = PacketState<F, kLanes, D>;

  void step(State& t) {
    ++t.u.intersection_packets;
    const auto lanes = static_cast<std::uint64_t>(t.p);
    PipelineUnits<F>::count(t.u.intersection_ops, 3 * lanes, 2 * lanes, lanes, 0);
    const std::uint64_t mask = t.list.entry_mask();
    const std::uint32_t instance = t.list.instance(), triangle = t.list.triangle();
    for (int i = 0; i < t.p; ++i) {
      Lane<F>& l = t.lane(i);
      if (!lane_in(mask, i)) continue;
      const Candidate<F> c = intersect_unit_triangle(t.u.raw, l.tri);
      if (t.u.tap != nullptr) [[unlikely]]
        t.u.tap->intersection(i, l.tri, c);
      ++l.counters.intersections;
      if (!accepts(c, instance, triangle, l.hit)) continue;
      l.hit.t = c.t;
      t.v.t_best[static_cast<std::size_t>(i)] = t.value(c.t);
      l.hit.u = c.u;
      l.hit.v = c.v;
      l.hit.c = c.c;
      l.hit.instance = instance;
      l.hit.triangle = triangle;
      if (t.kind == RayKind::kShadow) l.done = true;
    }
    t.list.resume(t);
  }
};

}  // namespace saarcor::units
