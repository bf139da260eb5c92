// The statistics of a finished tree (KdTreeStats): node and leaf counts, chain links, and the
// SAH-expected traversal steps, leaf visits and item tests per ray (surface-area probabilities
// relative to the root box), from which `saarcor scene` and the reports read a tree's quality.
#include <algorithm>

#include "host/kd_builder.h"

namespace saarcor::host {

KdTreeStats compute_kdtree_stats(const KdTree& tree, const KdBuildParams& params) {
  KdTreeStats st;
  st.build_seconds = tree.stats.build_seconds;
  st.node_cost = tree.stats.node_cost;
  st.nodes = static_cast<std::uint32_t>(tree.nodes.size());
  if (tree.nodes.empty()) return st;
  kd::Box root{};
  for (int k = 0; k < 3; ++k) {
    root.lo[k] = tree.bounds.empty() ? 0.0f : tree.bounds.lo[k];
    root.hi[k] = tree.bounds.empty() ? 0.0f : tree.bounds.hi[k];
  }
  const double root_area = kd::half_area(root);
  struct Item {
    std::uint32_t node;
    std::uint32_t depth;
    kd::Box box;
  };
  std::vector<Item> stack{{0, 0, root}};
  std::uint64_t listed = 0;
  double steps = 0.0;
  double leaf_visits = 0.0;
  double fetched = 0.0;
  double tests = 0.0;
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const KdTreeNode& nd = tree.nodes[it.node];
    // Probability that a ray through the root box also passes this node's box.
    const double pr = root_area > 0.0 ? kd::half_area(it.box) / root_area : 1.0;
    st.depth = std::max(st.depth, it.depth);
    if (nd.leaf) {
      ++st.leaves;
      if (nd.count == 0) ++st.empty_leaves;
      listed += nd.count;
      leaf_visits += pr;
      fetched += nd.count != 0 ? pr : 0.0;
      tests += pr * nd.count;
      continue;
    }
    steps += pr;
    const int link = kd::chain_link(tree.nodes, nd, nd.child, nd.child + 1);
    st.empty_chain_links += link != 0;
    st.mergeable_chain_links += link == 2;
    kd::Box l = it.box;
    kd::Box r = it.box;
    l.hi[nd.axis] = nd.split;
    r.lo[nd.axis] = nd.split;
    stack.push_back({nd.child + 1, it.depth + 1, r});
    stack.push_back({nd.child, it.depth + 1, l});
  }
  const std::uint32_t full = st.leaves - st.empty_leaves;
  st.items_per_leaf = full > 0 ? static_cast<double>(listed) / full : 0.0;
  st.expected_traversal_steps = steps;
  st.expected_leaf_visits = leaf_visits;
  st.expected_fetched_leaves = fetched;
  st.expected_item_tests = tests;
  st.sah_cost = params.traversal_cost * steps + params.intersection_cost * tests;
  return st;
}

}  // namespace saarcor::host
