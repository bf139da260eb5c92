// Test-only: the RTL traversal unit (rtl/traversal_ctrl.sv) beside the model's traversal
// semantics (units/traversal_step.h), packet by packet on a real memory image. The model's own
// units are the mock neighbours: its list, transformation and intersection steps run the packet
// between traversal requests, and what they hand the traversal unit goes onto the RTL's ports
// (the world rays and t_best on path b, the object rays and box for a bottom level, the hit
// update after each intersection, a pop when a leaf's list ends: docs/hw-interface.md; a level
// start with its rays and a hit update take one cycle, all lanes at once). Every
// traversal request is issued to the RTL and to the model; the thread's next request (unit,
// node, mask, list start), the lanes' segments and the cycle it leaves are compared, and the run
// stops at the first difference with a one-line report.
#pragma once

#include <cstdint>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "fixedfloat/float.h"
#include "memif/image_format.h"
#include "rtl/port_bits.h"
#include "units/fast_datapath.h"
#include "units/packet_state.h"
#include "units/reference_datapath.h"
#include "verilated.h"

namespace saarcor::rtl::testing {

using F = ff::fp24;
inline constexpr int kLanes = 4;     // P of the default build
inline constexpr int kThreads = 64;  // THREADS of every traversal_ctrl build
using State = units::PacketState<F, kLanes, units::FastDatapath>;

// The first difference between the RTL and the model.
struct TravDivergence {
  bool found = false;
  std::uint64_t request = 0;  // traversal requests compared before it
  std::uint64_t cycle = 0;    // the RTL cycle of the wrong (or missing) event
  std::string kind;           // "payload", "timing" or "missing"
  std::string what;           // field, model value, RTL value
};

struct TravRun {
  std::uint64_t packets = 0;
  std::uint64_t requests = 0;  // traversal requests compared (clip chains count once)
  std::uint64_t node_steps = 0, clips = 0, pops = 0, leaves = 0, drops = 0, pushes_seen = 0;
  std::uint64_t cycles = 0;
  TravDivergence first;
};

// Latencies the outputs are held to: the cycle model's traversal depth, one cycle per dropped
// stack entry (docs/hw-interface.md).
struct TravLatency {
  int depth = 12;
};

// V: the Verilated traversal_ctrl; kL: the model's lane capacity (>= P, at least 2).
template <class V, int kL = kLanes, class D = units::FastDatapath>
class TravHarness {
 public:
  using S = units::PacketState<F, kL, D>;

  TravHarness(const memif::MemoryImage& image, TravLatency lat)
      : image_(image), lat_(lat), top_(std::make_unique<V>()) {
    const auto& r = image.registers();
    set3(top_->scene_lo, r.scene_min);
    set3(top_->scene_hi, r.scene_max);
    top_->top_root = r.top_root;
    top_->rst = 1;
    for (int i = 0; i < 3; ++i)
      tick();
    top_->rst = 0;
    run_.cycles = 0;
  }
  ~TravHarness() { top_->final(); }

  const TravRun& run() const { return run_; }

  // Runs one packet from its generation to the RGS (the model's neighbours). With `shade`, the
  // thread goes on through the RGS (shading, shadow packets from path a and RGS -> traversal)
  // until it is done. Returns false at the first divergence.
  bool packet(S& s, std::uint32_t thread, bool shade = false) {
    ++run_.packets;
    thread_ = thread;
    // Path b: the top level's start with the generated world rays and t_best.
    start(s, false);
    for (;;) {
      const units::Phase ph = s.phase;
      if (ph == units::Phase::kClipTop || ph == units::Phase::kClipBottom) {
        if (!clip(s)) return false;
      } else if (ph == units::Phase::kTraverse) {
        if (!step(s)) return false;
      } else if (ph == units::Phase::kPop) {
        if (!pop_request(s)) return false;
      } else if (ph == units::Phase::kList || ph == units::Phase::kIntersect ||
                 ph == units::Phase::kTransformObject || ph == units::Phase::kTransformTriangle) {
        if (!neighbour(s)) return false;
      } else if (!shade || ph == units::Phase::kDone) {
        return true;  // the RGS: the packet left the traversal
      } else {
        rgs(s);
      }
    }
  }

 private:
  using Phase = units::Phase;

  static void set3(VlWide<3>& w, const std::array<std::uint32_t, 3>& f) {
    w[0] = (f[0] & 0xFFFFFFu) | (f[1] << 24);
    w[1] = ((f[1] & 0xFFFFFFu) >> 8) | (f[2] << 16);
    w[2] = (f[2] & 0xFFFFFFu) >> 16;
  }
  template <class Vec>
  static std::array<std::uint32_t, 3> bits3(const Vec& v) {
    return {v[0].bits, v[1].bits, v[2].bits};
  }

