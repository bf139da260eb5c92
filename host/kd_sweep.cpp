// The exact stage (Wald & Havran 2006, O(N log N)): a subtree's events sorted once, then per
// node one linear sweep per axis for the SAH-best plane (and the face slabs), the items
// classified against it, the straddlers clipped (kd_clip.cpp) and the event lists split for the
// children in order (kd_events.cpp), down to the leaves.
#include <algorithm>

#include "host/kd_builder.h"

namespace saarcor::host::kd {

// The exact stage for a subtree: events from the items' bounds (already on the grid), with
// local ids 0..n-1 so that the per-item side bytes stay in cache, sorted once.
void Builder::exact_subtree(std::uint32_t node, int depth, const Box& box, std::size_t b,
                            std::uint32_t n, bool no_empty) {
  gid_.resize(n);
  if (side_.size() < n) side_.resize(n);
  const BinItem* items = items_.data() + b;
  std::size_t eb[3];
  std::size_t ee[3];
  for (int k = 0; k < 3; ++k) {
    Arena& a = ev_[k];
    // Room for the subtree's list (up to 2 events per item) and the lists stacked above it
    // along the recursion path: 12 per item.
    a.top_ = 0;
    a.ensure(std::max<std::size_t>(64, std::size_t{n} * 12));
    Key* out = a.data();
    std::size_t m = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      const float lo = items[i].lo[k];
      const float hi = item_hi(items[i], k);
      if (lo == hi) {
        out[m++] = make_key(ordered(lo), kPlanar, i);
      } else {
        out[m++] = make_key(ordered(lo), kStart, i);
        out[m++] = make_key(ordered(hi), kEnd, i);
      }
    }
    radix_sort(out, m, sort_scratch_);
    a.top_ = m;
    eb[k] = 0;
    ee[k] = m;
  }
  for (std::uint32_t i = 0; i < n; ++i)
    gid_[i] = items[i].id;
  exact_root_ = node;
  build_node(node, depth, box, eb, ee, n, no_empty);
}

// A candidate where one side may be empty: both planar placements with the bonus, exactly.
// (The plain SAH's products in this order, as the sweep has always rounded them.)
void Builder::weigh_empty_side(int k, std::uint32_t pos, double al, double ar, std::uint32_t nl,
                               std::uint32_t nr, std::uint32_t np, const SweepCosts& c,
                               bool no_empty, Split& best, double& best_m) const {
  const double bonus = p_.empty_bonus;
  const std::uint32_t nl1 = nl + np;
  const std::uint32_t nr2 = nr + np;
  auto exact = [&](std::uint32_t l, std::uint32_t r) {
    if (p_.leaf_step) return leaf_step_cost(c.kt, al, ar, l, r, c.inv_area);
    return (l == 0 || r == 0 ? bonus : 1.0) *
           (c.kt + c.ki * (al * c.inv_area * l + ar * c.inv_area * r));
  };
  // Under no_empty a placement that leaves a side empty is no candidate.
  const double inf = std::numeric_limits<double>::infinity();
  const double c1 = no_empty && (nl1 == 0 || nr == 0) ? inf : exact(nl1, nr);
  const double c2 = no_empty && (nl == 0 || nr2 == 0) ? inf : exact(nl, nr2);
  if (c1 < best.cost || c2 < best.cost) {
    best = c1 <= c2 ? Split{c1, k, pos, true} : Split{c2, k, pos, false};
    best_m = (best.cost - c.kt0) / c.scale;
  }
}

