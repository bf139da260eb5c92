// SAH kd-tree builder: Wald & Havran, "On building fast kd-trees for ray tracing, and on doing
// that in O(N log N)" (2006), with perfect splits, below a binned-SAH stage (Wald 2007, Shevtsov
// et al. 2007) at the top. Builds the paper's (section 2) bottom-level trees over an object's
// triangles and the top-level tree over instance bounds; the node layout follows
// docs/memory-image.md (root at 0, children adjacent, split positions in fp24).
//
// How it works (docs/kdtree.md has the long form; host/kd_builder.h maps the files):
// - Item bounds are rounded outward onto the split grid (the values representable in
//   params.split_format): lower bounds down, upper bounds up. Every candidate plane is a grid
//   value, so it is a value the hardware can store, and the left/right counts are exact for it.
// - Binned stage (nodes with more than params.binned_above items; kd_binning.cpp): per node one
//   pass bins every item's bounds on all three axes; candidates are grid values at even spacing
//   plus the two empty-space planes at the items' bounds. One pass then writes the children's
//   item lists, clipping only the straddlers (perfect splits, kd_clip.cpp). When the bins find no
//   plane worth a split, the exact stage decides.
// - Exact stage (kd_sweep.cpp): every item yields, per axis, a start and an end event at its
//   bounds (a planar event when both coincide); the events are sorted once (64-bit keys:
//   position, type, local item id; kd_events.cpp). Per node, one linear sweep per axis finds the
//   SAH-best plane; the items are classified against it, the events split into the children's
//   lists in order (no re-sort), and only the straddlers get new events from their clipped
//   bounds (sorted, then merged in).
// - Memory: the binned stage's item lists and each axis's event list are stacks (a node's
//   children are written above it and popped when the subtree is done): no per-node allocation.
// This file: the parameters and the input checked, the items' bounds, the leaves, and the node
// bound's search around whole builds.
#include "host/kdtree.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "host/kd_builder.h"

