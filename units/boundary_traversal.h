// The traversal unit's ports as hardware carries them (the boundary record, units/boundary.h;
// paper section 3.1, Figure 2 paths b, c, f and g; D26, D27, D29), read from the thread
// program's state:
//   input, op 0, a level starts (path b from the transformation unit, or RGS -> traversal):
//     level (0 top, 1 bottom), shadow, valid and done (per lane), mask (a bottom level's entry
//     mask), root (a bottom level's kd-tree root); wide: per lane the level's ray O[3], D[3] and
//     t_best (fp encodings), then for a bottom level the object's box, rows 4-5 of the instance
//     record (lo[3], hi[3]). A bottom level's t_best is the unit's own copy (the hit updates).
//   input, op 1, a pop (f from the intersection unit, list -> traversal): no payload;
//   input, op 2, the unit's own loop: node, mask (what the unit keeps: it is not driven);
//   side band (the thread leaves the intersection unit, whatever its path): the hit update,
//     done (per lane); wide: per lane t_best;
//   output: dest (0 the unit's own loop, 1 a leaf's list to the list unit, 2 the end of a bottom
//     level: back to the top level's list, 3 the RGS), node (dest 0: the next node), first, end
//     (dest 1: the leaf's list), mask (dest 0: the next node's rays; dest 1: the rays in the
//     list), level (of the request that left). Fields a destination does not carry are 0.
#pragma once

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "units/boundary.h"
#include "units/packet_state.h"

namespace saarcor::units {

enum class TraversalIn : std::uint8_t { kStart = 0, kPop = 1, kLoop = 2 };
enum class TraversalOut : std::uint8_t { kLoop = 0, kLeaf = 1, kResume = 2, kRgs = 3 };

inline constexpr const char* kTraversalStartFields[] = {"op",   "level", "shadow", "valid",
                                                        "done", "mask",  "root"};
inline constexpr const char* kTraversalPopFields[] = {"op"};
inline constexpr const char* kTraversalLoopFields[] = {"op", "node", "mask"};
inline constexpr const char* kTraversalHitFields[] = {"done"};
inline constexpr const char* kTraversalOutputFields[] = {"dest", "node", "first",
                                                         "end",  "mask", "level"};
// The wide words of a level start: per lane O[3], D[3], t_best; a bottom level's box after them.
inline constexpr int kTraversalLaneWords = 7;

template <class F, int kLanes, class D>
class TraversalPayload final : public BoundaryPayload {
 public:
  using State = PacketState<F, kLanes, D>;
  using StateOf = std::function<const State&(ThreadToken)>;

  TraversalPayload(const ThreadTable& threads, StateOf state)
      : threads_(threads),
        state_(std::move(state)),
        before_(static_cast<std::size_t>(threads.size()), Level::kTop),
        after_(static_cast<std::size_t>(threads.size()), Level::kTop) {}

  void input(UnitId unit, UnitId from, ThreadToken t, BoundaryEvent& e) override {
    if (unit != UnitId::kTraversal) return RequestPayload(threads_).input(unit, from, t, e);
    const State& s = state_(t);
    if (from == UnitId::kTraversal) {
      e.fields = 3;
      e.names = kTraversalLoopFields;
      e.field = {static_cast<std::uint64_t>(TraversalIn::kLoop), s.traversal.node(),
                 s.traversal.mask()};
    } else if (from == UnitId::kIntersection || from == UnitId::kList) {
      e.fields = 1;
      e.names = kTraversalPopFields;
      e.field = {static_cast<std::uint64_t>(TraversalIn::kPop)};
    } else {
      start(s, e);
    }
  }

  // The hit update: every thread leaving the intersection unit.
  bool side_band(UnitId, UnitId from, ThreadToken t, BoundaryEvent& side) override {
    if (from != UnitId::kIntersection) return false;
    const State& s = state_(t);
    side.unit = UnitId::kTraversal;
    side.fields = 1;
    side.names = kTraversalHitFields;
    side.field = {s.done_mask()};
    side.wide.clear();
    for (int i = 0; i < s.p; ++i)
      side.wide.push_back(s.lane(i).hit.t.bits);
    return true;
  }

  void issued(UnitId, ThreadToken t, const Request&) override {
    before_[t] = after_[t];
    after_[t] = state_(t).traversal.level();
  }

  void output(UnitId unit, ThreadToken t, BoundaryEvent& e) override {
    if (unit != UnitId::kTraversal) return RequestPayload(threads_).output(unit, t, e);
    const State& s = state_(t);
    const Level level = before_[t];  // the level of the request that leaves
    e.fields = 6;
    e.names = kTraversalOutputFields;
    e.field = {};
    e.field[5] = static_cast<std::uint64_t>(level);
    switch (threads_.request(t).unit) {
      case UnitId::kTraversal:
        e.field[0] = static_cast<std::uint64_t>(TraversalOut::kLoop);
        e.field[1] = s.traversal.node();
        e.field[4] = s.traversal.mask();
        return;
      case UnitId::kList:
        if (after_[t] != level) {  // a bottom level ended: the top level's list resumes
          e.field[0] = static_cast<std::uint64_t>(TraversalOut::kResume);
          return;
        }
        e.field[0] = static_cast<std::uint64_t>(TraversalOut::kLeaf);
        e.field[2] = s.list.next(level);
        e.field[3] = s.list.end(level);
        e.field[4] = s.list.mask(level);
        return;
      case UnitId::kRgs:
        e.field[0] = static_cast<std::uint64_t>(TraversalOut::kRgs);
        return;
      default:
        throw std::logic_error(
            std::string("boundary record: the traversal unit has no path to the ") +
            unit_name(threads_.request(t).unit) + " unit");
    }
  }

 private:
  // A level starts: its rays, t_best, the lanes' flags, and a bottom level's object.
  static void start(const State& s, BoundaryEvent& e) {
    const bool bottom = s.traversal.level() == Level::kBottom;
    e.fields = 7;
    e.names = kTraversalStartFields;
    e.field = {static_cast<std::uint64_t>(TraversalIn::kStart),
               bottom ? 1u : 0u,
               s.kind == RayKind::kShadow ? 1u : 0u,
               s.valid_mask(),
               s.done_mask(),
               bottom ? s.list.entry_mask() : 0,
               bottom ? s.list.header().root : 0};
    e.wide.clear();
    for (int i = 0; i < s.p; ++i) {
      const Lane<F>& l = s.lane(i);
      const Ray<F>& ray = bottom ? l.current : l.world;
      for (const F& x : ray.o)
        e.wide.push_back(x.bits);
      for (const F& x : ray.d)
        e.wide.push_back(x.bits);
      e.wide.push_back(l.hit.t.bits);
    }
    if (!bottom) return;
    const std::uint32_t row = s.list.instance_row();
    for (std::uint32_t r : {row + 4, row + 5}) {
      const auto box = s.row(r);
      for (int k = 0; k < 3; ++k)
        e.wide.push_back(box[static_cast<std::size_t>(k)].bits);
    }
  }

  const ThreadTable& threads_;
  StateOf state_;
  // Per thread: the traversal level before and after the request it executed last.
  std::vector<Level> before_, after_;
};

}  // namespace saarcor::units