// One axis's sweep over its sorted events. Per candidate, without the constant factors:
// m = aL*nL + aR*nR + nP*min(aL, aR) (the planars go to the cheaper side), with aL, aR the
// children's half areas. The full cost kt + ki * m / area is compared only when m beats the best
// so far; the empty-space bonus (possible only where one side is empty) takes the exact path.
void Builder::sweep_axis(const Box& box, int k, const std::array<double, 3>& d, std::size_t b,
                         std::size_t e, std::uint32_t n, const SweepCosts& c, bool no_empty,
                         Split& best) const {
  const double sum = d[(k + 1) % 3] + d[(k + 2) % 3];
  const double prod = d[(k + 1) % 3] * d[(k + 2) % 3];
  const double lo = box.lo[k];
  const double hi = box.hi[k];
  const std::uint32_t lo_o = ordered(box.lo[k]);
  const std::uint32_t hi_o = ordered(box.hi[k]);
  double best_m = std::isinf(best.cost) ? std::numeric_limits<double>::infinity()
                                        : (best.cost - c.kt0) / c.scale;
  const Key* ev = ev_[k].data();
  std::uint32_t nl = 0;
  std::uint32_t nr = n;
  std::uint32_t np = 0;       // planars at the current position
  std::uint32_t pending = 0;  // starts and planars at the current position (left after it)
  for (std::size_t i = b; i < e; ++i) {
    const Key key = ev[i];
    const std::uint32_t t = key_type(key);
    nr -= t != kStart;
    np += t == kPlanar;
    pending += t != kEnd;
    const std::uint32_t pos = key_pos(key);
    // Evaluate at the last event of a position: then nl holds the items entirely before it,
    // nr those entirely after it, np those in it.
    if (i + 1 < e && key_pos(ev[i + 1]) == pos) continue;
    if (pos > lo_o && pos < hi_o) {
      const double x = unordered(pos);
      const double al = (x - lo) * sum + prod;
      const double ar = (hi - x) * sum + prod;
      const double m = al * nl + ar * nr + np * std::min(al, ar);
      if (nl == 0 || nr == 0) {
        weigh_empty_side(k, pos, al, ar, nl, nr, np, c, no_empty, best, best_m);
      } else if (const double ms = m + c.step * (al + ar); ms < best_m) {
        best_m = ms;
        best = Split{c.kt0 + c.scale * ms, k, pos, al <= ar};
      }
    }
    nl += pending;
    pending = 0;
    np = 0;
  }
}

Split Builder::find_split(const Box& box, const std::size_t b[3], const std::size_t e[3],
                          std::uint32_t n, bool no_empty) const {
  Split best;
  const std::array<double, 3> d = extents(box);
  const double area = half_area(d);
  if (!(area > 0.0)) return best;  // a line or a point: no plane can separate anything
  const double inv_area = 1.0 / area;
  const double kt = node_kt(area);
  const double ki = p_.intersection_cost;
  // With leaf steps the cost is scale * (m + step * (aL + aR)) (both sides hold items here)
  // and has no constant term.
  const SweepCosts c{
      kt, ki, inv_area, ki * inv_area, p_.leaf_step ? kt / ki : 0.0, p_.leaf_step ? 0.0 : kt};
  Split face;  // the best face slab (Builder::face_slabs)
  for (int k = 0; k < 3; ++k) {
    if (!(d[k] > 0.0)) continue;
    sweep_axis(box, k, d, b[k], e[k], n, c, no_empty, best);
    if (p_.face_slabs) {
      const double sum = d[(k + 1) % 3] + d[(k + 2) % 3];
      const double prod = d[(k + 1) % 3] * d[(k + 2) % 3];
      face_slabs(box, k, sum, prod, b[k], e[k], n, kt, inv_area, no_empty, face);
    }
  }
  // A face slab wins when it is cheaper, and also when no other plane beats the leaf but the slab
  // lies within the slack (build_node applies the slack to it).
  const double leaf_cost = ki * n;
  if (face.cost < best.cost || (!(best.cost < leaf_cost) && face.cost < leaf_cost * kFaceSlabSlack))
    return face;
  return best;
}

