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

// One Verilated DynRTC as a part of the lockstep: its boundary's inputs driven, its ports read
// as the model's records. Pipeline q's threads are the model's ids [q x threads, (q + 1) x
// threads): its events are moved to the RTL's ids (0 ..) on the way in and back on the way out.
template <class V>
class DynrtcCore {
 public:
  DynrtcCore(const DynrtcBuild& b, const DynrtcConfig& c, bool ext_route, int pipe)
      : tw_(thread_bits(b.threads)),
        p_(b.packet),
        pipe_(pipe),
        offset_(static_cast<std::uint32_t>(pipe * b.threads)),
        ext_route_(ext_route),
        config_(c) {}

  void reset() {
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
    v.ext_route = ext_route_;
    clear_inputs();
    top_.reset();
  }

  // The cycle's boundary events of this DynRTP onto its ports (the controller port's only with
  // the DynRTC's own routing), and the clock low.
  void drive(const std::vector<BoundaryEvent>& inputs) {
    clear_inputs();
    int clears = 0, starts = 0;
    for (const BoundaryEvent& e : inputs) {
      if (!at_dynrtc_boundary(e)) continue;  // (the lockstep gives no other)
      const bool port =
          e.port == BoundaryPort::kPortResponse || e.port == BoundaryPort::kPortBlocked;
      if (port ? ext_route_ : e.dynrtp != pipe_) continue;
      if (port || offset_ == 0) {
        drive(e, clears, starts);
        continue;
      }
      BoundaryEvent local = e;  // (a hand-over of the second DynRTC: its own thread ids)
      local.thread -= offset_;
      drive(local, clears, starts);
    }
    top_.fall();
  }

  V& ports() { return *top_; }
  // The routing's inputs changed (a chip-level routing): the DynRTC settles again.
  void settle() { top_->eval(); }

  // The cycle's outputs, checked and recorded.
  void outputs(std::uint64_t cycle, std::vector<BoundaryEvent>& out) const {
    V& v = *top_;
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
    const std::size_t first = out.size();
    traversal_and_list(cycle, out);
    transformation_and_intersection(cycle, out);
    for (int k = 0; k < 3; ++k)
      cache(cycle, k, out);
    for (std::size_t i = first; i < out.size(); ++i)
      to_model(out[i]);
  }

  void rise() { top_.rise(); }
  void start_trace(const std::string& path) { top_.start_trace(path); }
  void stop_trace() { top_.stop_trace(); }

 private:
  // An RTL record in the model's thread ids: the thread and a cache label's tag.
  void to_model(BoundaryEvent& e) const {
    e.dynrtp = pipe_;
    const bool labelled = e.port == BoundaryPort::kCacheRequest ||
                          e.port == BoundaryPort::kCacheAccept ||
                          e.port == BoundaryPort::kCacheReply;
    if (!e.cache || labelled) e.thread += offset_;  // (a line request's record has no thread)
    if (labelled) e.field[2] += offset_;
  }

  void clear_inputs() {
    V& v = *top_;
    v.a_valid = 0;
    v.clr_valid = 0;
    v.st_valid = 0;
    v.r_valid = 0;
    v.ld_valid = 0;
    v.port_blocked = 0;
    v.rsp_valid = 0;
    v.x_mem_take = 0;
    v.x_fill_valid = 0;
  }

