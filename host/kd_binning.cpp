// The binned-SAH stage at the top of the tree (Wald 2007; for kd-trees Shevtsov et al. 2007),
// with exact counts on the split grid: per node the items' bounds are binned on all three axes
// (kd_bin_simd.cpp), the bin planes and the two empty-space planes weighed, and the children's
// item lists written in one pass. Nodes at or below params.binned_above items, and nodes whose
// bins find no plane worth a split, go to the exact stage (kd_sweep.cpp).
//
// Per axis, a grid value x falls into bin f(x) = trunc(clamp((x - lo) * bins / extent, 0,
// bins - 1)), monotone in x. Candidate plane j is the smallest grid value s_j with f(s_j) > j,
// so for every grid value x: x < s_j <=> f(x) <= j. An item is left of s_j iff lo < s_j, i.e.
// f(lo) <= j; it is no longer right of s_j iff key < s_j (BinItem), i.e. f(key) <= j (planars at
// a candidate count right). The counts are therefore exact for the stored plane s_j, with two
// bin lookups per item and axis and no correction. A bin spans at least 4 grid steps, so s_j
// lies within a quarter bin of the even position, which is used for the areas; only the
// winner's s_j is searched. The two empty-space planes at the items' lowest and highest bounds
// are evaluated besides.
#include <algorithm>

#include "host/kd_builder.h"