namespace saarcor::host {
namespace kd {

const KdBuildParams& Builder::checked(const KdBuildParams& p) {
  const ff::Format& f = p.split_format;
  if (!f.valid()) throw std::runtime_error("kd-tree: invalid split format " + ff::format_name(f));
  if (!(p.traversal_cost >= 0.0f) || !(p.intersection_cost > 0.0f) ||
      !(p.empty_bonus > 0.0f && p.empty_bonus <= 1.0f))
    throw std::runtime_error(
        "kd-tree: cost parameters need traversal >= 0, intersection > 0, 0 < empty bonus <= 1");
  if ((p.max_depth < 0 && p.max_depth != KdBuildParams::kAutoDepth) || p.max_depth > 1000)
    throw std::runtime_error("kd-tree: max depth " + std::to_string(p.max_depth) +
                             " outside 0..1000 (or -1: automatic)");
  if (p.leaf_size < 0)
    throw std::runtime_error("kd-tree: negative leaf size " + std::to_string(p.leaf_size));
  if (p.binned_above < 0)
    throw std::runtime_error("kd-tree: negative binned-above threshold " +
                             std::to_string(p.binned_above));
  if (!(p.max_nodes_per_item >= 0.0f && p.max_nodes_per_item <= 1e6f) || p.node_floor < 0)
    throw std::runtime_error(
        "kd-tree: node bound needs 0 <= nodes per item <= 1e6 (0: no bound) and a floor >= 0");
  if (p.empty_chains < KdBuildParams::kChainsAllowed ||
      p.empty_chains > KdBuildParams::kChainsForbidden) {
    throw std::runtime_error("kd-tree: empty-chain rule " + std::to_string(p.empty_chains) +
                             " outside 0..2");
  }
  if (p.bins < 2 || p.bins > kMaxBins)
    throw std::runtime_error("kd-tree: bins " + std::to_string(p.bins) + " outside 2.." +
                             std::to_string(kMaxBins));
  return p;
}

void Builder::check_coordinate(float v, const char* what, std::size_t index) const {
  if (!std::isfinite(v))
    throw std::runtime_error(std::string("kd-tree: ") + what + " " + std::to_string(index) +
                             " has a non-finite coordinate");
  if (std::fabs(v) > grid_.max_finite())
    throw std::runtime_error(std::string("kd-tree: ") + what + " " + std::to_string(index) +
                             " has coordinate " + std::to_string(v) +
                             " outside the range of split format " +
                             ff::format_name(p_.split_format));
}

void Builder::start(std::size_t items) {
  if (items >= kMaxItems)
    throw std::runtime_error("kd-tree: " + std::to_string(items) + " items exceed the limit of " +
                             std::to_string(kMaxItems - 1));
  // Room for the root list and, stacked above it, the right lists along the recursion path
  // (left lists overwrite their parent's: about 1 + 1/2 + 1/4 + ... times the root's, plus
  // straddlers' duplicates). Untouched pages cost nothing; growing copies everything.
  items_.top_ = 0;
  items_.ensure(std::max<std::size_t>(64, items * 4));
  for (int k = 0; k < 3; ++k) {
    root_.lo[k] = std::numeric_limits<float>::infinity();
    root_.hi[k] = -std::numeric_limits<float>::infinity();
  }
}

void Builder::add_item(std::uint32_t id, const float lo[3], const float hi[3]) {
  float l[3];
  float h[3];
  for (int k = 0; k < 3; ++k) {
    l[k] = grid_.down(lo[k]);
    h[k] = grid_.up(hi[k]);
    root_.lo[k] = std::min(root_.lo[k], l[k]);
    root_.hi[k] = std::max(root_.hi[k], h[k]);
  }
  set_bin_item(items_.data()[items_.top_++], id, l, h);
  ++item_count_;
}

// Only the vertices of used triangles matter (and must be finite and storable). One comparison
// per coordinate in the common case (false for a NaN), the message otherwise.
void Builder::check_triangle(std::size_t i, const glm::uvec3& t) const {
  if (t.x >= positions_.size() || t.y >= positions_.size() || t.z >= positions_.size())
    throw std::runtime_error("kd-tree: triangle " + std::to_string(i) +
                             " indexes a vertex beyond the " + std::to_string(positions_.size()) +
                             " positions");
  const float lim = grid_.max_finite();
  for (const unsigned v : {t.x, t.y, t.z}) {
    const glm::vec3 a = glm::abs(positions_[v]);
    if (!(a.x <= lim && a.y <= lim && a.z <= lim))
      for (int k = 0; k < 3; ++k)
        check_coordinate(positions_[v][k], "vertex", v);
  }
}

void Builder::build_triangles(std::span<const glm::vec3> positions,
                              std::span<const glm::uvec3> tris,
                              std::span<const std::uint8_t> skip) {
  if (!skip.empty() && skip.size() != tris.size())
    throw std::runtime_error("kd-tree: skip list has " + std::to_string(skip.size()) +
                             " entries for " + std::to_string(tris.size()) + " triangles");
  positions_ = positions;
  tris_ = tris;
  triangles_ = true;
  start(tris.size());
  for (std::size_t i = 0; i < tris.size(); ++i) {
    if (!skip.empty() && skip[i] != 0) continue;
    const glm::uvec3 t = tris[i];
    check_triangle(i, t);
    const glm::vec3 lo = glm::min(glm::min(positions[t.x], positions[t.y]), positions[t.z]);
    const glm::vec3 hi = glm::max(glm::max(positions[t.x], positions[t.y]), positions[t.z]);
    const float l[3] = {lo.x, lo.y, lo.z};
    const float h[3] = {hi.x, hi.y, hi.z};
    add_item(static_cast<std::uint32_t>(i), l, h);
  }
  run();
}

void Builder::build_boxes(std::span<const Aabb> boxes) {
  boxes_ = boxes;
  triangles_ = false;
  start(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      // An empty box (inf, -inf) is allowed and left out; anything else must be finite.
      if (std::isnan(boxes[i].lo[k]) || std::isnan(boxes[i].hi[k]))
        throw std::runtime_error("kd-tree: box " + std::to_string(i) +
                                 " has a non-finite coordinate");
    }
    if (boxes[i].empty()) continue;
    for (int k = 0; k < 3; ++k) {
      check_coordinate(boxes[i].lo[k], "box", i);
      check_coordinate(boxes[i].hi[k], "box", i);
    }
    const float l[3] = {boxes[i].lo.x, boxes[i].lo.y, boxes[i].lo.z};
    const float h[3] = {boxes[i].hi.x, boxes[i].hi.y, boxes[i].hi.z};
    add_item(static_cast<std::uint32_t>(i), l, h);
  }
  run();
}

void Builder::run() {
  tree_.nodes.clear();
  tree_.items.clear();
  // Large meshes reach about 2.5 nodes per item: room for 3 saves a copy of the whole array.
  tree_.nodes.reserve(std::size_t{item_count_} * 3 + 1);
  tree_.items.reserve(std::size_t{item_count_} * 3);
  tree_.nodes.emplace_back();
  if (item_count_ == 0) {
    tree_.nodes[0].leaf = true;
    tree_.bounds = Aabb{};
    return;
  }
  tree_.bounds.lo = glm::vec3(root_.lo[0], root_.lo[1], root_.lo[2]);
  tree_.bounds.hi = glm::vec3(root_.hi[0], root_.hi[1], root_.hi[2]);
  const std::size_t n = items_.top_;
  p_.max_depth = kd_max_depth(p_, item_count_);
  root_half_area_ = half_area(root_);
  min_half_area_ = root_half_area_ * kMinAreaShare;
  bin_node(0, 0, root_, 0, static_cast<std::uint32_t>(n), false);
  if (p_.empty_chains == KdBuildParams::kChainsMerged) {
    kd_merge_empty_chains(tree_);
  }
}

// A leaf's list in ascending item id (deterministic; the hardware's tie rule may depend on it).
void Builder::emit_leaf(std::uint32_t node, std::vector<std::uint32_t>& ids) {
  // Lists taken from the binned stage are in id order already.
  if (!std::is_sorted(ids.begin(), ids.end())) {
    std::sort(ids.begin(), ids.end());
  }
  KdTreeNode& nd = tree_.nodes[node];
  nd.leaf = true;
  nd.first = static_cast<std::uint32_t>(tree_.items.size());
  nd.count = static_cast<std::uint32_t>(ids.size());
  tree_.items.insert(tree_.items.end(), ids.begin(), ids.end());
}

}  // namespace kd