  void tick() {
    top_->clk = 0;
    top_->eval();
    top_->clk = 1;
    top_->eval();
    ++cycle_;
    ++run_.cycles;
    top_->ld_valid = 0;
    top_->hu_valid = 0;
    top_->is_valid = 0;
  }
  void settle() {
    top_->clk = 0;
    top_->eval();
  }

  bool fail(const std::string& kind, const std::string& what) {
    run_.first.found = true;
    run_.first.request = run_.requests;
    run_.first.cycle = cycle_;
    run_.first.kind = kind;
    run_.first.what = what;
    return false;
  }
  static std::string hex(std::uint64_t v) {
    std::ostringstream o;
    o << "0x" << std::hex << v;
    return o.str();
  }

  // Port 0 of the level start (path b) for the thread: the level's rays of every lane (the world
  // rays with t_best, valid and done; or the object rays), and for a bottom level the object's
  // box, root and entry mask.
  void start(const S& s, bool bottom) {
    constexpr int kW = 24, kRay = 3 * kW;
    top_->ld_valid = 1;
    put_bits(top_->ld_thread, 0, thread_bits(kThreads), thread_);
    top_->ld_bottom = bottom;
    top_->ld_shadow = s.kind == units::RayKind::kShadow;
    std::uint64_t valid = 0, done = 0;
    for (int i = 0; i < s.p; ++i) {
      const auto& l = s.lane(i);
      const units::Ray<F>& ray = bottom ? l.current : l.world;
      for (int k = 0; k < 3; ++k) {
        put_bits(top_->ld_o, i * kRay + k * kW, kW, ray.o[static_cast<std::size_t>(k)].bits);
        put_bits(top_->ld_d, i * kRay + k * kW, kW, ray.d[static_cast<std::size_t>(k)].bits);
      }
      put_bits(top_->ld_tbest, i * kW, kW, l.hit.t.bits);
      valid |= std::uint64_t{l.valid} << i;
      done |= std::uint64_t{l.done} << i;
    }
    put_bits(top_->ld_lane_valid, 0, s.p, valid);
    put_bits(top_->ld_done, 0, s.p, done);
    put_bits(top_->ld_mask, 0, s.p, bottom ? s.list.entry_mask() : 0);
    if (bottom) {
      const std::uint32_t row = s.list.instance_row();
      const auto lo = image_.row(row + 4), hi = image_.row(row + 5);
      for (int k = 0; k < 3; ++k) {
        put_bits(top_->ld_lo, k * kW, kW, lo[static_cast<std::size_t>(k)]);
        put_bits(top_->ld_hi, k * kW, kW, hi[static_cast<std::size_t>(k)]);
      }
      put_bits(top_->ld_root, 0, 28, s.list.header().root);
    }
    tick();
  }

  // The request the RTL names for the thread against the model's.
  bool check_request(const S& s) {
    top_->rq_thread = thread_;
    settle();
    const bool clip = s.phase == Phase::kClipTop || s.phase == Phase::kClipBottom;
    if (static_cast<bool>(top_->rq_clip) != clip)
      return fail("payload", "request kind: model " + std::string(units::phase_name(s.phase)) +
                                 ", RTL " + (top_->rq_clip ? "clip" : "node"));
    if (clip) {
      if (top_->rq_face != static_cast<std::uint32_t>(s.traversal.clip_face()))
        return fail("payload", "clip face: model " + std::to_string(s.traversal.clip_face()) +
                                   ", RTL " + std::to_string(top_->rq_face));
      if (top_->rq_mask != s.traversal.clip_mask())
        return fail("payload", "clip mask: model " + hex(s.traversal.clip_mask()) + ", RTL " +
                                   hex(top_->rq_mask));
      return true;
    }
    if (top_->rq_node != s.traversal.node())
      return fail("payload", "node: model " + std::to_string(s.traversal.node()) + ", RTL " +
                                 std::to_string(top_->rq_node));
    if (top_->rq_mask != s.traversal.mask())
      return fail("payload",
                  "mask: model " + hex(s.traversal.mask()) + ", RTL " + hex(top_->rq_mask));
    return true;
  }

