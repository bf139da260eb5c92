// Mailboxed list unit of the DynRTP (paper section 3.1, Figure 2 paths c, d; docs/cycle-model.md;
// decision D28). Depth: the mailbox compare, fp-cmp latency (1 cycle by default).
#include "units/dynrtc_units.h"

namespace saarcor::units {

ListUnit::ListUnit(hw::Kernel& k, std::string name, ThreadTable& t, int depth, memif::Cache& cache)
    : CycleUnit(k, std::move(name), UnitId::kList, t, depth, &cache) {}

// One list entry per request through the list cache; a skipped (mailboxed) entry still costs its
// fetch and its cycle. A thread back from an object whose list is done reads nothing: it passes
// through the issue slot on to the traversal unit's pop.
CycleUnit::Fetch ListUnit::fetch(const Request& r) const {
  if (r.item == memif::kNone) return {};
  return {r.item, 1};
}

}  // namespace saarcor::units