// Items lying in a face of the node's box (a room's walls, floor and ceiling) are in every leaf
// along that face, and no event plane can separate them: their events sit on the box bound.
// Every ray crossing such a leaf then tests them (no triangle mailbox, paper 3.1). A plane a
// slab's width inside the face does: the thin slab holds the face's items and is entered only by
// rays near the face. The width is a fixed share of the root extent so that the traversal's
// rounded plane distances (about 2^-15 of the distance, fp24) cannot skip the slab.
// sum, prod: the sum and product of the box's two other extents (the sweep's per-axis constants).
void Builder::face_slabs(const Box& box, int k, double sum, double prod, std::size_t b,
                         std::size_t e, std::uint32_t n, double kt, double inv_area, bool no_empty,
                         Split& best) const {
  const double width = (static_cast<double>(root_.hi[k]) - root_.lo[k]) * kFaceSlabShare;
  const float lo = box.lo[k];
  const float hi = box.hi[k];
  if (!(static_cast<double>(hi) - lo > 4.0 * width) || !(width > 0.0)) return;
  const Key* ev = ev_[k].data();
  auto evaluate = [&](float x, std::uint32_t nl, std::uint32_t nr) {
    const double al = (static_cast<double>(x) - lo) * sum + prod;
    const double ar = (static_cast<double>(hi) - x) * sum + prod;
    // The interior side is empty where every item lies in the face.
    if (no_empty && (nl == 0 || nr == 0)) {
      return;
    }
    const double cost = plane_cost(kt, al, ar, nl, nr, inv_area);
    if (cost < best.cost) best = Split{cost, k, ordered(x), true, true};
  };
  // Near the low face: left = items with lo < x, right = items with hi > x.
  const float x_lo = grid_.up(static_cast<float>(lo + width));
  // Planars at x go left (planar_left), so they count left and not right.
  // A slab thinner than a grid step rounds onto the face itself: no plane.
  if (e > b && x_lo > lo && x_lo < hi && key_pos(ev[b]) == ordered(lo) &&
      key_type(ev[b]) == kPlanar) {
    std::uint32_t nl = 0;
    std::uint32_t ended = 0;
    const std::uint32_t xo = ordered(x_lo);
    for (std::size_t i = b; i < e && key_pos(ev[i]) <= xo; ++i) {
      const std::uint32_t t = key_type(ev[i]);
      nl += t == kPlanar || (t == kStart && key_pos(ev[i]) < xo);
      ended += t != kStart;
    }
    evaluate(x_lo, nl, n - ended);
  }
  // Near the high face: left = items with lo < x, right = items with hi > x.
  const float x_hi = grid_.down(static_cast<float>(hi - width));
  if (e > b && x_hi < hi && x_hi > lo && key_pos(ev[e - 1]) == ordered(hi) &&
      key_type(ev[e - 1]) == kPlanar) {
    std::uint32_t started = 0;  // items with lo >= x
    std::uint32_t nr = 0;
    const std::uint32_t xo = ordered(x_hi);
    for (std::size_t i = e; i-- > b && key_pos(ev[i]) >= xo;) {
      const std::uint32_t t = key_type(ev[i]);
      started += t == kStart || (t == kPlanar && key_pos(ev[i]) > xo);
      nr += t != kStart && key_pos(ev[i]) > xo;
    }
    evaluate(x_hi, n - started, nr);
  }
}

void Builder::make_leaf(std::uint32_t node, std::size_t b0, std::size_t e0) {
  leaf_scratch_.clear();
  if (node == exact_root_) {
    // The exact subtree's root holds every local id, whose item ids ascend (gid_, from the
    // binned list, which keeps the root's id order): most hand-overs end here as a leaf.
    leaf_scratch_.assign(gid_.begin(), gid_.end());
    emit_leaf(node, leaf_scratch_);
    return;
  }
  // Every item has exactly one start or planar event per axis.
  const Key* ev = ev_[0].data();
  for (std::size_t i = b0; i < e0; ++i)
    if (key_type(ev[i]) != kEnd) leaf_scratch_.push_back(gid_[key_id(ev[i])]);
  emit_leaf(node, leaf_scratch_);
}