  // The segments of the lanes in the mask (node requests).
  bool check_segments(const S& s) {
    for (int i = 0; i < s.p; ++i) {
      if (!units::lane_in(s.traversal.mask(), i)) continue;
      top_->dbg_thread = thread_;
      top_->dbg_lane = static_cast<std::uint32_t>(i);
      settle();
      const auto k = static_cast<std::size_t>(i);
      const std::uint32_t tn = s.encoding(s.v.tn[k]).bits, tf = s.encoding(s.v.tf[k]).bits;
      if (top_->dbg_tn != tn || top_->dbg_tf != tf)
        return fail("payload",
                    "lane " + std::to_string(i) + " segment: model [" + hex(tn) + ", " + hex(tf) +
                        "], RTL [" + hex(top_->dbg_tn) + ", " + hex(top_->dbg_tf) + "] (level " +
                        std::to_string(static_cast<int>(s.traversal.level())) + ", node " +
                        std::to_string(s.traversal.node()) + ", ray o " +
                        hex(s.lane(i).current.o[0].bits) + " " + hex(s.lane(i).current.o[1].bits) +
                        " " + hex(s.lane(i).current.o[2].bits) + " d " +
                        hex(s.lane(i).current.d[0].bits) + " " + hex(s.lane(i).current.d[1].bits) +
                        " " + hex(s.lane(i).current.d[2].bits) + ", t_best " +
                        hex(s.lane(i).hit.t.bits) + ")");
    }
    return true;
  }

  struct Out {
    bool valid = false;
    int port = 0;
    std::uint64_t cycle = 0;
    std::uint32_t dest = 0, node = 0, first = 0, end = 0, mask = 0;
  };
  // Clocks until the thread leaves the unit (at most `limit` cycles).
  Out wait_out(int limit) {
    Out o;
    for (int c = 0; c <= limit; ++c) {
      settle();
      if (top_->overflow) return o;
      if (top_->out_valid && top_->out_thread == thread_) {
        o = {true,           1,
             cycle_,         top_->out_dest,
             top_->out_node, top_->out_first,
             top_->out_end,  top_->out_mask};
        tick();
        return o;
      }
      if (top_->out2_valid && top_->out2_thread == thread_) {
        o = {true, 2, cycle_, top_->out2_dest, top_->out2_node, 0, 0, top_->out2_mask};
        tick();
        return o;
      }
      tick();
    }
    return o;
  }

  bool clip(S& s) {
    if (!check_request(s)) return false;
    const std::uint64_t issue = cycle_;
    top_->is_valid = 1;
    top_->is_thread = thread_;
    top_->is_kind = 1;
    // The model: the chained faces, one execute each.
    int faces = 0;
    const Phase ph = s.phase;
    while (s.phase == ph) {
      s.traversal.clip(s);
      ++faces;
    }
    ++run_.clips;
    drops_left_ = 0;
    const Out o = wait_out(lat_.depth + 16);
    return outcome(s, o, issue + static_cast<std::uint64_t>(faces - 1 + lat_.depth));
  }

  bool step(S& s) {
    if (!check_request(s) || !check_segments(s)) return false;
    const memif::KdNode n = image_.node(s.traversal.node());
    const auto w = memif::encode_node(n);
    const std::uint64_t issue = cycle_;
    top_->is_valid = 1;
    top_->is_thread = thread_;
    top_->is_kind = 0;
    top_->is_w0 = w[0];
    top_->is_w1 = w[1];
    const std::uint64_t drops0 = s.u.stack_drops;
    s.traversal.step(s);
    ++run_.node_steps;
    drops_left_ = s.u.stack_drops - drops0;
    run_.drops += drops_left_;
    const Out o = wait_out(lat_.depth + static_cast<int>(drops_left_) + 80);
    return outcome(s, o, issue + static_cast<std::uint64_t>(lat_.depth));
  }

  // A pop the model ran in the list or intersection unit: the thread passes through the RTL.
  bool pop(S& s) {
    const std::uint64_t issue = cycle_;
    top_->is_valid = 1;
    top_->is_thread = thread_;
    top_->is_kind = 2;
    ++run_.pops;
    const Out o = wait_out(lat_.depth + static_cast<int>(drops_left_) + 80);
    return outcome(s, o, issue + static_cast<std::uint64_t>(lat_.depth));
  }

