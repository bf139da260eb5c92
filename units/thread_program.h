// One DynRTP thread as the units see it (paper section 3.1, Figure 2, paths a-g;
// docs/cycle-model.md and docs/functional-model.md): a packet of P rays whose control flow is an
// explicit state machine, the "thread program". `request()` says which unit the thread needs next
// and what for (the request table); `execute()` hands the thread to that unit's semantics
// (units/*_step.h), which does the unit's work on the packet and moves it to the next phase. The
// functional model runs a thread to completion; the cycle model queues the thread at the requested
// unit and calls execute() when the unit serves it. Both run the same code in the same per-thread
// order, so their results are bit-identical by construction.
//
//   phase                unit            semantics                     path
//   generate             transformation  TransformationStep::generate  a
//   clip_top/bottom      traversal       TraversalStep::clip           b
//   traverse             traversal       TraversalStep::step           b, f
//   list                 list            ListStep::step                c
//   transform_object     transformation  TransformationStep::object    d
//   transform_triangle   transformation  TransformationStep::triangle  d
//   intersect            intersection    IntersectionStep::step        e
//   pop                  traversal       TraversalStep::pop            f, list -> traversal
//   shade_*              RGS             RgsStep::shade_*              g
#pragma once

#include <cstdint>
#include <vector>

#include "units/packet_state.h"
#include "units/program_types.h"

namespace saarcor::units {

// kLanes: the capacity of the packet arrays (>= P). A packet's per-lane values are kept field by
// field over kLanes slots, so a small capacity keeps a small packet's values in a few cache lines:
// the cycle model interleaves 64 programs, whose state has mostly left the L1 cache by the time a
// unit serves the thread again (P = 4 in 4 slots instead of 64: ~4% of a cycle-model frame).
// D: the datapath policy, chosen at compile time (units/fast_datapath.h: FastDatapath, what the
// models run; units/reference_datapath.h: ReferenceDatapath, every step on encodings, built in its
// own target). Both give the same results bit for bit (testbench/reference_datapath_test.cpp).
template <class F, int kLanes, class D>
class ThreadProgram {
 public:
  ThreadProgram(const memif::MemoryImage& image, const FunctionalParams& params,
                PipelineUnits<F>& units, FrameSink& sink)
      : s_(image, params, units, sink) {}

  // The RGC hands the thread the primary packet of pixels `pixel[i]` (memif::kNone = empty lane).
  void start_primary(const std::vector<std::uint32_t>& pixel) { s_.rgs.start_primary(s_, pixel); }

  bool done() const { return s_.phase == Phase::kDone; }
  Phase phase() const { return s_.phase; }
  RayKind kind() const { return s_.kind; }
  int packet_width() const { return s_.p; }
  // The packet's state as the units hold it (read by the boundary record, units/boundary_list.h).
  const PacketState<F, kLanes, D>& state() const { return s_; }
  // The memory accesses of the RGS request executed last (RgsStep::memory()).
  const std::vector<RgsAccess>& rgs_memory() const { return s_.rgs.memory(); }

  // What the thread asks of its next unit: the item to fetch and the pipeline slots it takes.
  Request request() const {
    Request r;
    r.phase = s_.phase;
    r.unit = phase_unit(s_.phase);
    r.steps = 1;
    r.pop_cycles = s_.traversal.pop_cycles();
    switch (s_.phase) {
      case Phase::kGenerate:
        r.mask = s_.valid_mask();
        r.steps = s_.transformation.steps(s_);
        break;
      case Phase::kClipTop:
      case Phase::kClipBottom:
        r.item = static_cast<std::uint32_t>(s_.traversal.clip_face());
        r.mask = s_.traversal.clip_mask();
        break;
      case Phase::kTraverse:
        r.item = s_.traversal.node();
        r.mask = s_.traversal.mask();
        break;
      case Phase::kList:
        // A list the thread comes back to after an object may be done: nothing to read.
        r.item =
            s_.list.done(s_.traversal.level()) ? memif::kNone : s_.list.next(s_.traversal.level());
        r.mask = s_.list.mask(s_.traversal.level());
        break;
      case Phase::kPop:
        r.mask = s_.traversal.mask();
        break;
      case Phase::kTransformObject:
        r.item = s_.list.instance_row();
        r.mask = s_.list.entry_mask();
        r.steps = s_.transformation.steps(s_);
        break;
      case Phase::kTransformTriangle:
        r.item = s_.list.header().triangle_row_base + memif::kTriangleRows * s_.list.triangle();
        r.mask = s_.list.entry_mask();
        r.steps = s_.transformation.steps(s_);
        break;
      case Phase::kIntersect:
        r.mask = s_.list.entry_mask();
        r.steps = s_.p;
        break;
      case Phase::kShadeSurface:
      case Phase::kShadeLight:
      case Phase::kShadeShadow:
        r.mask = s_.valid_mask();
        break;
      case Phase::kDone:
        r.steps = 0;
        break;
    }
    return r;
  }

  // Performs the requested unit's work and advances the program.
  void execute() {
    s_.traversal.clear_pop_cycles();
    switch (s_.phase) {
      case Phase::kGenerate:
        return s_.transformation.generate(s_);
      case Phase::kClipTop:
      case Phase::kClipBottom:
        return s_.traversal.clip(s_);
      case Phase::kTraverse:
        return s_.traversal.step(s_);
      case Phase::kList:
        return s_.list.step(s_);
      case Phase::kTransformObject:
        return s_.transformation.object(s_);
      case Phase::kTransformTriangle:
        return s_.transformation.triangle(s_);
      case Phase::kIntersect:
        return s_.intersection.step(s_);
      case Phase::kPop:
        ++s_.u.pop_steps;
        return s_.traversal.pop(s_);
      case Phase::kShadeSurface:
        s_.rgs.begin_request();
        return s_.rgs.shade_surface(s_);
      case Phase::kShadeLight:
        s_.rgs.begin_request();
        return s_.rgs.shade_light(s_);
      case Phase::kShadeShadow:
        s_.rgs.begin_request();
        return s_.rgs.shade_shadow(s_);
      case Phase::kDone:
        return;
    }
  }

  // Runs to completion (the functional model). Returns the number of requests served.
  std::uint64_t run() {
    std::uint64_t n = 0;
    while (s_.phase != Phase::kDone) {
      // Runs of traversal steps without the dispatch (the same steps as execute()).
      if (s_.phase == Phase::kTraverse) {
        do {
          s_.traversal.step(s_);
          ++n;
        } while (s_.phase == Phase::kTraverse);
        continue;
      }
      execute();
      ++n;
    }
    return n;
  }

 private:
  PacketState<F, kLanes, D> s_;
};

}  // namespace saarcor::units
