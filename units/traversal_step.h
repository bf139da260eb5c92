// The traversal unit's semantics (paper section 3.1; Figure 2 paths b and f; docs/cycle-model.md;
// decisions D26, D27, D29, D33): the clip of a packet against the scene box or an object's box,
// the sign groups, one kd-node step per request (early termination at node entry, near and far
// child, the push of the far child), the stack shared by both levels with its drops at the pop,
// and the end of a level. Its timing (node fetch, chain rule, pipeline depth: fp add + div + cmp)
// is units/traversal.cpp; its exact-cycle test units/unit_timing_test.cpp (UnitTimingTraversal.*).
// The arithmetic of a clip and of an inner node's lanes is the datapath policy D's (clip_box,
// decide: units/fast_datapath.h, units/reference_datapath.h).
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "units/packet.h"

namespace saarcor::units {

template <class F, int kLanes, class D>
class TraversalStep {
 public:
  using State = PacketState<F, kLanes, D>;
  using LaneSlots = Slots<kLanes>;

  TraversalStep(const memif::MemoryImage& image, const FunctionalParams& params, int slots) {
    stack_node_.resize(static_cast<std::size_t>(params.stack_depth));
    stack_mask_.resize(static_cast<std::size_t>(params.stack_depth));
    stack_t_.resize(static_cast<std::size_t>(params.stack_depth) * 2u *
                    static_cast<std::size_t>(slots));
    const auto& regs = image.registers();
    for (int i = 0; i < 3; ++i) {
      scene_lo_[i] = F::from_bits(regs.scene_min[i]);
      scene_hi_[i] = F::from_bits(regs.scene_max[i]);
    }
  }

  // What a request names: the clip face, the kd-node and the rays concerned.
  Level level() const { return level_; }
  int clip_face() const { return clip_face_; }
  std::uint64_t clip_mask() const { return clip_mask_; }
  std::uint32_t node() const { return node_; }
  std::uint64_t mask() const { return mask_; }

  // A generated packet's rays enter the top level (path b).
  void issue(State& t) {
    for (int i = 0; i < t.p; ++i)
      if (t.lane(i).valid) ++t.sink.rays_issued[static_cast<int>(t.kind)];
    start_level(t, Level::kTop);
  }

  // The transformation unit has moved the entry's rays into the object (path d): the top level's
  // groups and stack base are saved, its stack entries stay below (D26), the bottom level starts.
  void enter_object(State& t) {
    top_groups_ = groups_;
    top_n_groups_ = n_groups_;
    top_group_ = group_;
    top_stack_base_ = stack_base_;
    start_level(t, Level::kBottom);
  }

  // One clip step: clip_faces_per_step faces of the box for every ray; the last one forms the
  // sign groups and starts the first.
  void clip(State& t) {
    ++t.u.clip_steps;
    const auto lanes = static_cast<std::uint64_t>(t.p);
    // The faces this step divides for: clip_faces_per_step of the sequence (all six, or the
    // three exit faces), fewer in the last step.
    const int left = (6 - clip_face_ + clip_stride_ - 1) / clip_stride_;
    const auto faces = static_cast<std::uint64_t>(std::min(left, t.params.clip_faces_per_step));
    const bool first = clip_face_ == clip_stride_ - 1;
    const bool last = faces == static_cast<std::uint64_t>(left);
    // Per lane and face 1 add, 1 div, 1 cmp; the last face 1 more cmp (the empty-segment test).
    // With exit faces only, 2 more cmp per lane in the first step (origin against the box).
    const std::uint64_t cmp =
        faces * lanes + (last ? lanes : 0) + (clip_stride_ == 2 && first ? 2 * lanes : 0);
    PipelineUnits<F>::count(t.u.traversal_ops, faces * lanes, 0, faces * lanes, cmp);
    // The face steps only change the lanes' clipped segments, which nothing reads before the
    // last face; so the first step computes all six (per lane in face order, the same results:
    // a skipped entry face leaves tn at 0) and saves the other passes over the packet.
    if (first) clip_box(t);
    clip_face_ += clip_stride_ * static_cast<int>(faces);
    if (last) form_groups(t);
  }

