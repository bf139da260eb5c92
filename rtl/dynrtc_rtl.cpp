// The Verilated whole-DynRTC builds (rtl/dynrtc_rtl.h). The builds and their parameters come from
// one list in rtl/CMakeLists.txt, which generates rtl_dynrtc_builds.h (the Verilated headers and
// the table below) and passes the same values to Verilator as -G parameters.
#include "rtl/dynrtc_rtl.h"

#include <bit>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "rtl/port_bits.h"
#include "rtl/unit_ports.h"
#include "rtl/verilated_top.h"
#include "rtl_dynrtc_builds.h"
#include "verilated.h"

namespace saarcor::rtl {
namespace {

using units::BoundaryEvent;
using units::BoundaryPort;
using units::UnitId;

constexpr UnitId kCacheUnits[3] = {UnitId::kTraversal, UnitId::kList, UnitId::kTransformation};

template <class V>
class DynrtcRtlOf final : public UnitRtl {
 public:
  DynrtcRtlOf(const DynrtcBuild& b, const DynrtcConfig& c)
      : tw_(thread_bits(b.threads)), p_(b.packet), config_(c) {}

  UnitId unit() const override { return UnitId::kNone; }
  std::string name() const override { return "dynrtc"; }

  void reset() override {
    V& v = *top_;
    constexpr int kW = kPortFloatBits;
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<std::size_t>(k);
      put_bits(v.scene_lo, k * kW, kW, config_.frame.scene_min[a]);
      put_bits(v.scene_hi, k * kW, kW, config_.frame.scene_max[a]);
      const CacheSizes& s = config_.caches[a];
      put_bits(v.cfg_lines_log2, 5 * k, 5, std::countr_zero(unsigned(s.items)));
      put_bits(v.cfg_ways_log2, 5 * k, 5, std::countr_zero(unsigned(s.ways)));
      put_bits(v.cfg_words, 3 * k, 3, static_cast<std::uint64_t>(s.words));
      put_bits(v.cfg_base, 32 * k, 32, s.base);
      put_bits(v.cfg_id, 16 * k, 16, config_.clients[a]);
    }
    v.top_root = config_.frame.top_root;
    v.instance_row_base = config_.frame.instance_row_base;
    clear_inputs();
    top_.reset();
  }

  void cycle(std::uint64_t cycle, const std::vector<BoundaryEvent>& inputs,
             std::vector<BoundaryEvent>& outputs) override {
    V& v = *top_;
    clear_inputs();
    int clears = 0, starts = 0;
    for (const BoundaryEvent& e : inputs)
      drive(e, clears, starts);
    top_.fall();
    if (v.conflict)
      throw std::runtime_error(
          "lockstep: two threads for the list unit's path from the traversal "
          "unit in cycle " +
          std::to_string(cycle) + " (the DynRTC has one)");
    if (v.routing_error)
      throw std::runtime_error(
          "lockstep: the routing's response channel overflowed or a response "
          "named no cache in cycle " +
          std::to_string(cycle));
    traversal_and_list(cycle, outputs);
    transformation_and_intersection(cycle, outputs);
    for (int k = 0; k < 3; ++k)
      cache(cycle, k, outputs);
    top_.rise();
  }

  void start_trace(const std::string& path) override { top_.start_trace(path); }
  void stop_trace() override { top_.stop_trace(); }

 private:
  void clear_inputs() {
    V& v = *top_;
    v.a_valid = 0;
    v.clr_valid = 0;
    v.st_valid = 0;
    v.r_valid = 0;
    v.ld_valid = 0;
    v.port_blocked = 0;
    v.rsp_valid = 0;
  }

