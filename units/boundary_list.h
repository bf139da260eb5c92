// The mailboxed list unit's ports as hardware carries them (the boundary record, units/boundary.h;
// paper section 3.1, Figure 2 paths c and d; D28), read from the thread program's state:
//   input (path c from the traversal unit, the unit's own loop, the return from the intersection
//     unit): op (1: a leaf's list starts, 0: the current level's list resumes), level (0 top,
//     1 bottom), next, end (the list cursor), mask (the rays still in the list);
//   side band (path a): a new packet starts on the thread: its object mailbox is cleared (D28);
//   output: kind (0: an entry some ray still needs goes to the transformation unit, path d; 1: a
//     skipped entry, the list goes on through the unit's loop; 2: the list is done, the traversal
//     unit pops), level, next (the cursor after the entry), entry (kind 0: the instance or
//     triangle id), mask (kind 0: the rays that still need the entry; else the rays in the list),
//     list and last (kind 0: the level's rays still in the list and whether the entry was its
//     last, which travel with the entry through the transformation unit to the intersection
//     unit, D49, as units/boundary_transformation.h's path d input carries them; else 0).
// A resume's cursor is the unit's own (it holds next and end per thread and level); only the mask
// comes with the thread: the intersection unit's any-hit terminations remove rays from it.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "units/boundary.h"
#include "units/packet_state.h"

namespace saarcor::units {

enum class ListOut : std::uint8_t { kEntry = 0, kSkip = 1, kPop = 2 };

inline constexpr const char* kListInputFields[] = {"op", "level", "next", "end", "mask"};
inline constexpr const char* kListOutputFields[] = {"kind", "level", "next", "entry",
                                                    "mask", "list",  "last"};

template <class F, int kLanes, class D>
class ListPayload final : public BoundaryPayload {
 public:
  using State = PacketState<F, kLanes, D>;
  using StateOf = std::function<const State&(ThreadToken)>;

  ListPayload(const ThreadTable& threads, StateOf state)
      : threads_(threads),
        state_(std::move(state)),
        before_(static_cast<std::size_t>(threads.size()), Level::kTop),
        after_(static_cast<std::size_t>(threads.size()), Level::kTop) {}

  void input(UnitId unit, UnitId from, ThreadToken t, BoundaryEvent& e) override {
    if (unit != UnitId::kList) return RequestPayload(threads_).input(unit, from, t, e);
    const State& s = state_(t);
    const Level level = s.traversal.level();
    // A leaf hands its list over in the traversal step of the same level; a bottom-level tree
    // that ends resumes the top level's list (the level changed in that step).
    const bool start = from == UnitId::kTraversal && before_[t] == after_[t];
    e.fields = 5;
    e.names = kListInputFields;
    e.field = {start ? 1u : 0u, static_cast<std::uint64_t>(level), s.list.next(level),
               s.list.end(level), s.list.mask(level)};
  }

  // Path a: the RGS loads a new packet (TransformationStep::load clears the object mailbox).
  bool side_band(UnitId to, UnitId, ThreadToken t, BoundaryEvent& side) override {
    if (to != UnitId::kTransformation || threads_.request(t).phase != Phase::kGenerate)
      return false;
    side.unit = UnitId::kList;
    side.fields = 0;
    return true;
  }

  void issued(UnitId, ThreadToken t, const Request&) override {
    before_[t] = after_[t];
    after_[t] = state_(t).traversal.level();
  }

  void output(UnitId unit, ThreadToken t, BoundaryEvent& e) override {
    if (unit != UnitId::kList) return RequestPayload(threads_).output(unit, t, e);
    const State& s = state_(t);
    const Level level = before_[t];  // the level of the entry just read
    ListOut kind = ListOut::kPop;
    if (s.phase == Phase::kTransformObject || s.phase == Phase::kTransformTriangle)
      kind = ListOut::kEntry;
    else if (s.phase == Phase::kList && after_[t] == level)
      kind = ListOut::kSkip;
    std::uint64_t entry = 0, mask = s.list.mask(level), list = 0, last = 0;
    if (kind == ListOut::kEntry) {
      entry = level == Level::kTop ? s.list.instance() : s.list.triangle();
      mask = s.list.entry_mask();
      list = s.list.mask(level);
      last = s.list.next(level) >= s.list.end(level) ? 1u : 0u;
    }
    e.fields = 7;
    e.names = kListOutputFields;
    e.field = {static_cast<std::uint64_t>(kind),
               static_cast<std::uint64_t>(level),
               s.list.next(level),
               entry,
               mask,
               list,
               last};
  }

 private:
  const ThreadTable& threads_;
  StateOf state_;
  // Per thread: the traversal level before and after the request it executed last.
  std::vector<Level> before_, after_;
};

}  // namespace saarcor::units