namespace saarcor::host::kd {

// Fewer bins for smaller nodes: the per-node cost is proportional to the bins, the per-item cost
// is not; the top of the tree, which decides the most, gets the most. On each axis a bin spans at
// least 4 grid steps (finer candidates would collapse onto the same grid values).
BinGrid Builder::bin_grid(const Box& box, const std::array<double, 3>& d, std::uint32_t n) const {
  BinGrid g{};
  const int nb_node = std::clamp(static_cast<int>(n), std::min(32, p_.bins), p_.bins);
  for (int k = 0; k < 3; ++k) {
    const double mag = std::max(std::fabs(static_cast<double>(box.lo[k])),
                                std::fabs(static_cast<double>(box.hi[k])));
    const double grid_step = std::max(mag * step_rel_, min_normal_);
    g.nb[k] =
        static_cast<int>(std::clamp(d[k] / (4.0 * grid_step), 2.0, static_cast<double>(nb_node)));
    g.base[k] = box.lo[k];
    // Flat: all in bin 0. Any finite scale keeps f monotone (and free of 0 * inf).
    g.scale[k] = d[k] > 0.0 ? static_cast<float>(std::min(g.nb[k] / d[k], 0x1p127)) : 0.0f;
    g.top[k] = static_cast<float>(g.nb[k] - 1);
  }
  g.nb_max = std::max({g.nb[0], g.nb[1], g.nb[2]});
  return g;
}

// s_j (see above): the smallest binary32 value y with f(y) > j, found by bisection on the
// order-preserving integers (f can be flat over many values where x - lo absorbs x), then rounded
// up onto the grid: grid values >= y reach bin j + 1, smaller ones do not. Usually the even
// position is y already. +inf when not even the box's upper bound reaches the bin.
float Builder::bin_threshold(const Box& box, const std::array<double, 3>& d, const BinGrid& g,
                             int k, int j) const {
  const auto want = static_cast<float>(j + 1);
  auto reaches = [&](std::uint32_t o) {
    return std::min(std::max((unordered(o) - g.base[k]) * g.scale[k], 0.0f), g.top[k]) >= want;
  };
  std::uint32_t below = ordered(box.lo[k]);  // f(lo) = 0
  std::uint32_t at = ordered(box.hi[k]);
  if (!reaches(at)) return std::numeric_limits<float>::infinity();
  const std::uint32_t guess = ordered(
      std::clamp(static_cast<float>(box.lo[k] + d[k] * (j + 1) / g.nb[k]), box.lo[k], box.hi[k]));
  if (guess > below && guess < at) {
    if (reaches(guess)) {
      at = guess;
      if (!reaches(guess - 1)) below = guess - 1;
    } else {
      below = guess;
      if (reaches(guess + 1)) at = guess + 1;
    }
  }
  while (at - below > 1) {
    const std::uint32_t mid = below + (at - below) / 2;
    (reaches(mid) ? at : below) = mid;
  }
  return grid_.up(unordered(at));
}

// Per axis the swept bin plane and the two empty-space planes weighed against `best`; returns
// the winner's bin index when the winner is a bin plane (its counts and s_j are still to be
// found), else -1.
int Builder::best_binned_plane(const Box& box, const std::array<double, 3>& d, const BinSweep& sw,
                               const float tlo[3], const float tkey[3], std::uint32_t n,
                               bool no_empty, BinnedSplit& best) const {
  const double inv_area = 1.0 / half_area(d);
  const double kt = node_kt(half_area(d));
  const double ki = p_.intersection_cost;
  int bin_j = -1;
  for (int k = 0; k < 3; ++k) {
    if (!(d[k] > 0.0)) continue;
    const double sum = d[(k + 1) % 3] + d[(k + 2) % 3];
    const double prod = d[(k + 1) % 3] * d[(k + 2) % 3];
    const double lo = box.lo[k];
    const double hi = box.hi[k];
    auto cost_at = [&](double x, std::uint32_t nl, std::uint32_t nr) {
      const double al = (x - lo) * sum + prod;
      const double ar = (hi - x) * sum + prod;
      return plane_cost(kt, al, ar, nl, nr, inv_area);
    };
    if (sw.best_j[k] >= 0) {
      // Both children hold items and their half areas add up to d * sum + 2 * prod on every
      // plane of this axis: the leaf steps add the same amount to each (BinScan's order holds).
      const double c = p_.leaf_step
                           ? inv_area * (ki * sw.best_m[k] + kt * (d[k] * sum + 2.0 * prod))
                           : kt + ki * inv_area * sw.best_m[k];
      if (c < best.cost) {
        best = BinnedSplit{c, k, 0.0f, false, 0, 0};  // counts summed once the winner is known
        bin_j = sw.best_j[k];                         // and s_j searched
      }
    }
    // Empty-space planes at the items' bounds (all items on one side, planars with them):
    // the lowest lower bound, and the grid value above the highest key (the highest upper
    // bound, or one grid step beyond it when that is a planar item's).
    if (!no_empty && tlo[k] > box.lo[k] && tlo[k] < box.hi[k]) {
      const double c = cost_at(tlo[k], 0, n);
      if (c < best.cost) {
        best = BinnedSplit{c, k, tlo[k], false, 0, n};
        bin_j = -1;
      }
    }
    const float thi = grid_succ(tkey[k]);
    if (!no_empty && thi < box.hi[k] && thi > box.lo[k]) {
      const double c = cost_at(thi, n, 0);
      if (c < best.cost) {
        best = BinnedSplit{c, k, thi, true, n, 0};
        bin_j = -1;
      }
    }
  }
  return bin_j;
}

BinnedSplit Builder::find_binned_split(const Box& box, const BinItem* items, std::uint32_t n,
                                       bool no_empty) const {
  BinnedSplit best;
  const std::array<double, 3> d = extents(box);
  const double area = half_area(d);
  if (!(area > 0.0)) return best;
  const BinGrid g = bin_grid(box, d, n);
  alignas(16) BinHist hist_lo;
  alignas(16) BinHist hist_hi;
  float tlo[3];
  float tkey[3];
  fill_bins(g, items, n, hist_lo, hist_hi, tlo, tkey);
  // Per axis the first least bin plane (BinScan), all three axes swept together.
  BinSweep sw;
  for (int k = 0; k < 3; ++k) {
    if (!(d[k] > 0.0)) continue;  // flat: no planes (the lane stays at its defaults)
    const double sum = d[(k + 1) % 3] + d[(k + 2) % 3];
    const double prod = d[(k + 1) % 3] * d[(k + 2) % 3];
    sw.nc[k] = g.nb[k] - 1;
    sw.da[k] = d[k] / g.nb[k] * sum;
    sw.al[k] = prod;
    sw.ar[k] = d[k] * sum + prod;
  }
  sweep_bins(hist_lo, hist_hi, g.nb_max, n, sw);
  const int bin_j = best_binned_plane(box, d, sw, tlo, tkey, n, no_empty, best);
  if (bin_j >= 0) {
    const int k = best.axis;
    std::uint32_t not_right = 0;
    for (int j = 0; j <= bin_j; ++j) {
      best.left += hist_lo[j][k];
      not_right += hist_hi[j][k];
    }
    best.right = n - not_right;
    best.pos = bin_threshold(box, d, g, k, bin_j);
    // Only a box a few grid steps wide can leave no grid value strictly inside.
    if (!(best.pos > box.lo[k] && best.pos < box.hi[k])) return BinnedSplit{};
  }
  return best;
}

// The nodes the bins do not split: the empty side of an empty-space plane, a node small enough
// for the exact stage, and a node that must be a leaf. Returns false when the bins decide.
bool Builder::bin_node_is_leaf(std::uint32_t node, int depth, const Box& box, std::size_t b,
                               std::uint32_t n, bool no_empty) {
  if (n == 0) {  // the empty side of an empty-space plane: a leaf under every rule
    leaf_scratch_.clear();
    emit_leaf(node, leaf_scratch_);
    return true;
  }
  if (n <= static_cast<std::uint32_t>(p_.binned_above)) {
    exact_subtree(node, depth, box, b, n, no_empty);
    return true;
  }
  if (must_be_leaf(n, depth, box)) {
    leaf_scratch_.clear();
    for (std::uint32_t i = 0; i < n; ++i)
      leaf_scratch_.push_back(items_.data()[b + i].id);
    emit_leaf(node, leaf_scratch_);
    return true;
  }
  return false;
}

// One pass: classify (as the exact stage does) and write the children's lists, whose sizes the
// binning counted (clipping may only drop pieces). The left list overwrites the node's (from b)
// in place (each item read yields at most one left item, so writing never overtakes reading);
// the right one goes on top of the stack (from rb). nl, nr: the lists' lengths.
void Builder::partition_binned(const Box& box, const BinnedSplit& best, std::size_t b,
                               std::uint32_t n, std::size_t rb, std::uint32_t& nl,
                               std::uint32_t& nr) {
  const int k = best.axis;
  const float split = best.pos;
  const std::size_t lb = b;
  items_.ensure(rb + best.right + 1);  // + 1: the slot the branch-free write below may fill
  BinItem* all = items_.data();
  const std::uint8_t planar_side = best.planar_left ? kLeft : kRight;
  // The cursors in locals (written back at the end): the items written in the loop may alias
  // what a reference names.
  std::uint32_t l = 0;
  std::uint32_t r = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    // The split axis's fields read from the list, not from the copy: indexed by k, the copy
    // would be kept on the stack and read back.
    const float lo = all[b + i].lo[k];
    const float key = all[b + i].key[k];
    const bool planar = (all[b + i].planar >> k) & 1u;
    const BinItem it = all[b + i];  // a copy: the left list may overwrite its slot
    const bool at_plane = planar & (lo == split);
    const bool left = at_plane ? planar_side == kLeft : key < split;
    const bool right = at_plane ? planar_side == kRight : lo >= split;
    if (left || right) {
      // Written to both lists, kept by the cursor of its side: which side is unpredictable,
      // so no branch on it (the right slot written for a left item is above the stack top, the
      // left one for a right item at or below the slot just read).
      all[lb + l] = it;
      all[rb + r] = it;
      l += left;
      r += right;
      continue;
    }
    // Perfect split of a straddler, with the exact stage's rules.
    Pieces pc = straddler_pieces(it.id, box, k, split);
    if (pc.in_left) set_clipped_bin_item(all[lb + l++], it.id, pc.llo, pc.lhi);
    if (pc.in_right) set_clipped_bin_item(all[rb + r++], it.id, pc.rlo, pc.rhi);
  }
  nl = l;
  nr = r;
}

