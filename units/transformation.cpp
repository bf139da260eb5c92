// Transformation unit of the DynRTP (paper section 3.1, Figure 2 paths a, b, d, e;
// docs/cycle-model.md; decisions D30, D31, D32). Depth: fp mul, then the two adds of (m0 x + m1 y)
// + (m2 z + t) = 3 + 3 + 3 = 9 cycles by default; n+1 (shared origin) or 2n steps per packet.
#include "units/dynrtc_units.h"

#include "memif/image_format.h"

namespace saarcor::units {

TransformationUnit::TransformationUnit(hw::Kernel& k, std::string name, ThreadTable& t, int depth,
                                       memif::Cache& cache)
    : CycleUnit(k, std::move(name), UnitId::kTransformation, t, depth, &cache) {}

// An object entry reads the instance's six rows (matrix, header with the bottom tree's root, the
// object box the traversal clips against); a triangle entry the three rows of T_delta; ray
// generation gets its matrix from the RGS on path a.
CycleUnit::Fetch TransformationUnit::fetch(const Request& r) const {
  if (r.phase == Phase::kTransformObject) return {r.item, memif::kInstanceRows};
  if (r.phase == Phase::kTransformTriangle) return {r.item, memif::kTriangleRows};
  return {};
}

}  // namespace saarcor::units
