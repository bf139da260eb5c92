// The Verilated list unit builds (rtl/list_rtl.h). The builds and their parameters come from one
// list in rtl/CMakeLists.txt, which generates rtl_list_builds.h (the Verilated headers and the
// table below) and passes the same values to Verilator as -G parameters.
#include "rtl/list_rtl.h"

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "rtl/port_bits.h"
#include "rtl/verilated_top.h"
#include "rtl_list_builds.h"
#include "units/boundary_list.h"
#include "verilated.h"

namespace saarcor::rtl {
namespace {

template <class V>
class ListRtlOf final : public ListRtl {
 public:
  explicit ListRtlOf(const ListBuild& b) : tw_(thread_bits(b.threads)), p_(b.packet) {}

  void reset() override { top_.reset(); }

  ListOutputs cycle(const ListInputs& in) override {
    V& v = *top_;
    v.in_valid = 0;
    v.in_start = 0;
    v.in_level = 0;
    for (int i = 0; i < 3; ++i) {
      const auto k = static_cast<std::size_t>(i);
      put_bits(v.in_valid, i, 1, in.valid[k]);
      put_bits(v.in_start, i, 1, in.start[k]);
      put_bits(v.in_level, i, 1, in.level[k]);
      put_bits(v.in_thread, i * tw_, tw_, in.thread[k]);
      put_bits(v.in_next, i * 32, 32, in.next[k]);
      put_bits(v.in_end, i * 32, 32, in.end[k]);
      put_bits(v.in_mask, i * p_, p_, in.mask[k]);
    }
    for (int c = 0; c < 2; ++c) {
      const auto k = static_cast<std::size_t>(c);
      put_bits(v.clr_valid, c, 1, in.clear[k]);
      put_bits(v.clr_thread, c * tw_, tw_, in.clear_thread[k]);
    }
    v.req_ready = in.req_ready;
    v.resp_valid = in.resp;
    v.resp_thread = static_cast<std::remove_reference_t<decltype(v.resp_thread)>>(in.resp_thread);
    v.resp_word = in.resp_word;
    top_.fall();
    ListOutputs o;
    o.req = v.req_valid && in.req_ready;
    o.req_item = v.req_item;
    o.req_thread = static_cast<std::uint32_t>(v.req_thread);
    o.out = v.out_valid;
    o.out_thread = static_cast<std::uint32_t>(v.out_thread);
    o.kind = v.out_kind;
    o.level = v.out_level;
    o.next = v.out_next;
    o.entry = v.out_entry;
    o.mask = get_bits(v.out_mask, 0, p_);
    o.list = get_bits(v.out_list, 0, p_);
    o.last = v.out_last;
    top_.rise();
    return o;
  }

  void start_trace(const std::string& path) override { top_.start_trace(path); }
  void stop_trace() override { top_.stop_trace(); }

 private:
  int tw_, p_;
  VerilatedTop<V> top_;
};

// The list unit's input path (priority order, units/dynrtp.cpp) of a sending unit.
int input_path(units::UnitId from) {
  switch (from) {
    case units::UnitId::kList:
      return 0;
    case units::UnitId::kIntersection:
      return 1;
    case units::UnitId::kTraversal:
      return 2;
    default:
      throw std::logic_error(std::string("lockstep: a thread reached the list unit from the ") +
                             units::unit_name(from) + " unit, which has no path to it");
  }
}

class ListUnitRtl final : public UnitRtl {
 public:
  explicit ListUnitRtl(const ListBuild& b) : rtl_(make_list_rtl(b)) {}
  units::UnitId unit() const override { return units::UnitId::kList; }
  void reset() override { rtl_->reset(); }
  void start_trace(const std::string& path) override { rtl_->start_trace(path); }
  void stop_trace() override { rtl_->stop_trace(); }

  void cycle(std::uint64_t cycle, const std::vector<units::BoundaryEvent>& inputs,
             std::vector<units::BoundaryEvent>& outputs) override {
    using units::BoundaryPort;
    ListInputs in;
    int clears = 0;
    for (const units::BoundaryEvent& e : inputs) {
      switch (e.port) {
        case BoundaryPort::kInput: {
          const auto i = static_cast<std::size_t>(input_path(e.path));
          if (in.valid[i])
            throw std::logic_error("lockstep: two threads on one list unit path in a cycle");
          in.valid[i] = true;
          in.thread[i] = e.thread;
          in.start[i] = e.field[0] != 0;
          in.level[i] = e.field[1] != 0;
          in.next[i] = static_cast<std::uint32_t>(e.field[2]);
          in.end[i] = static_cast<std::uint32_t>(e.field[3]);
          in.mask[i] = e.field[4];
          break;
        }
        case BoundaryPort::kSideBand:
          if (clears == 2) throw std::logic_error("lockstep: three packet starts in one cycle");
          in.clear[static_cast<std::size_t>(clears)] = true;
          in.clear_thread[static_cast<std::size_t>(clears++)] = e.thread;
          break;
        case BoundaryPort::kCacheBlocked:
          in.req_ready = false;
          break;
        case BoundaryPort::kCacheResponse:
          in.resp = true;
          in.resp_thread = e.thread;
          in.resp_word = static_cast<std::uint32_t>(e.field[1]);
          break;
        default:
          throw std::logic_error("lockstep: an output event given to the list unit as an input");
      }
    }
    const ListOutputs out = rtl_->cycle(in);
    if (out.req)
      add_cache_request(outputs, cycle, units::UnitId::kList, out.req_item, out.req_thread);
    if (out.out) {
      units::BoundaryEvent& e = add_event(outputs, cycle, units::UnitId::kList,
                                          units::BoundaryPort::kOutput, out.out_thread);
      constexpr units::UnitId kTo[] = {units::UnitId::kTransformation, units::UnitId::kList,
                                       units::UnitId::kTraversal};
      e.path = kTo[std::min<std::uint32_t>(out.kind, 2)];
      e.fields = 7;
      e.names = units::kListOutputFields;
      e.field = {out.kind, out.level, out.next, out.entry, out.mask, out.list, out.last ? 1u : 0u};
    }
  }

 private:
  std::unique_ptr<ListRtl> rtl_;
};

}  // namespace

const std::vector<ListBuild>& list_builds() {
  static const std::vector<ListBuild> b = {
#define SAARCOR_LIST_BUILD(id, cls, threads, packet, mb, tmb, depth, fault) \
  {#id, threads, packet, mb, tmb, depth, fault},
      SAARCOR_LIST_BUILDS(SAARCOR_LIST_BUILD)
#undef SAARCOR_LIST_BUILD
  };
  return b;
}

std::unique_ptr<ListRtl> make_list_rtl(const ListBuild& build) {
#define SAARCOR_LIST_BUILD(id, cls, threads, packet, mb, tmb, depth, fault) \
  if (build.name == #id) return std::make_unique<ListRtlOf<cls>>(build);
  SAARCOR_LIST_BUILDS(SAARCOR_LIST_BUILD)
#undef SAARCOR_LIST_BUILD
  throw std::runtime_error("no Verilated list unit build named '" + build.name + "'");
}

std::unique_ptr<UnitRtl> make_list_unit_rtl(const ListBuild& build) {
  return std::make_unique<ListUnitRtl>(build);
}

}  // namespace saarcor::rtl