  // A model event at the DynRTC's boundary onto its ports; the others are the RTL's own.
  void drive(const BoundaryEvent& e, int& clears, int& starts) {
    V& v = *top_;
    switch (e.port) {
      case BoundaryPort::kInput:
        if (e.path != UnitId::kRgs) return;  // another unit's hand-over: wired inside
        if (e.unit == UnitId::kTransformation) return drive_generate(v, p_, e);
        if (v.r_valid) throw std::logic_error("lockstep: two threads on RGS -> traversal");
        v.r_valid = 1;
        put_bits(v.r_thread, 0, tw_, e.thread);
        return drive_level_start(v, 1, tw_, p_, e);
      case BoundaryPort::kSideBand:
        if (e.unit == UnitId::kIntersection) return drive_packet_start(v, starts++, tw_, e);
        if (e.unit != UnitId::kList) return;  // the hit update: the intersection unit's output
        if (clears == 2) throw std::logic_error("lockstep: three packet starts in one cycle");
        put_bits(v.clr_valid, clears, 1, 1);
        put_bits(v.clr_thread, tw_ * clears++, tw_, e.thread);
        return;
      case BoundaryPort::kPortResponse:
        if (v.rsp_valid) throw std::logic_error("lockstep: two port responses in one cycle");
        v.rsp_valid = 1;
        v.rsp_client = static_cast<std::uint16_t>(e.field[0]);
        put_bits(v.rsp_tag, 0, 32, e.field[1]);
        for (int k = 0; k + 2 < e.fields; ++k)
          put_bits(v.rsp_words, 32 * k, 32, e.field[static_cast<std::size_t>(k) + 2]);
        return;
      case BoundaryPort::kPortBlocked:
        v.port_blocked = 1;
        return;
      default:
        return;  // a cache's request, response or back-pressure: wired inside
    }
  }

  void traversal_and_list(std::uint64_t cycle, std::vector<BoundaryEvent>& out) const {
    V& v = *top_;
    if (v.tv_req)
      add_cache_request(out, cycle, UnitId::kTraversal, v.tv_req_item,
                        static_cast<std::uint32_t>(v.tv_req_thread));
    if (v.tv_out_valid)
      add_traversal_output(out, cycle, v.tv_out_thread, v.tv_out_dest,
                           {v.tv_out_node, v.tv_out_first, v.tv_out_end,
                            get_bits(v.tv_out_mask, 0, p_), v.tv_out_level});
    if (v.tv_out2_valid)
      add_traversal_output(
          out, cycle, v.tv_out2_thread, v.tv_out2_dest,
          {v.tv_out2_node, 0, 0, get_bits(v.tv_out2_mask, 0, p_), v.tv_out2_level});
    ListOutputs o;
    o.req = v.ls_req;
    o.req_item = v.ls_req_item;
    o.req_thread = static_cast<std::uint32_t>(v.ls_req_thread);
    o.out = v.ls_out_valid;
    o.out_thread = static_cast<std::uint32_t>(v.ls_out_thread);
    o.kind = v.ls_out_kind;
    o.level = v.ls_out_level;
    o.next = v.ls_out_next;
    o.entry = v.ls_out_entry;
    o.mask = get_bits(v.ls_out_mask, 0, p_);
    o.list = get_bits(v.ls_out_list, 0, p_);
    o.last = v.ls_out_last;
    add_list_outputs(out, cycle, o);
  }

  void transformation_and_intersection(std::uint64_t cycle, std::vector<BoundaryEvent>& out) const {
    V& v = *top_;
    if (v.tf_req)
      add_cache_request(out, cycle, UnitId::kTransformation, v.tf_req_item,
                        static_cast<std::uint32_t>(v.tf_req_thread));
    if (v.tf_out_valid)
      add_transformation_output(
          out, cycle, p_, static_cast<std::uint32_t>(v.tf_out_thread),
          {v.tf_out_dest, v.tf_out_level, v.tf_out_shared, get_bits(v.tf_out_mask, 0, p_),
           v.tf_out_root, get_bits(v.tf_out_list, 0, p_), v.tf_out_last, v.tf_out_instance,
           v.tf_out_triangle, v.tf_out_shadow},
          v.tf_out_o, v.tf_out_d, v.tf_out_lo, v.tf_out_hi);
    if (v.is_out_valid)
      add_intersection_output(out, cycle, p_, static_cast<std::uint32_t>(v.is_out_thread),
                              v.is_out_dest, get_bits(v.is_out_mask, 0, p_),
                              get_bits(v.is_out_done, 0, p_), v.is_out_t, v.is_out_u, v.is_out_v,
                              v.is_out_c, v.is_out_instance, v.is_out_triangle);
  }

