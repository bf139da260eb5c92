// The Verilated traversal unit builds (rtl/traversal_rtl.h). The builds and their parameters come
// from one list in rtl/CMakeLists.txt, which generates rtl_traversal_builds.h (the Verilated
// headers and the table below) and passes the same values to Verilator as -G parameters.
#include "rtl/traversal_rtl.h"

#include <array>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "rtl/port_bits.h"
#include "rtl/unit_ports.h"
#include "rtl/verilated_top.h"
#include "rtl_traversal_builds.h"
#include "units/boundary_traversal.h"
#include "verilated.h"

namespace saarcor::rtl {
namespace {

using units::BoundaryEvent;
using units::BoundaryPort;
using units::UnitId;

constexpr int kW = kPortFloatBits;
constexpr int kLoadPorts = 2;  // 0: path b (the transformation unit), 1: RGS -> traversal

// The input path a sending unit's thread arrives on (f, list -> traversal, RGS -> traversal, b);
// -1 for the unit's own loop, which the RTL closes itself.
int input_path(UnitId from) {
  switch (from) {
    case UnitId::kTraversal:
      return -1;
    case UnitId::kIntersection:
      return 0;
    case UnitId::kList:
      return 1;
    case UnitId::kRgs:
      return 2;
    case UnitId::kTransformation:
      return 3;
    default:
      throw std::logic_error(
          std::string("lockstep: a thread reached the traversal unit from the ") +
          units::unit_name(from) + " unit, which has no path to it");
  }
}

template <class V>
class TraversalRtlOf final : public UnitRtl, public TraversalStackProbe {
 public:
  TraversalRtlOf(const TraversalBuild& b, const memif::FrameRegisters& frame)
      : tw_(thread_bits(b.threads)), p_(b.packet) {
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<std::size_t>(k);
      put_bits(top_->scene_lo, k * kW, kW, frame.scene_min[a]);
      put_bits(top_->scene_hi, k * kW, kW, frame.scene_max[a]);
    }
    top_->top_root = frame.top_root;
  }

  UnitId unit() const override { return UnitId::kTraversal; }

  void reset() override { top_.reset(); }

  void cycle(std::uint64_t cycle, const std::vector<BoundaryEvent>& inputs,
             std::vector<BoundaryEvent>& outputs) override {
    V& v = *top_;
    clear_inputs();
    for (const BoundaryEvent& e : inputs)
      drive(e);
    top_.fall();
    if (v.req_valid && v.req_ready)
      add_cache_request(outputs, cycle, UnitId::kTraversal, v.req_item,
                        static_cast<std::uint32_t>(v.req_thread));
    if (v.out_valid)
      add_traversal_output(
          outputs, cycle, v.out_thread, v.out_dest,
          {v.out_node, v.out_first, v.out_end, get_bits(v.out_mask, 0, p_), v.out_level});
    if (v.out2_valid)
      add_traversal_output(outputs, cycle, v.out2_thread, v.out2_dest,
                           {v.out2_node, 0, 0, get_bits(v.out2_mask, 0, p_), v.out2_level});
    top_.rise();
  }

  int stack_size(std::uint32_t thread) override {
    top_->dbg_thread = static_cast<std::remove_reference_t<decltype(top_->dbg_thread)>>(thread);
    top_->eval();
    return static_cast<int>(top_->dbg_size);
  }

  void start_trace(const std::string& path) override { top_.start_trace(path); }
  void stop_trace() override { top_.stop_trace(); }

 private:
  void clear_inputs() {
    V& v = *top_;
    v.ld_valid = 0;
    v.hu_valid = 0;
    v.f_valid = 0;
    v.l_valid = 0;
    v.r_valid = 0;
    v.b_valid = 0;
    v.resp_valid = 0;
    v.req_ready = 1;
  }