void Builder::bin_node(std::uint32_t node, int depth, const Box& box, std::size_t b,
                       std::uint32_t n, bool no_empty) {
  if (bin_node_is_leaf(node, depth, box, b, n, no_empty)) return;
  const BinnedSplit best = find_binned_split(box, items_.data() + b, n, no_empty);
  if (best.axis < 0 || !(best.cost < static_cast<double>(p_.intersection_cost) * n)) {
    // The bins found nothing worth it: the exact sweep decides (leaf or a plane between bins).
    exact_subtree(node, depth, box, b, n, no_empty);
    return;
  }
  const int k = best.axis;
  const float split = best.pos;
  Box lbox;
  Box rbox;
  split_box(box, k, split, lbox, rbox);
  const std::size_t entry_top = items_.top_;
  const std::size_t rb = entry_top;
  std::uint32_t nl = 0;
  std::uint32_t nr = 0;
  partition_binned(box, best, b, n, rb, nl, nr);

  const std::uint32_t child = make_inner(node, k, split);
  const std::size_t top = rb + nr;
  items_.top_ = top;
  const bool no_empty_below = forbid_empty_below(nl, nr);
  bin_node(child, depth + 1, lbox, b, nl, no_empty_below);
  items_.top_ = top;
  bin_node(child + 1, depth + 1, rbox, rb, nr, no_empty_below);
  items_.top_ = entry_top;
}

}  // namespace saarcor::host::kd
