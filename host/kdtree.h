// SAH kd-trees (Wald & Havran 2006, O(N log N) with perfect splits): one builder for the
// bottom-level trees over an object's triangles and the top-level tree over instance bounds
// (paper section 2: a top-level index over objects, rebuilt whenever an object moves).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <span>
#include <vector>

#include "fixedfloat/format.h"

namespace saarcor::host {

struct Aabb {
  glm::vec3 lo{std::numeric_limits<float>::infinity()};
  glm::vec3 hi{-std::numeric_limits<float>::infinity()};
  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  void grow(const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Aabb& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  float area() const {
    const glm::vec3 d = hi - lo;
    return empty() ? 0.0f : 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
  }
};

struct KdBuildParams {
  // Costs in the DynRTP's terms (docs/kdtree.md "Costs for this hardware"): a traversal step is a
  // traversal-unit cycle, a triangle test P + 1 transformation cycles on another unit running
  // in parallel. 30 : 20 balances the two units' SAH-expected loads on the room and keeps most
  // large meshes under 4 nodes per triangle (the node bound below keeps all; Wald & Havran's
  // software defaults were 15 : 20 with an empty-space bonus of 0.8, which made long chains of
  // empty cuts).
  float traversal_cost = 30.0f;
  float intersection_cost = 20.0f;
  float empty_bonus = 1.0f;  // cost factor for a split that cuts off empty space
  // Leaf steps (docs/kdtree.md "Costs for this hardware"): the traversal unit spends a step on
  // every node it fetches, a non-empty leaf as much as an inner node, while an empty child is
  // skipped in its parent (traversal.skip_empty) and costs none. With it a split pays K_T for
  // each non-empty child by the child's area share instead of K_T once.
  bool leaf_step = false;
  // Nodes at this depth are leaves (root = depth 0). kAutoDepth: 8 + 1.3 * floor(log2 N) for N
  // items (pbrt's and Mitsuba's rule), so a small object is not cut down to slivers and a large
  // one may go deeper. Per level; the image builder caps it so that top + bottom fit the
  // traversal stack (docs/kdtree.md "Depth and the stack").
  int max_depth = kAutoDepth;
  static constexpr int kAutoDepth = -1;
  int leaf_size = 0;  // never split a node with this many items or fewer (0: SAH decides)
  // Node bound (docs/kdtree.md "Node bound"): a tree over N items has at most
  // max(max_nodes_per_item * N, node_floor) nodes. A node is 2 words of scene memory and a
  // triangle's matrix 9, so 4 nodes per triangle keep a tree below the data it indexes; small
  // trees (the room's face slabs take 6 nodes per triangle) are never bound. Where a tree
  // is over, the builder adds a cost per node (by the node's share of the root's area, the
  // least cost that fits) and builds again. 0: no bound.
  float max_nodes_per_item = 4.0f;
  int node_floor = 16384;
  // Face slabs (docs/kdtree.md): planes a thin slab inside a node face that peel items lying in
  // the face (walls) off the interior, so rays crossing the face's leaves do not meet the wall's
  // triangles in each (the triangle mailbox only saves the repeats within one packet).
  bool face_slabs = true;
  // Chains of empty cuts (docs/kdtree.md "Chains of empty cuts"): a chain link is an empty
  // cut whose non-empty child is again an empty cut, one traversal step per link for every ray
  // crossing it (the empty children themselves are skipped, traversal.skip_empty).
  // kChainsAllowed: the SAH alone decides. kChainsMerged: a link whose two cuts lie on one axis
  // with the empty side on the same side is replaced by one cut at the inner plane (the two empty
  // slabs together are empty), the same leaves with one inner node and one empty leaf fewer.
  // kChainsForbidden: the non-empty child of an empty cut is split only by a plane with items on
  // both sides, or is a leaf. Merged by default: the builder's empty-space planes lie at the
  // items' outermost bounds, so no measured scene's tree has a mergeable link and the pass changes
  // none, but it guarantees the property; forbidding chains left the empty space inside the
  // leaves and cost 1-4 % more cycles per packet on every scene.
  enum EmptyChains : int { kChainsAllowed = 0, kChainsMerged = 1, kChainsForbidden = 2 };
  int empty_chains = kChainsMerged;
  // Hybrid build (docs/kdtree.md): a node with more than `binned_above` items is split by binned
  // SAH over its items' clipped bounds (`bins` bins per axis, plus the two empty-space planes at
  // the items' bounds); a subtree at or below it by Wald & Havran's exact event sweep. A huge
  // value gives the pure event builder.
  int binned_above = 0;
  int bins = 128;  // 2..256
  // Item bounds are rounded outward onto this format's values before any plane is chosen, so
  // every split is exactly representable and the tree is exact for the plane the hardware stores
  // (docs/memory-image.md: split position in fp24).
  ff::Format split_format = ff::kFp24;
};

struct KdTreeNode {
  bool leaf = false;
  std::uint8_t axis = 0;    // inner
  float split = 0.0f;       // inner: exactly representable in split_format
  std::uint32_t child = 0;  // inner: left child index; right child = child + 1
  std::uint32_t first = 0;  // leaf: first index into KdTree::items
  std::uint32_t count = 0;  // leaf: number of items
};

struct KdTreeStats {
  std::uint32_t nodes = 0;
  std::uint32_t leaves = 0;
  std::uint32_t empty_leaves = 0;
  // Chain links: inner nodes with an empty leaf as one child and, as the other, an inner node
  // that again has an empty-leaf child (each an inner step for the rays crossing it; the empty
  // children are skipped). Of those, the mergeable ones: both cuts on one axis with the empty
  // side on the same side, replaceable by one cut at the inner plane (KdBuildParams::empty_chains).
  std::uint32_t empty_chain_links = 0;
  std::uint32_t mergeable_chain_links = 0;
  std::uint32_t depth = 0;
  double items_per_leaf = 0.0;  // average over non-empty leaves
  double sah_cost = 0.0;
  // SAH-expected per ray (surface-area probabilities relative to the root box).
  double expected_traversal_steps = 0.0;
  double expected_leaf_visits = 0.0;
  // Of those, the non-empty leaves: with the inner nodes, the nodes the traversal unit fetches
  // (an empty child is skipped in its parent, traversal.skip_empty).
  double expected_fetched_leaves = 0.0;
  double expected_item_tests = 0.0;
  double build_seconds = 0.0;  // every build of the node bound's search included
  // The node bound's cost per node (in SAH cost units at the root), 0 when the first build fit.
  double node_cost = 0.0;
  // The busiest-unit objective's record (host/tree_objective.h; 0 where the tree did not go
  // through it): the K_T the tree was built with and its SAH-expected unit cycles per packet.
  double chosen_traversal_cost = 0.0;
  double expected_traversal_cycles = 0.0;
  double expected_list_cycles = 0.0;
  double expected_transformation_cycles = 0.0;
  double expected_intersection_cycles = 0.0;
};

struct KdTree {
  std::vector<KdTreeNode> nodes;     // node 0 is the root; children adjacent
  std::vector<std::uint32_t> items;  // leaf lists: triangle ids or instance indices
  Aabb bounds;
  KdTreeStats stats;
};

// Bottom level: triangles (positions indexed by tris) with skip[i] != 0 left out (degenerate).
KdTree build_kdtree(std::span<const glm::vec3> positions, std::span<const glm::uvec3> tris,
                    std::span<const std::uint8_t> skip, const KdBuildParams& params = {});
// Top level: boxes (instance world bounds); item i is box i. Empty boxes (lo > hi) are left out.
KdTree build_kdtree(std::span<const Aabb> boxes, const KdBuildParams& params = {});

// Additions (docs/kdtree.md). Both builders throw std::runtime_error on bad input: a non-finite
// coordinate, a coordinate outside split_format's range, an index beyond the positions, a skip
// list of the wrong length, more than 2^30 - 1 items, or invalid parameters.
//
// The statistics of a tree (what build_kdtree stores in KdTree::stats; build_seconds is copied).
KdTreeStats compute_kdtree_stats(const KdTree& tree, const KdBuildParams& params = {});
// Replaces every mergeable chain link (KdTreeStats::mergeable_chain_links) by one cut at the inner
// plane, as the builder does under KdBuildParams::kChainsMerged: the same non-empty leaves, one
// inner node and one empty leaf fewer per link, the node array in the builder's order (children
// adjacent, allocated depth first). Leaves tree.stats as they were.
void kd_merge_empty_chains(KdTree& tree);
// Directed rounding onto the split grid (the values representable in `f` with subnormals
// flushed): the builder rounds item bounds outward with these, so every candidate plane is a
// stored plane. KdTree::bounds is rounded outward the same way.
float kd_split_round_down(float v, const ff::Format& f);
// The automatic depth limit for `items` items: round(8 + 1.3 * floor(log2 items)), 8 for 0 or 1.
int kd_auto_max_depth(std::size_t items);
// The depth limit a build over `items` items uses: params.max_depth, or the automatic one.
int kd_max_depth(const KdBuildParams& params, std::size_t items);
float kd_split_round_up(float v, const ff::Format& f);

}  // namespace saarcor::host
