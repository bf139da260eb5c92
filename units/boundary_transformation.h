// The transformation unit's ports as hardware carries them (the boundary record, units/boundary.h;
// paper sections 2.2, 2.3 and 3.1, Figure 2 paths a, b, d and e; D25, D30, D31, D32), read from
// the thread program's state:
//   input, op 0 (path d from the list unit, served first, D25): kind (0 an object: the
//     instance's six rows; 1 a triangle: T_delta's three rows), entry (the instance or triangle
//     id), mask (the rays that enter it), list (the rays still in the level's list), last (the
//     entry was its list's last); the unit computes the row address from the entry (an object's
//     from the frame's instance_row_base, a triangle's from the triangle_row_base its object's
//     header row brought) and keeps the header per thread;
//   input, op 1 (path a from the RGS, ray generation): shadow, shared (the packet's rays share an
//     origin: the n + 1 rule, D31), valid (per lane); wide: per lane T[12] (the rows m_r0, m_r1,
//     m_r2, t_r), R'o[3], R'd[3];
//   cache port (the row cache, D32): one request per row, the rows of an entry in consecutive
//     cycles (address = row index); the response's words are the row's packed words;
//   output: dest (0 the traversal unit, path b or RGS -> traversal: a level starts; 1 the
//     intersection unit, path e; 2 the RGS: shadow rays, which the RGS decides to trace), level
//     (0 top: ray generation; 1 bottom: an object), shared, mask (the rays that entered: an
//     entry's mask, or ray generation's valid lanes), root (dest 0, bottom: the object's kd-tree
//     root, from its header row); wide: per lane the transformed ray O[3], D[3] (world rays,
//     object-space rays or unit-triangle-space rays); an object's box after them (rows 4 and 5 of
//     the instance record, lo[3], hi[3]), which the traversal unit clips against (D29); dest 1
//     also carries what the intersection unit's input takes (units/boundary_intersection.h):
//     list and last as path d brought them, instance (the object the thread entered: its last
//     object entry) and triangle (the entry's id); dest 0 and 2 (a level starts at the traversal
//     unit, after the RGS for shadow rays) carry shadow (the packet's kind, from path a). A field
//     a destination does not carry is 0.
// Steps: n + 1 for a packet whose rays share an origin, 2n otherwise, whatever the mask (D30).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "units/boundary.h"
#include "units/packet_state.h"

namespace saarcor::units {

enum class TransformationIn : std::uint8_t { kEntry = 0, kGenerate = 1 };
enum class TransformationOut : std::uint8_t { kTraversal = 0, kIntersection = 1, kRgs = 2 };

inline constexpr const char* kTransformationEntryFields[] = {"op",   "kind", "entry",
                                                             "mask", "list", "last"};
inline constexpr const char* kTransformationGenerateFields[] = {"op", "shadow", "shared", "valid"};
inline constexpr const char* kTransformationOutputFields[] = {
    "dest", "level", "shared", "mask", "root", "list", "last", "instance", "triangle", "shadow"};
// Wide words per lane: ray generation's input (T, R'o, R'd) and an output's ray (O, D).
inline constexpr int kTransformationGenerateWords = 18;
inline constexpr int kTransformationRayWords = 6;

template <class F, int kLanes, class D>
class TransformationPayload final : public BoundaryPayload {
 public:
  using State = PacketState<F, kLanes, D>;
  using StateOf = std::function<const State&(ThreadToken)>;

  TransformationPayload(const ThreadTable& threads, StateOf state)
      : threads_(threads),
        state_(std::move(state)),
        phase_(static_cast<std::size_t>(threads.size()), Phase::kGenerate) {}