  // One kd-node step of the packet (path b, or f after a leaf's list).
  void step(State& t) {
    ++t.u.traversal_steps;
    PipelineUnits<F>::count(t.u.traversal_ops, 0, 0, 0, static_cast<std::uint64_t>(t.p));
    const memif::KdNode node = t.scene.node(node_);
    // Early termination at node entry (1 cmp per lane): t_best < tn leaves.
    std::uint64_t terminated = 0;
    for (int i = 0; i < t.p; i += 2) {
      const auto s = static_cast<std::size_t>(i);
      terminated |= mask2(load2(&t.v.t_best[s]) < load2(&t.v.tn[s])) << i;
    }
    std::uint64_t active = mask_ & ~terminated;
    if (t.kind == RayKind::kShadow) active &= ~t.done_mask();
    for (int i = 0; i < t.p; ++i)
      t.traversal_steps[static_cast<std::size_t>(i)] += (active >> i) & 1u;
    if (active == 0) return pop(t);
    if (node.leaf) return leaf(t, node, active);
    inner(t, node, active);
  }

  // The pop engine's cycles of the request executed last (0: it did not end in a pop).
  std::uint16_t pop_cycles() const { return pop_cycles_; }
  void clear_pop_cycles() { pop_cycles_ = 0; }

  // Pops the next node of the current group, or ends the group: a request of its own after a
  // list (Phase::kPop), or the end of a node step that leaves no child. The stack is a memory
  // read one entry per cycle (the pop engine, units/traversal.cpp): pop_cycles() says how many
  // entries this pop read, the dropped ones and the one that decided.
  void pop(State& t) {
    pop_cycles_ = 1;
    // Entries whose rays have all finished (any-hit) are dropped without a node fetch.
    if (t.kind == RayKind::kShadow) {
      const std::uint64_t done = t.done_mask();
      while (stack_size_ > stack_base_ && (stack_mask_[stack_size_ - 1] & ~done) == 0) {
        --stack_size_;
        ++pop_cycles_;
      }
    }
    // Early termination at the pop (paper section 3.1): the entry holds each ray's tn, so the
    // node-entry test (t_best < tn) runs on the stack's values before any node fetch, and an
    // entry whose rays have all terminated is dropped without a traversal step. The same lanes
    // terminate as at node entry, so every result is unchanged; what is saved is one node fetch
    // and one traversal slot per entry left behind a hit.
    while (stack_size_ > stack_base_ && entry_terminated(t, stack_size_ - 1)) {
      --stack_size_;
      ++t.u.stack_drops;
      ++pop_cycles_;
    }
    // The compare of the entry popped below is its node-entry test, counted with its step.
    if (stack_size_ == stack_base_) return finish_group(t);
    --stack_size_;
    node_ = stack_node_[stack_size_];
    mask_ = stack_mask_[stack_size_];
    // Every slot: lanes outside the entry's mask are not read until set again (LaneValues).
    const auto n = static_cast<std::size_t>(t.slots);
    const double* ts = &stack_t_[stack_size_ * 2u * n];
    t.copy_slots(t.v.tn.data(), ts);
    t.copy_slots(t.v.tf.data(), ts + n);
    t.phase = Phase::kTraverse;
  }

 private:
  // O and 1/D of the current level's rays.
  const std::array<LaneSlots, 3>& level_o(const State& t) const {
    return level_ == Level::kTop ? t.v.world_o : t.v.o;
  }
  const std::array<LaneSlots, 3>& level_inv(const State& t) const {
    return level_ == Level::kTop ? t.v.world_inv : t.v.inv;
  }

