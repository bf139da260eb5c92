// Tests of the busiest-unit objective (host/tree_objective.h, docs/kdtree.md "Busiest unit"): the
// unit loads against a hand-counted tree, the objective's tree against the plain SAH tree on
// inputs where the plain tree overloads one unit, and the plain objective against build_kdtree.
#include "host/tree_objective.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "host/image_builder.h"
#include "host/tree_settings.h"

namespace saarcor::host {
namespace {

struct Mesh {
  std::vector<glm::vec3> pos;
  std::vector<glm::uvec3> tris;
};

// n x n x n small triangles on a lattice of spacing 1: separable everywhere, so K_T alone decides
// how deep the tree goes.
Mesh lattice(int n) {
  Mesh m;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const glm::vec3 c(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
        const auto base = static_cast<unsigned>(m.pos.size());
        m.pos.push_back(c);
        m.pos.push_back(c + glm::vec3(0.25f, 0.0f, 0.125f));
        m.pos.push_back(c + glm::vec3(0.0f, 0.25f, 0.0625f));
        m.tris.emplace_back(base, base + 1, base + 2);
      }
  return m;
}

bool same_tree(const KdTree& a, const KdTree& b) {
  if (a.nodes.size() != b.nodes.size() || a.items != b.items) return false;
  for (std::size_t i = 0; i < a.nodes.size(); ++i) {
    const KdTreeNode& x = a.nodes[i];
    const KdTreeNode& y = b.nodes[i];
    if (x.leaf != y.leaf || x.axis != y.axis || x.split != y.split || x.child != y.child ||
        x.first != y.first || x.count != y.count)
      return false;
  }
  return true;
}

bool on_ladder(float k_t, float configured) {
  const std::vector<float> ladder = kd_objective_ladder(configured);
  return std::find(ladder.begin(), ladder.end(), k_t) != ladder.end();
}

// A single leaf of n triangles: one step and n entries per packet, each entry 5 transformation
// and 4 intersection cycles.
TEST(TreeObjective, LoadsOfALeafFollowTheUnits) {
  const Mesh m = lattice(2);
  KdBuildParams p;
  p.leaf_size = 8;  // 8 triangles: one leaf
  const KdTree tree = build_kdtree(m.pos, m.tris, {}, p);
  ASSERT_EQ(tree.nodes.size(), 1u);
  const KdUnitLoads u = kd_unit_loads(tree);
  EXPECT_DOUBLE_EQ(u.traversal, 1.0);
  EXPECT_DOUBLE_EQ(u.list, 8.0);
  EXPECT_DOUBLE_EQ(u.transformation, 40.0);
  EXPECT_DOUBLE_EQ(u.intersection, 32.0);
  EXPECT_DOUBLE_EQ(u.busiest(), 40.0);
}

// With the objective off the tree is build_kdtree's, node for node, and its stats say so.
TEST(TreeObjective, SahSumIsBuildKdtreesTree) {
  const Mesh m = lattice(5);
  KdBuildParams p;
  p.traversal_cost = 5.0f;  // a traversal-heavy plain tree, which the objective would change
  const KdTree plain = build_kdtree(m.pos, m.tris, {}, p);
  const KdTree off = build_kdtree_for_units(m.pos, m.tris, {}, p, KdObjective::kSahSum);
  EXPECT_TRUE(same_tree(off, plain));
  EXPECT_EQ(off.stats.chosen_traversal_cost, 5.0);
  EXPECT_DOUBLE_EQ(off.stats.sah_cost, plain.stats.sah_cost);
  EXPECT_DOUBLE_EQ(off.stats.expected_transformation_cycles, kd_unit_loads(plain).transformation);
  const KdTree on = build_kdtree_for_units(m.pos, m.tris, {}, p, KdObjective::kBusiestUnit);
  EXPECT_FALSE(same_tree(on, plain));
}

// Cheap steps make the plain tree traversal-heavy (deep, one triangle per leaf); the objective
// climbs the ladder and keeps a tree whose busiest unit is less loaded.
TEST(TreeObjective, TraversalHeavyTreeGetsDearerSteps) {
  const Mesh m = lattice(6);
  KdBuildParams p;
  p.traversal_cost = 2.0f;
  const KdTree plain = build_kdtree(m.pos, m.tris, {}, p);
  const KdUnitLoads pu = kd_unit_loads(plain);
  ASSERT_GT(pu.traversal, pu.transformation);
  const KdTree t = build_kdtree_for_units(m.pos, m.tris, {}, p, KdObjective::kBusiestUnit);
  const KdUnitLoads u = kd_unit_loads(t);
  EXPECT_LT(u.busiest(), pu.busiest());
  EXPECT_GT(t.stats.chosen_traversal_cost, 2.0);
  EXPECT_TRUE(on_ladder(static_cast<float>(t.stats.chosen_traversal_cost), 2.0f));
  EXPECT_DOUBLE_EQ(t.stats.expected_traversal_cycles, u.traversal);
  EXPECT_DOUBLE_EQ(t.stats.expected_transformation_cycles, u.transformation);
  EXPECT_DOUBLE_EQ(t.stats.expected_list_cycles, u.list);
  EXPECT_DOUBLE_EQ(t.stats.expected_intersection_cycles, u.intersection);
}

// Dear steps make the plain tree one leaf (every triangle tested); the objective walks down the
// ladder, past the rungs that still build the leaf, to a split tree.
TEST(TreeObjective, TestHeavyTreeGetsCheaperSteps) {
  const Mesh m = lattice(4);
  KdBuildParams p;
  p.traversal_cost = 1000.0f;
  const KdTree plain = build_kdtree(m.pos, m.tris, {}, p);
  ASSERT_EQ(plain.nodes.size(), 1u);
  const KdUnitLoads pu = kd_unit_loads(plain);
  ASSERT_GT(pu.transformation, pu.traversal);
  const KdTree t = build_kdtree_for_units(m.pos, m.tris, {}, p, KdObjective::kBusiestUnit);
  EXPECT_LT(kd_unit_loads(t).busiest(), pu.busiest());
  EXPECT_LT(t.stats.chosen_traversal_cost, 1000.0);
  EXPECT_TRUE(on_ladder(static_cast<float>(t.stats.chosen_traversal_cost), 1000.0f));
  // The stats' SAH cost stays at the configured costs, so trees of both objectives compare.
  EXPECT_DOUBLE_EQ(t.stats.sah_cost, compute_kdtree_stats(t, p).sah_cost);
}

// The guard: a tree whose plain traversal and transformation loads differ by less than the ratio
// keeps its plain tree; one whose loads differ by more is walked as without the guard.
TEST(TreeObjective, RatioGuardWalksOnlyOverloadedTrees) {
  const Mesh m = lattice(6);
  KdBuildParams p;
  p.traversal_cost = 2.0f;
  const KdTree plain = build_kdtree(m.pos, m.tris, {}, p);
  const KdUnitLoads pu = kd_unit_loads(plain);
  const double ratio = pu.traversal / pu.transformation;
  ASSERT_GT(ratio, 1.0);
  const KdTree kept =
      build_kdtree_for_units(m.pos, m.tris, {}, p, KdObjective::kBusiestUnit, ratio * 1.01);
  EXPECT_TRUE(same_tree(kept, plain));
  EXPECT_EQ(kept.stats.chosen_traversal_cost, 2.0);
  EXPECT_DOUBLE_EQ(kept.stats.expected_traversal_cycles, pu.traversal);
  const KdTree walked =
      build_kdtree_for_units(m.pos, m.tris, {}, p, KdObjective::kBusiestUnit, ratio * 0.99);
  const KdTree unguarded = build_kdtree_for_units(m.pos, m.tris, {}, p, KdObjective::kBusiestUnit);
  EXPECT_FALSE(same_tree(walked, plain));
  EXPECT_TRUE(same_tree(walked, unguarded));
  EXPECT_EQ(walked.stats.chosen_traversal_cost, unguarded.stats.chosen_traversal_cost);
}

TEST(TreeObjective, LadderIsGeometricAroundTheConfiguredCost) {
  const std::vector<float> l = kd_objective_ladder(30.0f);
  ASSERT_EQ(l.size(), 9u);
  EXPECT_FLOAT_EQ(l.front(), 7.5f);
  EXPECT_EQ(l[4], 30.0f);
  EXPECT_FLOAT_EQ(l.back(), 120.0f);
  EXPECT_TRUE(std::is_sorted(l.begin(), l.end()));
}

TEST(TreeObjective, KeyIsATreeSetting) {
  ImageParams p;
  EXPECT_EQ(p.tree_objective, 0);
  apply_tree_setting(p, "kd.objective=1");
  EXPECT_EQ(p.tree_objective, 1);
  EXPECT_THROW(apply_tree_setting(p, "kd.objective=2"), std::runtime_error);
  EXPECT_THROW(apply_tree_setting(p, "kd.objective=0.5"), std::runtime_error);
  EXPECT_EQ(p.tree_objective_ratio, 1.0f);
  apply_tree_setting(p, "kd.objective_ratio=2");
  EXPECT_EQ(p.tree_objective_ratio, 2.0f);
  EXPECT_THROW(apply_tree_setting(p, "kd.objective_ratio=0.5"), std::runtime_error);
}

}  // namespace
}  // namespace saarcor::host
