// The busiest-unit objective for bottom-level kd-trees (docs/kdtree.md "Busiest unit"): the
// DynRTP's traversal, list, transformation and intersection units run in parallel, so a frame
// takes about as long as its busiest unit, not as long as the SAH's sum of steps and tests.
// With the objective a tree is built at several K_T values and the one whose SAH-expected load
// in its busiest unit is lowest is kept.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "host/kdtree.h"

namespace saarcor::host {

enum class KdObjective : int {
  kSahSum = 0,       // one build at the configured K_T (build_kdtree's tree)
  kBusiestUnit = 1,  // the K_T ladder, the lowest busiest-unit load kept
};

// Unit cycles per 4-ray packet (the prototype's P = 4, docs/kdtree.md "Costs for this
// hardware"): a traversal step (inner node or non-empty leaf; empty children are skipped in
// their parent) is one traversal cycle, a list entry one list cycle, a triangle test P + 1
// transformation cycles (the shared-origin rule, D31) and P intersection cycles.
inline constexpr double kTraversalCyclesPerStep = 1.0;
inline constexpr double kListCyclesPerEntry = 1.0;
inline constexpr double kTransformationCyclesPerTest = 5.0;
inline constexpr double kIntersectionCyclesPerTest = 4.0;

// SAH-expected unit cycles per packet that enters the tree's root box (surface-area
// probabilities relative to the root box, every ray of the packet taking the same path).
struct KdUnitLoads {
  double traversal = 0.0;
  double list = 0.0;
  double transformation = 0.0;
  double intersection = 0.0;
  double busiest() const;
};

// From the expectations compute_kdtree_stats stored in tree.stats (a built tree's).
KdUnitLoads kd_unit_loads(const KdTree& tree);

// The K_T values a busiest-unit build may use: K_T * 2^(i/2) for i = -4..4 (K_T / 4 .. 4 K_T),
// ascending; the configured K_T is the middle rung.
std::vector<float> kd_objective_ladder(float traversal_cost);

// A bottom-level tree (build_kdtree's arguments) under `objective`. kSahSum returns
// build_kdtree's tree. kBusiestUnit starts at the configured K_T and walks the ladder towards
// the lighter unit (up while traversal is the busiest, down while transformation is) as long as
// the busiest unit's load does not rise; ties go to the lower SAH cost at the configured costs.
// Every rung is built with the node bound. A tree whose plain loads of the two units the walk
// trades (traversal and transformation) differ by less than `min_ratio` is not walked: the
// objective is for trees that overload one unit while the other idles. Either way the stats'
// sah_cost is at the configured costs, build_seconds counts every rung, and the chosen K_T and
// unit loads are recorded.
KdTree build_kdtree_for_units(std::span<const glm::vec3> positions,
                              std::span<const glm::uvec3> tris, std::span<const std::uint8_t> skip,
                              const KdBuildParams& params, KdObjective objective,
                              double min_ratio = 1.0);

}  // namespace saarcor::host