// Classify against the stored plane s (the grid value itself) from axis k's events: ends at or
// before it are left, starts at or after it right, planars at it go to the SAH's side, the rest
// straddle (into both_). Branch-free: a start writes right or straddling, the end then marks left
// if it ends at or before the plane; each item is counted at its last event (end or planar).
void Builder::classify(int k, std::size_t b, std::size_t e, std::uint32_t s, bool planar_left,
                       std::uint32_t& n_left, std::uint32_t& n_right) {
  std::uint8_t* side = side_.data();
  const Key* ev = ev_[k].data();
  const std::uint8_t planar_side = planar_left ? kLeft : kRight;
  both_.resize(e - b);
  std::uint32_t* both = both_.data();
  std::size_t nb = 0;
  // Counted in locals: the side bytes written in the loop may alias anything a reference names.
  std::uint32_t nl = n_left;
  std::uint32_t nr = n_right;
  for (std::size_t i = b; i < e; ++i) {
    const Key key = ev[i];
    const std::uint32_t id = key_id(key);
    const std::uint32_t pos = key_pos(key);
    const std::uint32_t t = key_type(key);
    const std::uint8_t cur = side[id];
    const std::uint8_t v_start = pos >= s ? kRight : kBoth;
    const std::uint8_t v_end = cur | (pos <= s ? kLeft : 0);
    const std::uint8_t v_planar = pos < s ? kLeft : pos > s ? kRight : planar_side;
    const std::uint8_t v = t == kStart ? v_start : t == kEnd ? v_end : v_planar;
    side[id] = v;
    const bool last = t != kStart;
    nl += last & (v == kLeft);
    nr += last & (v == kRight);
    both[nb] = id;
    nb += last & (v == kBoth);
  }
  n_left = nl;
  n_right = nr;
  both_.resize(nb);
}

// Perfect splits: straddlers get new events from their bounds clipped to each child (not at the
// last level, whose children are leaves at once), and are counted on each side they keep a piece.
void Builder::clip_straddlers(const Box& box, int k, float split, bool last_level,
                              std::uint32_t& n_left, std::uint32_t& n_right) {
  for (int j = 0; j < 3; ++j) {
    new_left_[j].clear();
    new_right_[j].clear();
  }
  both_left_.clear();
  both_right_.clear();
  for (const std::uint32_t id : both_) {
    const Pieces pc = straddler_pieces(gid_[id], box, k, split);
    if (pc.in_left) {
      if (!last_level) add_clipped(id, pc.llo, pc.lhi, new_left_);
      both_left_.push_back(gid_[id]);
      ++n_left;
    }
    if (pc.in_right) {
      if (!last_level) add_clipped(id, pc.rlo, pc.rhi, new_right_);
      both_right_.push_back(gid_[id]);
      ++n_right;
    }
  }
}

// Both children are leaves: their lists come straight from the classification (one entry per
// item: its start or planar event on the split axis k), no event lists are split.
void Builder::emit_child_leaves(std::uint32_t child, int k, std::size_t b, std::size_t e) {
  const std::uint8_t* side = side_.data();
  leaf_scratch_.clear();
  right_scratch_.clear();
  const Key* ev = ev_[k].data();
  for (std::size_t i = b; i < e; ++i) {
    const Key key = ev[i];
    if (key_type(key) == kEnd) continue;
    const std::uint32_t id = key_id(key);
    if (side[id] == kLeft) leaf_scratch_.push_back(gid_[id]);
    if (side[id] == kRight) right_scratch_.push_back(gid_[id]);
  }
  leaf_scratch_.insert(leaf_scratch_.end(), both_left_.begin(), both_left_.end());
  right_scratch_.insert(right_scratch_.end(), both_right_.begin(), both_right_.end());
  emit_leaf(child, leaf_scratch_);
  emit_leaf(child + 1, right_scratch_);
}

