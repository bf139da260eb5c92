// The busiest-unit objective (host/tree_objective.h; docs/kdtree.md "Busiest unit").
#include "host/tree_objective.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace saarcor::host {
namespace {

// The SAH cost at the configured costs of a tree built at any K_T (the formula of
// compute_kdtree_stats, on the expectations the builder already computed).
double sah_at(const KdBuildParams& params, const KdTreeStats& s) {
  return params.traversal_cost * s.expected_traversal_steps +
         params.intersection_cost * s.expected_item_tests;
}

// The tree's stats at the configured costs, with the objective's record.
void record(KdTree& tree, const KdBuildParams& params, float chosen, double seconds) {
  tree.stats.sah_cost = sah_at(params, tree.stats);
  tree.stats.build_seconds = seconds;
  const KdUnitLoads u = kd_unit_loads(tree);
  tree.stats.chosen_traversal_cost = chosen;
  tree.stats.expected_traversal_cycles = u.traversal;
  tree.stats.expected_list_cycles = u.list;
  tree.stats.expected_transformation_cycles = u.transformation;
  tree.stats.expected_intersection_cycles = u.intersection;
}

}  // namespace

double KdUnitLoads::busiest() const {
  return std::max({traversal, list, transformation, intersection});
}

KdUnitLoads kd_unit_loads(const KdTree& tree) {
  const KdTreeStats& s = tree.stats;
  // The nodes the traversal unit fetches: inner nodes and non-empty leaves.
  const double steps = s.expected_traversal_steps + s.expected_fetched_leaves;
  const double tests = s.expected_item_tests;
  return {kTraversalCyclesPerStep * steps, kListCyclesPerEntry * tests,
          kTransformationCyclesPerTest * tests, kIntersectionCyclesPerTest * tests};
}

std::vector<float> kd_objective_ladder(float traversal_cost) {
  std::vector<float> v;
  for (int i = -4; i <= 4; ++i) {
    v.push_back(static_cast<float>(traversal_cost * std::exp2(0.5 * i)));
  }
  return v;
}

KdTree build_kdtree_for_units(std::span<const glm::vec3> positions,
                              std::span<const glm::uvec3> tris, std::span<const std::uint8_t> skip,
                              const KdBuildParams& params, KdObjective objective,
                              double min_ratio) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto since = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  KdTree best = build_kdtree(positions, tris, skip, params);
  if (objective == KdObjective::kSahSum) {
    record(best, params, params.traversal_cost, since());
    return best;
  }
  KdUnitLoads best_loads = kd_unit_loads(best);
  const double lighter = std::min(best_loads.traversal, best_loads.transformation);
  const double heavier = std::max(best_loads.traversal, best_loads.transformation);
  if (heavier < min_ratio * lighter) {
    record(best, params, params.traversal_cost, since());
    return best;
  }
  const std::vector<float> ladder = kd_objective_ladder(params.traversal_cost);
  const int middle = static_cast<int>(ladder.size()) / 2;
  // The SAH cost at the configured costs breaks ties (the plain sum is the better tree when the
  // busiest unit does not care).
  double best_sah = sah_at(params, best.stats);
  float chosen = params.traversal_cost;
  // Dearer steps trade traversal steps for triangle tests and cheaper ones the reverse, so the
  // walk goes towards the unit that is not the busiest and stops where the busiest load rises
  // (it passes rungs that build the same tree: a leaf stays a leaf over a range of K_T).
  const int dir = best_loads.traversal >= best_loads.transformation ? 1 : -1;
  for (int i = middle + dir; i >= 0 && i < static_cast<int>(ladder.size()); i += dir) {
    KdBuildParams p = params;
    p.traversal_cost = ladder[static_cast<std::size_t>(i)];
    KdTree t = build_kdtree(positions, tris, skip, p);
    const KdUnitLoads u = kd_unit_loads(t);
    if (u.busiest() > best_loads.busiest()) {
      break;
    }
    const double s = sah_at(params, t.stats);
    const bool better = u.busiest() < best_loads.busiest() || s < best_sah;
    if (!better) {
      continue;
    }
    best = std::move(t);
    best_loads = u;
    best_sah = s;
    chosen = p.traversal_cost;
  }
  record(best, params, chosen, since());
  return best;
}

}  // namespace saarcor::host