  // ---- levels, clipping and sign groups (D27, D29) --------------------------------------------
  void start_level(State& t, Level level) {
    level_ = level;
    clip_face_ = 0;
    // The box the clip steps read: the scene box, or rows 4-5 of the instance record.
    if (level == Level::kTop) {
      box_lo_ = scene_lo_;
      box_hi_ = scene_hi_;
      clip_mask_ = 0;
      for (int i = 0; i < t.p; ++i)
        if (t.lane(i).valid && !t.lane(i).done) clip_mask_ |= std::uint64_t{1} << i;
      for (int i = 0; i < t.p; ++i)
        t.lane(i).current = t.lane(i).world;
      t.phase = Phase::kClipTop;
    } else {
      const auto rlo = t.row(t.list.instance_row() + 4);
      const auto rhi = t.row(t.list.instance_row() + 5);
      box_lo_ = {rlo[0], rlo[1], rlo[2]};
      box_hi_ = {rhi[0], rhi[1], rhi[2]};
      clip_mask_ = t.list.entry_mask();
      t.phase = Phase::kClipBottom;
    }
    for (int i = 0; i < t.slots; ++i) {
      t.v.clip_tn[static_cast<std::size_t>(i)] = 0.0;
      t.v.clip_tf[static_cast<std::size_t>(i)] = t.v.t_best[static_cast<std::size_t>(i)];
    }
    // Faces in the order x entry, x exit, y entry, ...: the exit faces alone (odd faces) when every
    // ray starts inside the box (the comparators decide it with the first step).
    clip_stride_ = t.params.clip_exit_only && origins_inside_box(t) ? 2 : 1;
    clip_face_ = clip_stride_ - 1;
    ++t.u.clips;
    t.u.exit_only_clips += clip_stride_ == 2 ? 1 : 0;
  }

  // True when every ray of the clip mask has its origin in the level's box (closed): its entry
  // distances are then <= 0 (or NaN, which keeps the bound) and leave tn at 0.
  bool origins_inside_box(const State& t) const {
    for (std::uint64_t m = clip_mask_; m != 0; m &= m - 1) {
      const Lane<F>& l = t.lanes[static_cast<std::size_t>(std::countr_zero(m))];
      for (std::size_t k = 0; k < 3; ++k) {
        const double o = t.value(l.current.o[k]);
        if (!(o >= t.value(box_lo_[k]) && o <= t.value(box_hi_[k]))) return false;
      }
    }
    return true;
  }

  // Last face: a ray misses the box when its segment is empty (1 cmp per lane). Sign groups: rays
  // with equal direction signs share one front-to-back order (D27). Groups in increasing
  // sign-pattern order; each is a masked sub-packet traversed to the end.
  void form_groups(State& t) {
    std::array<std::uint64_t, 8> by_pattern{};
    for (int i = 0; i < t.p; ++i) {
      const Lane<F>& l = t.lane(i);
      const auto k = static_cast<std::size_t>(i);
      if (!lane_in(clip_mask_, i) || t.v.clip_tf[k] < t.v.clip_tn[k]) continue;
      const int s = (l.current.d[0].sign() ? 1 : 0) | (l.current.d[1].sign() ? 2 : 0) |
                    (l.current.d[2].sign() ? 4 : 0);
      by_pattern[static_cast<std::size_t>(s)] |= std::uint64_t{1} << i;
    }
    n_groups_ = 0;
    for (const std::uint64_t g : by_pattern)
      if (g != 0) groups_[n_groups_++] = g;
    if (n_groups_ > 1) t.u.sub_packets += n_groups_ - 1;
    group_ = 0;
    stack_base_ = stack_size_;
    if (n_groups_ == 0) return finish_level(t);
    start_group(t);
  }

  // The slab clip of the level's box (D29), faces 0..5: x entry, x exit, y entry, ...
  void clip_box(State& t) {
    D::clip_box(t, clip_mask_, box_lo_, box_hi_, level_o(t), level_inv(t));
  }

