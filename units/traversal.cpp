// Traversal unit of the DynRTP (paper section 3.1, Figure 2 paths b, c, f, g; docs/cycle-model.md;
// decisions D26, D27, D29, D33). Depth: fp add (split - O) + fp div (/ D) + fp cmp (near/far/
// termination) = 3 + 8 + 1 = 12 cycles by default.
#include "units/dynrtc_units.h"

namespace saarcor::units {

TraversalUnit::TraversalUnit(hw::Kernel& k, std::string name, ThreadTable& t, int depth,
                             memif::Cache& cache)
    : CycleUnit(k, std::move(name), UnitId::kTraversal, t, depth, &cache) {}

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
