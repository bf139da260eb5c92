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
  // Wald & Havran's cost model defaults.
  float traversal_cost = 15.0f;
  float intersection_cost = 20.0f;
  float empty_bonus = 0.8f;  // cost factor for a split that cuts off empty space
  int max_depth = 24;        // per level; top + bottom must fit the 64-entry traversal stack
  int leaf_size = 0;         // never split a node with this many items or fewer (0: SAH decides)
  // Hybrid build (docs/kdtree.md): a node with more than `binned_above` items is split by binned
  // SAH over its items' clipped bounds (`bins` bins per axis, plus the two empty-space planes at
  // the items' bounds); a subtree at or below it by Wald & Havran's exact event sweep. A huge
  // value gives the pure event builder.
  int binned_above = 0;
  int bins = 128;  // 2..256
  // Item bounds are rounded outward onto this format's values before any plane is chosen, so
  // every split is exactly representable and the tree is exact for the plane the hardware stores
  // (DESIGN.md section 4: split position in fp24).
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
  std::uint32_t depth = 0;
  double items_per_leaf = 0.0;  // average over non-empty leaves
  double sah_cost = 0.0;
  // SAH-expected per ray (surface-area probabilities relative to the root box).
  double expected_traversal_steps = 0.0;
  double expected_leaf_visits = 0.0;
  double expected_item_tests = 0.0;
  double build_seconds = 0.0;
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
// Directed rounding onto the split grid (the values representable in `f` with subnormals
// flushed): the builder rounds item bounds outward with these, so every candidate plane is a
// stored plane. KdTree::bounds is rounded outward the same way.
float kd_split_round_down(float v, const ff::Format& f);
float kd_split_round_up(float v, const ff::Format& f);

}  // namespace saarcor::host