  void start_group(State& t) {
    const std::uint64_t g = groups_[group_];
    // The other lanes' tn, tf are not read while they are outside the mask (LaneValues).
    t.copy_slots(t.v.tn.data(), t.v.clip_tn.data());
    t.copy_slots(t.v.tf.data(), t.v.clip_tf.data());
    node_ = level_ == Level::kTop ? t.image.registers().top_root : t.list.header().root;
    mask_ = g;
    // Groups of a level live on the stack one after another: a level keeps its base.
    t.phase = Phase::kTraverse;
  }

  // ---- one kd-node step -----------------------------------------------------------------------
  // A leaf hands its list to the list unit (path c); an empty one ends the step.
  void leaf(State& t, const memif::KdNode& node, std::uint64_t active) {
    if (node.count == 0) {
      ++t.u.empty_leaf_steps;
      return pop(t);
    }
    for (std::uint32_t k = 0; k < node.count && k < 8u; ++k)
      t.scene.prefetch_list(node.first + k);
    t.list.start(level_, node.first, node.first + node.count, active);
    t.phase = Phase::kList;
  }

  using Decision = TraversalDecision<kLanes>;

  void inner(State& t, const memif::KdNode& node, std::uint64_t active) {
    ++t.u.inner_steps;
    // Host-side prefetch of both children's node words (one of them is the next step's node,
    // the other may be pushed): no effect on results.
    t.scene.prefetch_node(node.child_pair);
    t.scene.prefetch_node(node.child_pair + 1);
    const auto lanes = static_cast<std::uint64_t>(t.p);
    PipelineUnits<F>::count(t.u.traversal_ops, lanes, 0, lanes, 2 * lanes);  // traversal_lane
    const int axis = static_cast<int>(node.axis);
    const F split = F::from_bits(node.split);
    Decision d;
    decide(t, axis, split, active, d);
    if (t.u.tap != nullptr) [[unlikely]]
      tap_step(t, axis, split, active, d);
    // The group's shared direction sign on this axis picks the near child.
    const bool neg = t.lane(std::countr_zero(active)).current.d[axis].sign();
    descend(t, node, neg, d);
  }

  // traversal_lane for every active lane (D::decide).
  void decide(State& t, int axis, F split, std::uint64_t active, Decision& d) {
    D::decide(t, axis, split, active, level_o(t), level_inv(t), d);
  }

  void tap_step(State& t, int axis, F split, std::uint64_t active, const Decision& d) {
    for (std::uint64_t m = active; m != 0; m &= m - 1) {
      const int i = std::countr_zero(m);
      const auto s = static_cast<std::size_t>(i);
      const Lane<F>& l = t.lane(i);
      t.u.tap->traversal(i, split, l.current.o[axis], l.current.d[axis], t.encoding(t.v.tn[s]),
                         t.encoding(t.v.tf[s]), lane_in(d.near_mask, i), lane_in(d.far_mask, i),
                         t.encoding(d.near_tf[s]), t.encoding(d.far_tn[s]));
    }
  }

  // The near child next, the far child pushed when both are visited; an empty child (flagged in
  // the node, memif::KdNode) is dropped here: its lanes are done with it (same results, no step).
  void descend(State& t, const memif::KdNode& node, bool neg, Decision& d) {
    const std::uint32_t near_child = neg ? node.child_pair + 1 : node.child_pair;
    const std::uint32_t far_child = neg ? node.child_pair : node.child_pair + 1;
    const bool skip_near = t.params.skip_empty && (neg ? node.empty_right : node.empty_left);
    const bool skip_far = t.params.skip_empty && (neg ? node.empty_left : node.empty_right);
    if (skip_near) d.near_mask = 0;
    if (skip_far) d.far_mask = 0;
    if (d.far_mask != 0 && d.near_mask != 0) {
      push(t, far_child, d.far_mask, d.far_tn);
      // Lanes outside near_mask leave the mask: their tf is not read (LaneValues).
      t.copy_slots(t.v.tf.data(), d.near_tf.data());
      node_ = near_child;
      mask_ = d.near_mask;
    } else if (d.near_mask != 0) {
      // A skipped far child: the near segment ends at the plane, as when both are visited.
      if (skip_far) t.copy_slots(t.v.tf.data(), d.near_tf.data());
      node_ = near_child;
      mask_ = d.near_mask;
    } else if (d.far_mask != 0) {
      if (skip_near) t.copy_slots(t.v.tn.data(), d.far_tn.data());
      node_ = far_child;
      mask_ = d.far_mask;
    } else {
      pop(t);
    }
  }