  void input(UnitId unit, UnitId from, ThreadToken t, BoundaryEvent& e) override {
    if (unit != UnitId::kTransformation) return RequestPayload(threads_).input(unit, from, t, e);
    const State& s = state_(t);
    e.wide.clear();
    if (threads_.request(t).phase == Phase::kGenerate) return generate(s, e);
    const Level level = s.traversal.level();
    const bool object = threads_.request(t).phase == Phase::kTransformObject;
    e.fields = 6;
    e.names = kTransformationEntryFields;
    e.field = {static_cast<std::uint64_t>(TransformationIn::kEntry),
               object ? 0u : 1u,
               object ? s.list.instance() : s.list.triangle(),
               s.list.entry_mask(),
               s.list.mask(level),
               s.list.next(level) >= s.list.end(level) ? 1u : 0u};
  }

  bool side_band(UnitId, UnitId, ThreadToken, BoundaryEvent&) override { return false; }

  void issued(UnitId unit, ThreadToken t, const Request& r) override {
    if (unit == UnitId::kTransformation) phase_[t] = r.phase;
  }

  void output(UnitId unit, ThreadToken t, BoundaryEvent& e) override {
    if (unit != UnitId::kTransformation) return RequestPayload(threads_).output(unit, t, e);
    const State& s = state_(t);
    const Phase done = phase_[t];
    const bool object = done == Phase::kTransformObject;
    TransformationOut dest = TransformationOut::kTraversal;
    if (done == Phase::kTransformTriangle)
      dest = TransformationOut::kIntersection;
    else if (threads_.request(t).unit == UnitId::kRgs)
      dest = TransformationOut::kRgs;
    const bool triangle = dest == TransformationOut::kIntersection;
    e.fields = 10;
    e.names = kTransformationOutputFields;
    e.field = {static_cast<std::uint64_t>(dest),
               object ? 1u : 0u,
               s.shared_origin ? 1u : 0u,
               done == Phase::kGenerate ? s.valid_mask() : s.list.entry_mask(),
               object ? s.list.header().root : 0u,
               triangle ? s.list.mask(Level::kBottom) : 0u,
               triangle && s.list.next(Level::kBottom) >= s.list.end(Level::kBottom) ? 1u : 0u,
               triangle ? s.list.instance() : 0u,
               triangle ? s.list.triangle() : 0u,
               !triangle && s.kind == RayKind::kShadow ? 1u : 0u};
    e.wide.clear();
    Ray<F> Lane<F>::*ray = done == Phase::kGenerate ? &Lane<F>::world
                           : object                 ? &Lane<F>::current
                                                    : &Lane<F>::tri;
    for (int i = 0; i < s.p; ++i) {
      const Ray<F>& r = s.lane(i).*ray;
      for (const F& x : r.o)
        e.wide.push_back(x.bits);
      for (const F& x : r.d)
        e.wide.push_back(x.bits);
    }
    if (!object) return;
    const std::uint32_t row = s.list.instance_row();
    for (std::uint32_t r : {row + 4, row + 5}) {
      const auto box = s.row(r);
      for (int k = 0; k < 3; ++k)
        e.wide.push_back(box[static_cast<std::size_t>(k)].bits);
    }
  }

 private:
  // Ray generation's packet (TransformationStep::input, loaded by the RGS before the push).
  void generate(const State& s, BoundaryEvent& e) const {
    const GenPacket<F>& pk = s.transformation.input();
    e.fields = 4;
    e.names = kTransformationGenerateFields;
    e.field = {static_cast<std::uint64_t>(TransformationIn::kGenerate),
               pk.kind == RayKind::kShadow ? 1u : 0u, pk.shared_origin ? 1u : 0u, s.valid_mask()};
    for (int i = 0; i < s.p; ++i) {
      const GenLane<F>& g = pk.lanes[static_cast<std::size_t>(i)];
      for (const auto& row : g.t)
        for (const F& x : row)
          e.wide.push_back(x.bits);
      for (const F& x : g.ro)
        e.wide.push_back(x.bits);
      for (const F& x : g.rd)
        e.wide.push_back(x.bits);
    }
  }

  const ThreadTable& threads_;
  StateOf state_;
  std::vector<Phase> phase_;  // per thread: the phase of its last request on this unit
};

}  // namespace saarcor::units