  // One input event of the model's traversal unit onto the ports.
  void drive(const BoundaryEvent& e) {
    V& v = *top_;
    switch (e.port) {
      case BoundaryPort::kInput:
        return arrive(e);
      case BoundaryPort::kSideBand:
        return hit_update(e);
      case BoundaryPort::kCacheBlocked:
        v.req_ready = 0;
        return;
      case BoundaryPort::kCacheResponse:
        v.resp_valid = 1;
        v.resp_thread = static_cast<std::remove_reference_t<decltype(v.resp_thread)>>(e.thread);
        v.resp_w0 = static_cast<std::uint32_t>(e.field[1]);
        v.resp_w1 = static_cast<std::uint32_t>(e.field[2]);
        return;
      default:
        throw std::logic_error("lockstep: an output event given to the traversal unit as an input");
    }
  }

  // A thread pushed on one of the input paths (with its level start on b and RGS -> traversal).
  void arrive(const BoundaryEvent& e) {
    V& v = *top_;
    const int path = input_path(e.path);
    if (path < 0) return;  // the unit's own loop: the RTL takes its thread back itself
    const auto t = static_cast<std::uint32_t>(e.thread);
    const auto taken = [](auto& valid) {
      if (valid)
        throw std::logic_error("lockstep: two threads on one traversal unit path in a cycle");
      valid = 1;
    };
    using TW = std::remove_reference_t<decltype(v.f_thread)>;
    switch (path) {
      case 0:
        taken(v.f_valid);
        v.f_thread = static_cast<TW>(t);
        return;
      case 1:
        taken(v.l_valid);
        v.l_thread = static_cast<TW>(t);
        return;
      case 2:
        taken(v.r_valid);
        v.r_thread = static_cast<TW>(t);
        return load(1, e);
      default:
        taken(v.b_valid);
        v.b_thread = static_cast<TW>(t);
        return load(0, e);
    }
  }

  // Load port k: the level start's fields and the lanes' rays.
  void load(int k, const BoundaryEvent& e) { drive_level_start(*top_, k, tw_, p_, e); }

  // The hit update: every lane's t_best and done.
  void hit_update(const BoundaryEvent& e) {
    V& v = *top_;
    if (v.hu_valid) throw std::logic_error("lockstep: two hit updates in one cycle");
    if (e.fields != 1 || e.wide.size() != static_cast<std::size_t>(p_))
      throw std::logic_error("lockstep: a hit update without its " + std::to_string(p_) +
                             " words for the traversal unit");
    v.hu_valid = 1;
    v.hu_thread = static_cast<std::remove_reference_t<decltype(v.hu_thread)>>(e.thread);
    put_bits(v.hu_done, 0, p_, e.field[0]);
    for (int i = 0; i < p_; ++i)
      put_bits(v.hu_tbest, i * kW, kW, e.wide[static_cast<std::size_t>(i)]);
  }

  int tw_, p_;
  VerilatedTop<V> top_;
};

}  // namespace

const std::vector<TraversalBuild>& traversal_builds() {
  static const std::vector<TraversalBuild> b = {
#define SAARCOR_TRAVERSAL_BUILD(id, cls, threads, packet, stack, add, div, cmp, fault) \
  {#id, threads, packet, stack, add, div, cmp, fault},
      SAARCOR_TRAVERSAL_BUILDS(SAARCOR_TRAVERSAL_BUILD)
#undef SAARCOR_TRAVERSAL_BUILD
  };
  return b;
}

std::unique_ptr<UnitRtl> make_traversal_unit_rtl(const TraversalBuild& build,
                                                 const memif::FrameRegisters& frame) {
#define SAARCOR_TRAVERSAL_BUILD(id, cls, threads, packet, stack, add, div, cmp, fault) \
  if (build.name == #id) return std::make_unique<TraversalRtlOf<cls>>(build, frame);
  SAARCOR_TRAVERSAL_BUILDS(SAARCOR_TRAVERSAL_BUILD)
#undef SAARCOR_TRAVERSAL_BUILD
  throw std::runtime_error("no Verilated traversal unit build named '" + build.name + "'");
}

}  // namespace saarcor::rtl