// Every axis's event list split into the children's, on top of the axis's stack: [lb, le) and
// [rb, re). left_only, right_only: the items on one side only.
void Builder::split_event_lists(const std::size_t b[3], const std::size_t e[3],
                                std::uint32_t left_only, std::uint32_t right_only,
                                std::size_t lb[3], std::size_t le[3], std::size_t rb[3],
                                std::size_t re[3]) {
  for (int j = 0; j < 3; ++j) {
    std::sort(new_left_[j].begin(), new_left_[j].end());
    std::sort(new_right_[j].begin(), new_right_[j].end());
    const std::size_t m = e[j] - b[j];
    Arena& a = ev_[j];
    // Bounds for the children's lists: the parent's minus at least one event per item of the
    // other side, plus the new ones, plus one slot that the branch-free filter may write past
    // the last kept event.
    const std::size_t cap_left = m - right_only + new_left_[j].size() + 1;
    const std::size_t cap_right = m - left_only + new_right_[j].size() + 1;
    a.ensure(a.top_ + cap_left + cap_right);
    Key* base = a.data();
    lb[j] = a.top_;
    rb[j] = a.top_ + cap_left;
    std::size_t rn = 0;
    const std::size_t ln = split_events(base + b[j], m, side_.data(), new_left_[j], new_right_[j],
                                        base + lb[j], base + rb[j], &rn);
    le[j] = lb[j] + ln;
    re[j] = rb[j] + rn;
    a.top_ = re[j];
  }
}

void Builder::build_node(std::uint32_t node, int depth, const Box& box, const std::size_t b[3],
                         const std::size_t e[3], std::uint32_t n, bool no_empty) {
  if (must_be_leaf(n, depth, box)) {
    make_leaf(node, b[0], e[0]);
    return;
  }
  const Split best = find_split(box, b, e, n, no_empty);
  const double leaf_cost = static_cast<double>(p_.intersection_cost) * n;
  if (best.axis < 0 || !(best.cost < leaf_cost * (best.face_slab ? kFaceSlabSlack : 1.0))) {
    make_leaf(node, b[0], e[0]);
    return;
  }
  const int k = best.axis;
  const float split = unordered(best.pos);
  std::uint32_t n_left = 0;
  std::uint32_t n_right = 0;
  classify(k, b[k], e[k], best.pos, best.planar_left, n_left, n_right);
  // Items on one side only (each has at least one event per axis on that side alone).
  const std::uint32_t left_only = n_left;
  const std::uint32_t right_only = n_right;
  const bool last_level = depth + 1 >= p_.max_depth;
  clip_straddlers(box, k, split, last_level, n_left, n_right);
  const std::uint32_t child = make_inner(node, k, split);
  const auto leaf_size = static_cast<std::uint32_t>(p_.leaf_size);
  if (last_level || (n_left <= leaf_size && n_right <= leaf_size)) {
    emit_child_leaves(child, k, b[k], e[k]);
    return;
  }
  std::size_t lb[3];
  std::size_t le[3];
  std::size_t rb[3];
  std::size_t re[3];
  split_event_lists(b, e, left_only, right_only, lb, le, rb, re);
  Box lbox;
  Box rbox;
  split_box(box, k, split, lbox, rbox);
  std::size_t saved_top[3];
  for (int j = 0; j < 3; ++j)
    saved_top[j] = ev_[j].top_;
  const bool no_empty_below = forbid_empty_below(n_left, n_right);
  build_node(child, depth + 1, lbox, lb, le, n_left, no_empty_below);
  for (int j = 0; j < 3; ++j)
    ev_[j].top_ = saved_top[j];
  build_node(child + 1, depth + 1, rbox, rb, re, n_right, no_empty_below);
  for (int j = 0; j < 3; ++j)
    ev_[j].top_ = lb[j];
}

}  // namespace saarcor::host::kd
