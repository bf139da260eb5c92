// The list unit's semantics (paper section 3.1; Figure 2 paths c and d; docs/cycle-model.md;
// decision D28): a leaf's list, one entry per request; at the top level an entry is an object
// instance, at the bottom level a triangle; the mailbox "omits objects already visited by the same
// ray" (and, with triangle_mailbox > 0, triangles). An entry some ray still needs goes to the
// transformation unit (path d); the end of the list returns the packet to the traversal unit.
// Timing: units/list_unit.cpp (depth: the mailbox compare); exact-cycle test:
// units/unit_timing_test.cpp (UnitTimingList.*).
#pragma once

#include <cstdint>

#include "units/mailbox.h"
#include "units/packet.h"

namespace saarcor::units {

template <class F, int kLanes, class D>
class ListStep {
 public:
  using State = PacketState<F, kLanes, D>;

  explicit ListStep(const FunctionalParams& params)
      : mailbox_(params.mailbox), tri_mailbox_(params.triangle_mailbox) {}

  // The entry the list unit handed on, read by the transformation and intersection units and by
  // the traversal unit's object clip.
  std::uint64_t entry_mask() const { return entry_mask_; }
  std::uint32_t instance() const { return instance_; }
  std::uint32_t instance_row() const { return instance_row_; }
  std::uint32_t triangle() const { return triangle_; }
  const memif::InstanceHeader& header() const { return header_; }
  // The entry the next request reads, and its rays.
  std::uint32_t next(Level level) const { return cursor(level).next; }
  std::uint64_t mask(Level level) const { return cursor(level).mask; }
  // The end of the level's list (the boundary record's payload on path c, units/boundary_list.h).
  std::uint32_t end(Level level) const { return cursor(level).end; }
  // The level's list has no entry left for its rays.
  bool done(Level level) const {
    const Cursor& c = cursor(level);
    return c.next >= c.end || c.mask == 0;
  }

  // A packet leaves its mailbox behind (D28: a mailbox belongs to one packet's rays).
  void clear() { mailbox_.clear(); }

  // A leaf's list entries first .. end - 1 for the rays in `mask` (path c).
  void start(Level level, std::uint32_t first, std::uint32_t end, std::uint64_t mask) {
    Cursor& c = cursor(level);
    c.next = first;
    c.end = end;
    c.mask = mask;
  }

  // Entering an object: its header, and a clear triangle mailbox.
  void enter_object(const State& t) {
    header_ = t.image.instance_header(instance_);
    tri_mailbox_.clear();
  }

  // One list entry (a request): mailboxed, then to the transformation unit or on to the next.
  void step(State& t) {
    const Level level = t.traversal.level();
    Cursor& c = cursor(level);
    // Back from an object whose top-level list is done: the thread passes on to the traversal
    // unit's pop without reading an entry (the unit holds the cursor; the traversal unit cannot
    // know the list is done).
    if (done(level)) {
      ++t.u.list_returns;
      t.phase = Phase::kPop;
      return;
    }
    ++t.u.list_steps;
    const std::uint32_t entry = t.scene.list_entry(c.next++);
    // The matrix rows of this entry and of the next (its list entry was prefetched at the leaf).
    prefetch_entry_rows(t, entry);
    if (c.next < c.end) prefetch_entry_rows(t, t.scene.list_entry(c.next));
    for (int i = 0; i < t.p; ++i)
      t.lane(i).counters.list_entries += (c.mask >> i) & 1u;
    Mailbox& mb = level == Level::kTop ? mailbox_ : tri_mailbox_;
    const std::uint64_t todo = mb.filter(entry, c.mask);
    for (int i = 0; i < t.p; ++i)
      t.lane(i).counters.mailbox_skips += ((c.mask & ~todo) >> i) & 1u;
    if (todo == 0) return resume(t);
    entry_mask_ = todo;
    if (level == Level::kTop) {
      instance_ = entry;
      instance_row_ = t.image.registers().instance_row_base + memif::kInstanceRows * entry;
      t.phase = Phase::kTransformObject;
    } else {
      triangle_ = entry;
      t.phase = Phase::kTransformTriangle;
    }
  }

  // Back at the current level's list (from the intersection unit, or the list unit's own skip):
  // its next entry, or the traversal unit's pop once the list is done or (any-hit) its rays are.
  // The stack is the traversal unit's: the thread goes there to pop (path f, list -> traversal).
  void resume(State& t) {
    drop_done(t);
    t.phase = done(t.traversal.level()) ? Phase::kPop : Phase::kList;
  }

  // An object's bottom level ended: the thread goes back to the list unit (path c), which reads
  // the top-level list's next entry or, when it is done, sends the thread on to the pop.
  void return_to_list(State& t) {
    drop_done(t);
    t.phase = Phase::kList;
  }

 private:
  // Any-hit rays that are done leave the level's list (the mask travels with the thread).
  void drop_done(State& t) {
    if (t.kind != RayKind::kShadow) return;
    Cursor& c = cursor(t.traversal.level());
    c.mask &= ~t.done_mask();
  }

  struct Cursor {
    std::uint32_t next = 0, end = 0;
    std::uint64_t mask = 0;
  };
  Cursor& cursor(Level level) { return level == Level::kTop ? top_list_ : bottom_list_; }
  const Cursor& cursor(Level level) const {
    return level == Level::kTop ? top_list_ : bottom_list_;
  }

  void prefetch_entry_rows(const State& t, std::uint32_t entry) const {
    if (t.traversal.level() == Level::kTop)
      t.scene.prefetch_rows(t.image.registers().instance_row_base + memif::kInstanceRows * entry,
                            memif::kInstanceRows);
    else
      t.scene.prefetch_rows(header_.triangle_row_base + memif::kTriangleRows * entry,
                            memif::kTriangleRows);
  }

  Cursor top_list_, bottom_list_;
  Mailbox mailbox_, tri_mailbox_;
  std::uint64_t entry_mask_ = 0;
  std::uint32_t instance_ = 0, instance_row_ = 0, triangle_ = 0;
  memif::InstanceHeader header_;
};

}  // namespace saarcor::units