namespace {

// The node bound's search (docs/kdtree.md "Node bound"): the least cost per node that fits,
// found by steps of kNodeCostGrowth from kFirstNodeCost times K_T (up while over the bound,
// down while within) and kNodeCostBisections geometric bisections of the bracket (within a
// factor 4^(2^-3) = 1.19 of the least). The first guess fits the 2CylinderEngine's and the
// arena's trees (5 and 4.2 nodes per triangle at no cost) in one or two steps.
constexpr double kFirstNodeCost = 0x1p-16;
constexpr double kNodeCostGrowth = 4.0;
constexpr int kMaxNodeCostSteps = 10;
constexpr int kNodeCostBisections = 3;

// The bracket of the node bound's search: the largest cost known to give too many nodes and the
// least known to fit (0: none yet); `tree` holds the tree of `within`, or the smallest so far.
struct NodeCostBracket {
  double over = 0.0;
  double within = 0.0;
};

// build_once(node_cost) builds one tree with that cost per node; fits(tree) says whether it is
// within the bound. Steps from the first guess until the bracket closes, then bisects it.
template <class BuildOnce, class Fits>
void search_node_cost(const KdBuildParams& params, KdTree& tree, BuildOnce& build_once,
                      const Fits& fits) {
  const double unit =
      params.traversal_cost > 0.0f ? params.traversal_cost : params.intersection_cost;
  NodeCostBracket br;
  double c = unit * kFirstNodeCost;
  for (int i = 0; i < kMaxNodeCostSteps && (br.over == 0.0 || br.within == 0.0); ++i) {
    KdTree t = build_once(c);
    if (fits(t)) {
      br.within = c;
      tree = std::move(t);
      c /= kNodeCostGrowth;
    } else {
      br.over = c;
      if (br.within == 0.0) tree = std::move(t);  // the smallest so far, if none fits
      c *= kNodeCostGrowth;
    }
  }
  for (int i = 0; i < kNodeCostBisections && br.over > 0.0 && br.within > 0.0; ++i) {
    const double mid = std::sqrt(br.over * br.within);
    KdTree t = build_once(mid);
    if (fits(t)) {
      tree = std::move(t);
      br.within = mid;
    } else {
      br.over = mid;
    }
  }
}

template <class BuildOnce>
KdTree build_bounded(const KdBuildParams& params, std::size_t items, BuildOnce build_once) {
  const auto t0 = std::chrono::steady_clock::now();
  KdTree tree = build_once(0.0);
  const double budget = std::max(static_cast<double>(params.max_nodes_per_item) * items,
                                 static_cast<double>(params.node_floor));
  auto fits = [&](const KdTree& t) { return static_cast<double>(t.nodes.size()) <= budget; };
  if (params.max_nodes_per_item > 0.0f && !fits(tree)) {
    search_node_cost(params, tree, build_once, fits);
  }
  tree.stats = compute_kdtree_stats(tree, params);
  tree.stats.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return tree;
}

std::size_t used_items(std::size_t n, std::span<const std::uint8_t> skip) {
  if (skip.size() != n) return n;  // the builder refuses a skip list of the wrong length
  return n - static_cast<std::size_t>(
                 std::count_if(skip.begin(), skip.end(), [](std::uint8_t v) { return v != 0; }));
}

}  // namespace

