// Traversal unit of the DynRTP (paper section 3.1, Figure 2 paths b, c, f, g; docs/cycle-model.md;
// decisions D26, D27, D29, D33). Depth: fp add (split - O) + fp div (/ D) + fp cmp (near/far/
// termination) = 3 + 8 + 1 = 12 cycles by default.
#include "units/dynrtc_units.h"

#include <algorithm>

namespace saarcor::units {

TraversalUnit::TraversalUnit(hw::Kernel& k, std::string name, ThreadTable& t, int depth,
                             memif::Cache& cache)
    : CycleUnit(k, std::move(name), UnitId::kTraversal, t, depth, &cache) {
  has_extra_ = true;
}

// The pop engine (docs/cycle-model.md "The pop engine"; rtl/traversal_ctrl.sv): the stack is a
// memory the unit reads one entry per cycle. A request whose step ends in a pop (a pop request
// after a list, a node step that leaves no child) reaches the engine at the pipeline's last stage;
// the engine reads the top entry there and, if the entry decides (it is popped, or the level's
// stack is empty), the thread leaves in that cycle as any other. Each dropped entry (its rays have
// all terminated or, any-hit, are done) costs one more cycle, and while the engine works through
// one thread's entries, pops arriving behind it wait in its queue, in arrival order.
bool TraversalUnit::hold(ThreadToken t) {
  const int entries = threads_.request(t).pop_cycles;
  if (entries == 0) return false;
  stage_.push_back({now() + static_cast<std::uint64_t>(depth()), t, entries});
  return true;
}

// One cycle of the pop engine: the queue's head reads its next entry (and leaves once that entry
// decides); a pop reaching the last stage is served at once when the queue was empty, else it
// joins the queue with all its entries still to read.
int TraversalUnit::extra() {
  int progress = 0;
  const bool busy = !queue_.empty();
  if (busy) {
    Popping& head = queue_.front();
    if (head.entries > 1) {
      --head.entries;
    } else if (leave(head.thread)) {
      queue_.pop_front();
    } else {
      stall();
    }
    progress = 1;
  }
  if (!stage_.empty() && stage_.front().at <= now()) {
    Popping p = stage_.front();
    stage_.pop_front();
    if (!busy) --p.entries;  // the engine reads its first entry in the last stage
    if (busy || p.entries > 0 || !leave(p.thread))
      queue_.push_back({p.at, p.thread, std::max(p.entries, 1)});
    progress = 1;
  }
  return progress;
}

std::uint64_t TraversalUnit::extra_wakeup(std::uint64_t now) const {
  if (!queue_.empty()) return now + 1;
  if (!stage_.empty()) return std::max(now + 1, stage_.front().at);
  return hw::kNever;
}

// A node step reads its kd-node (one request for the packet, D20); a clip face reads nothing (the
// scene box is a frame register, the object box came with the instance's rows on path b).
CycleUnit::Fetch TraversalUnit::fetch(const Request& r) const {
  if (r.phase == Phase::kTraverse) return {r.item, 1};
  return {};
}

// The six faces of a box are independent divisions (max/min folds at the end): they issue on
// consecutive cycles and leave the pipeline once.
bool TraversalUnit::chains(const Request& done, const Request& next) const {
  const bool clip = done.phase == Phase::kClipTop || done.phase == Phase::kClipBottom;
  return clip && next.phase == done.phase;
}

}  // namespace saarcor::units