  // The RTL's outcome against the model's state after the request. The thread leaves `due` =
  // issue + depth, one cycle later per stack entry dropped. A bottom level that ended inside the
  // request goes back to the top level's list (dest 2); when the model popped the top level as
  // well (that list was over), the RTL pops on, and the request's drops are split over the two.
  bool outcome(S& s, const Out& o, std::uint64_t due) {
    ++run_.requests;
    top_->dbg_thread = thread_;
    settle();
    if (!o.valid)
      return fail("missing", top_->overflow ? "RTL stack overflow" : "the thread never left");
    const Phase ph = s.phase;
    const bool more = o.dest == 2 && !(ph == Phase::kList || ph == Phase::kTransformObject);
    const std::uint64_t extra = o.cycle >= due ? o.cycle - due : ~std::uint64_t{0};
    // Shadow packets also drop entries whose rays are all done, which the model does not count:
    // there the RTL may leave later than the counted drops say, never earlier.
    const bool shadow = s.kind == units::RayKind::kShadow;
    if (shadow ? (extra == ~std::uint64_t{0} || (!more && extra < drops_left_))
               : (more ? extra > drops_left_ : extra != drops_left_))
      return fail("timing", "thread left in cycle " + std::to_string(o.cycle) + ", model " +
                                std::to_string(due + drops_left_) + " (depth " +
                                std::to_string(lat_.depth) + " + " + std::to_string(drops_left_) +
                                " drops after the issue)");
    drops_left_ = drops_left_ > extra ? drops_left_ - extra : 0;
    if (o.dest == 2) {
      // Back at the top level's list: the model continued there or popped the top level too.
      if (s.traversal.level() != units::Level::kTop)
        return fail("payload", "RTL ended the object, the model is still in it");
      if (!more) return true;
      return pop(s);
    }
    switch (ph) {
      case Phase::kTraverse:
        if (o.dest != 0)
          return fail("payload", "next unit: model traversal, RTL dest " + std::to_string(o.dest));
        if (o.node != s.traversal.node() || o.mask != s.traversal.mask())
          return fail("payload", "next node/mask: model " + std::to_string(s.traversal.node()) +
                                     "/" + hex(s.traversal.mask()) + ", RTL " +
                                     std::to_string(o.node) + "/" + hex(o.mask));
        return check_segments(s);
      case Phase::kList:
      case Phase::kTransformObject:
      case Phase::kTransformTriangle:
        if (o.dest != 1)
          return fail("payload", "next unit: model list, RTL dest " + std::to_string(o.dest));
        ++run_.leaves;
        if (o.mask != s.list.mask(s.traversal.level()))
          return fail("payload", "leaf mask: model " + hex(s.list.mask(s.traversal.level())) +
                                     ", RTL " + hex(o.mask));
        if (ph == Phase::kList && o.first != s.list.next(s.traversal.level()))
          return fail("payload", "leaf list: model " +
                                     std::to_string(s.list.next(s.traversal.level())) + ", RTL " +
                                     std::to_string(o.first));
        return true;
      case Phase::kShadeSurface:
      case Phase::kShadeShadow:
        if (o.dest != 3)
          return fail("payload", "next unit: model RGS, RTL dest " + std::to_string(o.dest));
        return true;
      default:
        return fail("payload", std::string("model phase ") + units::phase_name(ph) +
                                   " after a traversal request");
    }
  }

  // The RGS and ray generation (as ThreadProgram::execute): a packet that starts a top level
  // (a secondary packet from path b, a shadow packet from the RGS) loads its world rays.
  void rgs(S& s) {
    switch (s.phase) {
      case Phase::kGenerate:
        s.transformation.generate(s);
        break;
      case Phase::kShadeSurface:
        s.rgs.begin_request();
        s.rgs.shade_surface(s);
        break;
      case Phase::kShadeLight:
        s.rgs.begin_request();
        s.rgs.shade_light(s);
        break;
      case Phase::kShadeShadow:
        s.rgs.begin_request();
        s.rgs.shade_shadow(s);
        break;
      default:
        return;
    }
    if (s.phase == Phase::kClipTop) {
      ++run_.packets;
      start(s, false);
    }
  }

  // The model's list, transformation and intersection steps; their hand-overs to the RTL.
  bool neighbour(S& s) {
    switch (s.phase) {
      case Phase::kList:
        s.list.step(s);
        break;
      case Phase::kTransformObject:
        s.transformation.object(s);
        start(s, true);
        return true;
      case Phase::kTransformTriangle:
        s.transformation.triangle(s);
        return true;
      case Phase::kIntersect:
        s.intersection.step(s);
        hit_update(s);
        break;
      default:
        return true;
    }
    return true;
  }

  // A list ended (Phase::kPop, on f or list -> traversal): the model's pop and the RTL's.
  bool pop_request(S& s) {
    const std::uint64_t drops0 = s.u.stack_drops;
    s.traversal.pop(s);
    drops_left_ = s.u.stack_drops - drops0;
    run_.drops += drops_left_;
    return pop(s);
  }

  // The hit update of every lane in one cycle.
  void hit_update(const S& s) {
    top_->hu_valid = 1;
    top_->hu_thread = thread_;
    std::uint64_t done = 0;
    for (int i = 0; i < s.p; ++i) {
      put_bits(top_->hu_tbest, i * 24, 24, s.lane(i).hit.t.bits);
      done |= std::uint64_t{s.lane(i).done} << i;
    }
    put_bits(top_->hu_done, 0, s.p, done);
    tick();
  }

  const memif::MemoryImage& image_;
  TravLatency lat_;
  std::unique_ptr<V> top_;
  std::uint64_t cycle_ = 0;
  std::uint32_t thread_ = 0;
  std::uint64_t drops_left_ = 0;  // the model's drops of the request not yet seen in the RTL
  TravRun run_;
};

}  // namespace saarcor::rtl::testing