  // A model event at the DynRTC's boundary (at_dynrtc_boundary) onto its ports.
  void drive(const BoundaryEvent& e, int& clears, int& starts) {
    V& v = *top_;
    switch (e.port) {
      case BoundaryPort::kInput:
        if (e.unit == UnitId::kTransformation) return drive_generate(v, p_, e);
        if (v.r_valid) throw std::logic_error("lockstep: two threads on RGS -> traversal");
        v.r_valid = 1;
        put_bits(v.r_thread, 0, tw_, e.thread);
        return drive_level_start(v, 1, tw_, p_, e);
      case BoundaryPort::kSideBand:
        if (e.unit == UnitId::kIntersection) return drive_packet_start(v, starts++, tw_, e);
        if (clears == 2) throw std::logic_error("lockstep: three packet starts in one cycle");
        put_bits(v.clr_valid, clears, 1, 1);
        put_bits(v.clr_thread, tw_ * clears++, tw_, e.thread);
        return;
      default:
        drive_controller_port(v, e);
        return;
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

  int tw_, p_, pipe_;
  std::uint32_t offset_;
  bool ext_route_;
  DynrtcConfig config_;
  VerilatedTop<V> top_;
};

// The whole DynRTC of pipelines=1: one top with its own routing.
template <class V>
class DynrtcRtlOf final : public UnitRtl {
 public:
  DynrtcRtlOf(const DynrtcBuild& b, const DynrtcConfig& c) : core_(b, c, false, 0) {}
  UnitId unit() const override { return UnitId::kNone; }
  std::string name() const override { return "dynrtc"; }
  void reset() override { core_.reset(); }
  void cycle(std::uint64_t cycle, const std::vector<BoundaryEvent>& inputs,
             std::vector<BoundaryEvent>& outputs) override {
    core_.drive(inputs);
    core_.outputs(cycle, outputs);
    core_.rise();
  }
  void start_trace(const std::string& path) override { core_.start_trace(path); }
  void stop_trace() override { core_.stop_trace(); }

 private:
  DynrtcCore<V> core_;
};

#if defined(SAARCOR_DYNRTC_ROUTING)
// Two whole DynRTCs (pipelines=2) on one RTL routing over their six caches (rtl/routing.sv, the
// model's one SimpleRouting over every pipeline's clients): each DynRTC takes the chip-level
// routing (ext_route), whose takes and fills the wires below carry in the same cycle (the caches'
// line-request queue and fill room are registers: the routing settles after the DynRTCs, the
// DynRTCs after it).
template <class V, class R>
class DynrtcPairRtl final : public UnitRtl {
 public:
  DynrtcPairRtl(const DynrtcBuild& b, const std::vector<DynrtcConfig>& c) {
    for (int q = 0; q < 2; ++q)
      cores_.push_back(std::make_unique<DynrtcCore<V>>(b, c[static_cast<std::size_t>(q)], true, q));
    for (int i = 0; i < 6; ++i)
      put_bits(route_->cfg_id, 16 * i, 16,
               c[static_cast<std::size_t>(i / 3)].clients[static_cast<std::size_t>(i % 3)]);
  }
  UnitId unit() const override { return UnitId::kNone; }
  std::string name() const override { return "dynrtc"; }
  void reset() override {
    for (auto& c : cores_)
      c->reset();
    route_->port_blocked = 0;
    route_->rsp_valid = 0;
    route_.reset();
  }

  void cycle(std::uint64_t cycle, const std::vector<BoundaryEvent>& inputs,
             std::vector<BoundaryEvent>& outputs) override {
    R& r = *route_;
    r.port_blocked = 0;
    r.rsp_valid = 0;
    for (const BoundaryEvent& e : inputs)
      drive_controller_port(r, e);
    for (int q = 0; q < 2; ++q) {
      cores_[static_cast<std::size_t>(q)]->drive(inputs);
      const auto& v = cores_[static_cast<std::size_t>(q)]->ports();
      put_bits(r.mq_valid, 3 * q, 3, v.x_mq_valid);
      put_bits(r.fill_ready, 3 * q, 3, v.x_fill_ready);
    }
    route_.fall();
    if (r.overflow || r.unknown_client)
      throw std::runtime_error(
          "lockstep: the routing's response channel overflowed or a response "
          "named no cache in cycle " +
          std::to_string(cycle));
    for (int q = 0; q < 2; ++q) {
      auto& v = cores_[static_cast<std::size_t>(q)]->ports();
      v.x_mem_take = static_cast<CData>(get_bits(r.mem_take, 3 * q, 3));
      v.x_fill_valid = static_cast<CData>(get_bits(r.fill_valid, 3 * q, 3));
      v.x_fill_tag = r.fill_tag;
      for (int w = 0; w < 4; ++w)
        put_bits(v.x_fill_words, 32 * w, 32, get_bits(r.fill_words, 32 * w, 32));
      cores_[static_cast<std::size_t>(q)]->settle();
      cores_[static_cast<std::size_t>(q)]->outputs(cycle, outputs);
    }
    for (auto& c : cores_)
      c->rise();
    route_.rise();
  }
  // Each DynRTC's waveform: the second's file name has ".dynrtp1" before its extension.
  void start_trace(const std::string& path) override {
    cores_[0]->start_trace(path);
    const std::size_t dot = path.rfind('.');
    const std::size_t slash = path.rfind('/');
    const bool ext = dot != std::string::npos && (slash == std::string::npos || dot > slash);
    cores_[1]->start_trace(ext ? path.substr(0, dot) + ".dynrtp1" + path.substr(dot)
                               : path + ".dynrtp1");
  }
  void stop_trace() override {
    for (auto& c : cores_)
      c->stop_trace();
  }

 private:
  std::vector<std::unique_ptr<DynrtcCore<V>>> cores_;
  VerilatedTop<R> route_;
};
#endif

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
                                         [[maybe_unused]] const std::vector<DynrtcConfig>& config) {
  if (config.size() != 1 && config.size() != 2)
    throw std::runtime_error("lockstep: one or two whole DynRTCs, not " +
                             std::to_string(config.size()));
#if defined(SAARCOR_DYNRTC_ROUTING)
#define SAARCOR_DYNRTC_BUILD(id, cls, threads, packet, stack, mb, tmb)                   \
  if (build.name == #id) {                                                               \
    if (config.size() == 1) return std::make_unique<DynrtcRtlOf<cls>>(build, config[0]); \
    return std::make_unique<DynrtcPairRtl<cls, SAARCOR_DYNRTC_ROUTING>>(build, config);  \
  }
  SAARCOR_DYNRTC_BUILDS(SAARCOR_DYNRTC_BUILD)
#undef SAARCOR_DYNRTC_BUILD
#endif
  throw std::runtime_error("no Verilated whole-DynRTC build named '" + build.name + "'");
}

}  // namespace saarcor::rtl
