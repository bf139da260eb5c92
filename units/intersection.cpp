// Intersection unit of the DynRTP (paper section 3.1, Figure 2 paths e, f; docs/cycle-model.md;
// decision D30). Depth: t = -O'z / D'z (div), u = O'x + t D'x (mul, add), u + v (add), the hit
// compares (cmp) = 8 + 3 + 3 + 3 + 1 = 18 cycles by default; one ray per cycle.
#include "units/dynrtc_units.h"

namespace saarcor::units {

IntersectionUnit::IntersectionUnit(hw::Kernel& k, std::string name, ThreadTable& t, int depth)
    : CycleUnit(k, std::move(name), UnitId::kIntersection, t, depth, nullptr) {}

// The ray in unit-triangle space comes on path e: nothing to fetch.
CycleUnit::Fetch IntersectionUnit::fetch(const Request&) const {
  return {};
}

}  // namespace saarcor::units
