// The intersection unit's ports as hardware carries them (the boundary record, units/boundary.h;
// paper section 2.1.2 and 3.1, Figure 2 paths e and f; D15, D30, D49), read from the thread
// program's state:
//   input (path e from the transformation unit, a triangle's step): mask (the rays that enter the
//     triangle), list (the rays still in the bottom-level list), last (the list's cursor is past
//     its end: the triangle was the list's last entry), instance, triangle (the candidate's ids,
//     for the tie rule); wide: per lane the ray in unit-triangle space, O'[3] then D'[3];
//   side band (path a: the RGS hands the transformation unit a new packet): shadow; every lane's
//     closest hit starts afresh (t_best the ray's t_max: +inf, or 1 - 1/512 for a shadow ray;
//     ids none) and no lane is done;
//   output: dest (0 back to the list unit, path f: the bottom-level list goes on; 1 the traversal
//     unit pops, path f: the list is done, or every one of its rays is, D49), mask (the rays
//     still in the list after the any-hit rays that are done left it), done (per lane: any-hit
//     satisfied, D15); wide: per lane the closest hit t, u, v, c, instance, triangle.
// The unit keeps each ray's closest hit itself: nothing else writes it (the traversal unit gets
// t_best and done on its side band, the RGS reads the record when the packet is shaded).
#pragma once

#include <cstdint>
#include <functional>

#include "units/boundary.h"
#include "units/packet_state.h"

namespace saarcor::units {

enum class IntersectionOut : std::uint8_t { kList = 0, kPop = 1 };

inline constexpr const char* kIntersectionInputFields[] = {"mask", "list", "last", "instance",
                                                           "triangle"};
inline constexpr const char* kIntersectionStartFields[] = {"shadow"};
inline constexpr const char* kIntersectionOutputFields[] = {"dest", "mask", "done"};
// The wide words of an input (per lane O'[3], D'[3]) and of an output (per lane the hit record).
inline constexpr int kIntersectionRayWords = 6;
inline constexpr int kIntersectionHitWords = 6;

template <class F, int kLanes, class D>
class IntersectionPayload final : public BoundaryPayload {
 public:
  using State = PacketState<F, kLanes, D>;
  using StateOf = std::function<const State&(ThreadToken)>;

  IntersectionPayload(const ThreadTable& threads, StateOf state)
      : threads_(threads), state_(std::move(state)) {}

  void input(UnitId unit, UnitId from, ThreadToken t, BoundaryEvent& e) override {
    if (unit != UnitId::kIntersection) return RequestPayload(threads_).input(unit, from, t, e);
    const State& s = state_(t);
    e.fields = 5;
    e.names = kIntersectionInputFields;
    e.field = {s.list.entry_mask(), s.list.mask(Level::kBottom),
               s.list.next(Level::kBottom) >= s.list.end(Level::kBottom) ? 1u : 0u,
               s.list.instance(), s.list.triangle()};
    e.wide.clear();
    for (int i = 0; i < s.p; ++i) {
      const Ray<F>& r = s.lane(i).tri;
      for (const F& x : r.o)
        e.wide.push_back(x.bits);
      for (const F& x : r.d)
        e.wide.push_back(x.bits);
    }
  }

  // Path a: a new packet (ray generation) resets the rays' closest hits.
  bool side_band(UnitId to, UnitId, ThreadToken t, BoundaryEvent& side) override {
    if (to != UnitId::kTransformation || threads_.request(t).phase != Phase::kGenerate)
      return false;
    side.unit = UnitId::kIntersection;
    side.fields = 1;
    side.names = kIntersectionStartFields;
    side.field = {state_(t).kind == RayKind::kShadow ? 1u : 0u};
    side.wide.clear();
    return true;
  }

  void issued(UnitId, ThreadToken, const Request&) override {}

  void output(UnitId unit, ThreadToken t, BoundaryEvent& e) override {
    if (unit != UnitId::kIntersection) return RequestPayload(threads_).output(unit, t, e);
    const State& s = state_(t);
    const bool pop = threads_.request(t).unit != UnitId::kList;
    e.fields = 3;
    e.names = kIntersectionOutputFields;
    e.field = {static_cast<std::uint64_t>(pop ? IntersectionOut::kPop : IntersectionOut::kList),
               s.list.mask(Level::kBottom), s.done_mask()};
    e.wide.clear();
    for (int i = 0; i < s.p; ++i) {
      const HitRecord<F>& h = s.lane(i).hit;
      for (std::uint32_t w : {h.t.bits, h.u.bits, h.v.bits, h.c.bits, h.instance, h.triangle})
        e.wide.push_back(w);
    }
  }

 private:
  const ThreadTable& threads_;
  StateOf state_;
};

}  // namespace saarcor::units