  // ---- the stack (D26: one stack for both levels) ---------------------------------------------
  // Stack entry: node, mask, and per slot the far segment's tn, then per slot tf.
  void push(State& t, std::uint32_t node, std::uint64_t mask, const LaneSlots& far_tn) {
    if (stack_size_ >= stack_node_.size())
      throw std::runtime_error("functional model: traversal stack overflow (depth " +
                               std::to_string(t.params.stack_depth) +
                               "); the kd-trees are deeper than the stack");
    stack_node_[stack_size_] = node;
    stack_mask_[stack_size_] = mask;
    const auto n = static_cast<std::size_t>(t.slots);
    double* ts = &stack_t_[stack_size_ * 2u * n];
    t.copy_slots(ts, far_tn.data());
    t.copy_slots(ts + n, t.v.tf.data());
    ++stack_size_;
  }

  // True when every lane of stack entry e has its closest hit before the entry's tn.
  // 1 cmp per lane, counted with the drop (the stack's comparators, not a traversal step).
  bool entry_terminated(State& t, std::size_t e) {
    const double* tn = &stack_t_[e * 2u * static_cast<std::size_t>(t.slots)];
    for (std::uint64_t m = stack_mask_[e]; m != 0; m &= m - 1) {
      const auto k = static_cast<std::size_t>(std::countr_zero(m));
      if (!(t.v.t_best[k] < tn[k])) return false;
    }
    PipelineUnits<F>::count(t.u.traversal_ops, 0, 0, 0, static_cast<std::uint64_t>(t.p));
    return true;
  }

  void finish_group(State& t) {
    if (++group_ < n_groups_) return start_group(t);
    finish_level(t);
  }

  // The bottom level ends back at the top level's list (path f); the top level hands the packet
  // to the RGS (path g).
  void finish_level(State& t) {
    if (level_ == Level::kBottom) {
      level_ = Level::kTop;
      groups_ = top_groups_;
      n_groups_ = top_n_groups_;
      group_ = top_group_;
      stack_base_ = top_stack_base_;
      for (int i = 0; i < t.p; ++i)
        t.lane(i).current = t.lane(i).world;
      return t.list.return_to_list(t);
    }
    t.phase = t.kind == RayKind::kShadow ? Phase::kShadeShadow : Phase::kShadeSurface;
    for (int i = 0; i < t.p; ++i)
      if (t.lane(i).valid) ++t.sink.rays_returned[static_cast<int>(t.kind)];
  }

  std::array<F, 3> scene_lo_{}, scene_hi_{};
  std::array<F, 3> box_lo_{}, box_hi_{};  // the current level's box (clip steps)
  Level level_ = Level::kTop;
  int clip_face_ = 0;
  int clip_stride_ = 1;  // 2: exit faces only (every origin inside the box)
  std::uint64_t clip_mask_ = 0;
  std::array<std::uint64_t, 8> groups_{}, top_groups_{};
  std::size_t n_groups_ = 0, top_n_groups_ = 0, group_ = 0, top_group_ = 0;
  std::size_t stack_base_ = 0, top_stack_base_ = 0;
  std::uint32_t node_ = 0;
  std::uint64_t mask_ = 0;
  std::vector<std::uint32_t> stack_node_;
  std::vector<std::uint64_t> stack_mask_;
  std::vector<double> stack_t_;  // per entry: far tn per slot, then tf per slot (values)
  std::size_t stack_size_ = 0;   // entries in use (the vectors are allocated once)
  std::uint16_t pop_cycles_ = 0;
};

}  // namespace saarcor::units