  // Cache k's lookup, reply and line request, and what the routing did to it.
  void cache(std::uint64_t cycle, int k, std::vector<BoundaryEvent>& out) const {
    V& v = *top_;
    constexpr int kLabel = 12, kMshr = 3, kLine = 4 * 32;
    CacheOutputs o;
    o.accept = get_bits(v.c_acc_valid, k, 1) != 0;
    o.acc_index = static_cast<std::uint32_t>(get_bits(v.c_acc_index, 32 * k, 32));
    o.acc_requester = static_cast<std::uint32_t>(get_bits(v.c_acc_requester, 3 * k, 3));
    o.acc_tag = static_cast<std::uint32_t>(get_bits(v.c_acc_tag, kLabel * k, kLabel));
    o.acc_kind = static_cast<std::uint32_t>(get_bits(v.c_acc_kind, 2 * k, 2));
    o.acc_mshr = static_cast<std::uint32_t>(get_bits(v.c_acc_mshr, kMshr * k, kMshr));
    o.resp = get_bits(v.c_resp_valid, k, 1) != 0;
    o.resp_index = static_cast<std::uint32_t>(get_bits(v.c_resp_index, 32 * k, 32));
    o.resp_requester = static_cast<std::uint32_t>(get_bits(v.c_resp_requester, 3 * k, 3));
    o.resp_tag = static_cast<std::uint32_t>(get_bits(v.c_resp_tag, kLabel * k, kLabel));
    const int words = config_.caches[static_cast<std::size_t>(k)].words;
    for (int w = 0; w < words; ++w)
      o.resp_words[static_cast<std::size_t>(w)] =
          static_cast<std::uint32_t>(get_bits(v.c_resp_words, kLine * k + 32 * w, 32));
    o.mreq = get_bits(v.c_mreq_valid, k, 1) != 0;
    o.mreq_tag = static_cast<std::uint32_t>(get_bits(v.c_mreq_tag, kMshr * k, kMshr));
    o.mreq_bank = static_cast<std::uint32_t>(get_bits(v.c_mreq_bank, 3 * k, 3));
    o.mreq_offset = static_cast<std::uint32_t>(get_bits(v.c_mreq_offset, 32 * k, 32));
    o.mreq_words = static_cast<std::uint32_t>(get_bits(v.c_mreq_words, 3 * k, 3));
    const UnitId unit = kCacheUnits[k];
    add_cache_outputs(out, cycle, unit, words, o);
    if (get_bits(v.c_mem_take, k, 1) != 0)
      add_event(out, cycle, unit, BoundaryPort::kMemTaken, 0).cache = true;
    if (get_bits(v.c_fill_valid, k, 1) != 0) {
      BoundaryEvent& e = add_event(out, cycle, unit, BoundaryPort::kMemFill, 0);
      e.cache = true;
      e.fields = 1 + words;
      e.names = units::kMemFillFields;
      e.field[0] = v.c_fill_tag;
      for (int w = 0; w < words; ++w)
        e.field[1 + static_cast<std::size_t>(w)] = get_bits(v.c_fill_words, 32 * w, 32);
    }
  }

  int tw_, p_;
  DynrtcConfig config_;
  VerilatedTop<V> top_;
};

}  // namespace

const std::vector<DynrtcBuild>& dynrtc_builds() {
  static const std::vector<DynrtcBuild> b = {
#define SAARCOR_DYNRTC_BUILD(id, cls, threads, packet, stack, mb, tmb) \
  {#id, threads, packet, stack, mb, tmb},
      SAARCOR_DYNRTC_BUILDS(SAARCOR_DYNRTC_BUILD)
#undef SAARCOR_DYNRTC_BUILD
  };
  return b;
}

std::unique_ptr<UnitRtl> make_dynrtc_rtl(const DynrtcBuild& build,
                                         [[maybe_unused]] const DynrtcConfig& config) {
#define SAARCOR_DYNRTC_BUILD(id, cls, threads, packet, stack, mb, tmb) \
  if (build.name == #id) return std::make_unique<DynrtcRtlOf<cls>>(build, config);
  SAARCOR_DYNRTC_BUILDS(SAARCOR_DYNRTC_BUILD)
#undef SAARCOR_DYNRTC_BUILD
  throw std::runtime_error("no Verilated whole-DynRTC build named '" + build.name + "'");
}

}  // namespace saarcor::rtl
