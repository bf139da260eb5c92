// The busiest-unit objective (host/tree_objective.h; docs/kdtree.md "Busiest unit").
#include "host/tree_objective.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

namespace saarcor::host {
namespace {

struct Walk {
  double steps = 0.0;  // inner nodes and non-empty leaves: the nodes the traversal unit fetches
  double inner = 0.0;  // inner nodes only (the SAH's traversal steps)
  double tests = 0.0;  // list entries, each a triangle test
};

// Surface-area probabilities of every node relative to the root box, as compute_kdtree_stats
// takes them, split into the nodes the traversal unit steps into and the entries it hands on.
Walk walk(const KdTree& tree) {
  Walk w;
  if (tree.nodes.empty()) {
    return w;
  }
  using Box = std::array<std::array<double, 3>, 2>;
  const auto half_area = [](const Box& b) {
    const double x = b[1][0] - b[0][0], y = b[1][1] - b[0][1], z = b[1][2] - b[0][2];
    return x * y + y * z + z * x;
  };
  Box root{};
  if (!tree.bounds.empty()) {
    for (int k = 0; k < 3; ++k) {
      root[0][k] = tree.bounds.lo[k];
      root[1][k] = tree.bounds.hi[k];
    }
  }
  const double root_area = half_area(root);
  std::vector<std::pair<std::uint32_t, Box>> stack{{0, root}};
  while (!stack.empty()) {
    const auto [n, box] = stack.back();
    stack.pop_back();
    const KdTreeNode& nd = tree.nodes[n];
    const double pr = root_area > 0.0 ? half_area(box) / root_area : 1.0;
    if (nd.leaf) {
      if (nd.count == 0) {  // flagged empty in its parent: never fetched
        continue;
      }
      w.steps += pr;
      w.tests += pr * nd.count;
      continue;
    }
    w.steps += pr;
    w.inner += pr;
    Box l = box;
    Box r = box;
    l[1][nd.axis] = nd.split;
    r[0][nd.axis] = nd.split;
    stack.push_back({nd.child + 1, r});
    stack.push_back({nd.child, l});
  }
  return w;
}

KdUnitLoads loads_of(const Walk& w) {
  return {kTraversalCyclesPerStep * w.steps, kListCyclesPerEntry * w.tests,
          kTransformationCyclesPerTest * w.tests, kIntersectionCyclesPerTest * w.tests};
}

// The tree's stats at the configured costs, with the objective's record.
void record(KdTree& tree, const KdBuildParams& params, float chosen, double seconds) {
  tree.stats = compute_kdtree_stats(tree, params);
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
  return loads_of(walk(tree));
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
  const auto sah = [&](const KdTree& t) {
    const Walk w = walk(t);
    return params.traversal_cost * w.inner + params.intersection_cost * w.tests;
  };
  double best_sah = sah(best);
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
    const double s = sah(t);
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