float kd_split_round_down(float v, const ff::Format& f) {
  return kd::SplitGrid(f).down(v);
}
float kd_split_round_up(float v, const ff::Format& f) {
  return kd::SplitGrid(f).up(v);
}

KdTree build_kdtree(std::span<const glm::vec3> positions, std::span<const glm::uvec3> tris,
                    std::span<const std::uint8_t> skip, const KdBuildParams& params) {
  const std::size_t items = skip.empty() ? tris.size() : used_items(tris.size(), skip);
  return build_bounded(params, items, [&](double node_cost) {
    KdTree tree;
    kd::Builder(params, tree, node_cost).build_triangles(positions, tris, skip);
    tree.stats.node_cost = node_cost;
    return tree;
  });
}

KdTree build_kdtree(std::span<const Aabb> boxes, const KdBuildParams& params) {
  const auto items = static_cast<std::size_t>(
      std::count_if(boxes.begin(), boxes.end(), [](const Aabb& b) { return !b.empty(); }));
  return build_bounded(params, items, [&](double node_cost) {
    KdTree tree;
    kd::Builder(params, tree, node_cost).build_boxes(boxes);
    tree.stats.node_cost = node_cost;
    return tree;
  });
}

int kd_auto_max_depth(std::size_t items) {
  int log2 = 0;
  while (items > 1) {
    items >>= 1;
    ++log2;
  }
  return static_cast<int>(std::lround(8.0 + 1.3 * log2));
}

int kd_max_depth(const KdBuildParams& params, std::size_t items) {
  return params.max_depth == KdBuildParams::kAutoDepth ? kd_auto_max_depth(items)
                                                       : params.max_depth;
}

}  // namespace saarcor::host
