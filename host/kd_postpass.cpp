// The pass after a build: chains of empty cuts (docs/kdtree.md "Chains of empty cuts") found and,
// under KdBuildParams::kChainsMerged, each mergeable link replaced by one cut.
#include <algorithm>

#include "host/kd_builder.h"

namespace saarcor::host {
namespace kd {

int chain_link(const std::vector<KdTreeNode>& nodes, const KdTreeNode& nd, std::uint32_t l,
               std::uint32_t r) {
  for (int empty_side = 0; empty_side < 2; ++empty_side) {
    if (!is_empty_leaf(nodes[empty_side == 0 ? l : r])) {
      continue;
    }
    const KdTreeNode& other = nodes[empty_side == 0 ? r : l];
    if (other.leaf) {
      continue;
    }
    const bool same_side = is_empty_leaf(nodes[other.child + empty_side]);
    if (!same_side && !is_empty_leaf(nodes[other.child + 1 - empty_side])) {
      continue;
    }
    return same_side && other.axis == nd.axis ? 2 : 1;
  }
  return 0;
}

}  // namespace kd

// KdBuildParams::kChainsMerged: rewrites the node array with every mergeable chain link replaced
// by one cut. An empty cut at s1 whose non-empty child cuts the same axis at s2 with its empty
// side towards s1 leaves the slab between the node's face and s2 empty, so the node cuts at s2
// instead (strictly inside its box, on the split grid: the child's plane), its children the
// first empty leaf and the child's non-empty child; repeated while the new child is such a cut.
// The array is written in the builder's order (a node's two children allocated together when it
// is reached, then its left subtree, then its right one), so a tree without mergeable links comes
// out unchanged; leaf lists are not moved.
void kd_merge_empty_chains(KdTree& tree) {
  using kd::chain_link;
  using kd::is_empty_leaf;
  const std::vector<KdTreeNode>& in = tree.nodes;
  // Most trees have no mergeable link (the builder puts an empty cut at the items' outermost
  // bound): one read-only pass over the array, no rewrite.
  const auto mergeable = [&](const KdTreeNode& nd) {
    return !nd.leaf && chain_link(in, nd, nd.child, nd.child + 1) == 2;
  };
  if (std::none_of(in.begin(), in.end(), mergeable)) {
    return;
  }
  std::vector<KdTreeNode> out;
  out.reserve(in.size());
  out.push_back(in[0]);
  struct Pending {
    std::uint32_t old_node;
    std::uint32_t new_node;
  };
  std::vector<Pending> stack{{0, 0}};
  while (!stack.empty()) {
    const Pending pd = stack.back();
    stack.pop_back();
    KdTreeNode nd = in[pd.old_node];
    if (nd.leaf) {
      out[pd.new_node] = nd;
      continue;
    }
    std::uint32_t l = nd.child;
    std::uint32_t r = nd.child + 1;
    while (chain_link(in, nd, l, r) == 2) {
      if (is_empty_leaf(in[l]) && !in[r].leaf && is_empty_leaf(in[in[r].child])) {
        nd.split = in[r].split;
        r = in[r].child + 1;
      } else {
        nd.split = in[l].split;
        l = in[l].child;
      }
    }
    nd.child = static_cast<std::uint32_t>(out.size());
    out[pd.new_node] = nd;
    out.emplace_back();
    out.emplace_back();
    stack.push_back({r, nd.child + 1});
    stack.push_back({l, nd.child});
  }
  tree.nodes = std::move(out);
}

}  // namespace saarcor::host
