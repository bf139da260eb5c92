// The Verilated cache builds (rtl/cache_rtl.h). The builds and their parameters come from one
// list in rtl/CMakeLists.txt, which generates rtl_cache_builds.h (the Verilated headers and the
// table below) and passes the same values to Verilator as -G parameters.
#include "rtl/cache_rtl.h"

#include <bit>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "rtl/port_bits.h"
#include "rtl/unit_ports.h"
#include "rtl/verilated_top.h"
#include "rtl_cache_builds.h"
#include "units/boundary_cache.h"
#include "verilated.h"

namespace saarcor::rtl {
namespace {

// A value as the type of a Verilated port (the ports are references to the model's signals).
template <class Port, class V>
std::remove_reference_t<Port> as(V v) {
  return static_cast<std::remove_reference_t<Port>>(v);
}

template <class V>
class CacheRtlOf final : public CacheRtl {
 public:
  explicit CacheRtlOf(const CacheBuild& b) : words_(b.words) {}

  void reset(const CacheSizes& c) override {
    V& v = *top_;
    v.cfg_lines_log2 = as<decltype(v.cfg_lines_log2)>(std::countr_zero(unsigned(c.items)));
    v.cfg_ways_log2 = as<decltype(v.cfg_ways_log2)>(std::countr_zero(unsigned(c.ways)));
    v.cfg_words = as<decltype(v.cfg_words)>(c.words);
    v.cfg_base = c.base;
    v.req_valid = 0;
    v.mem_take = 0;
    v.fill_valid = 0;
    top_.reset();
  }

  CacheOutputs cycle(const CacheInputs& in) override {
    V& v = *top_;
    v.req_valid = in.req;
    v.req_index = in.req_index;
    v.req_requester = as<decltype(v.req_requester)>(in.req_requester);
    v.req_tag = as<decltype(v.req_tag)>(in.req_tag);
    v.mem_take = in.mem_take;
    v.fill_valid = in.fill;
    v.fill_tag = as<decltype(v.fill_tag)>(in.fill_tag);
    for (int k = 0; k < words_; ++k)
      put_bits(v.fill_words, 32 * k, 32, in.fill_words[static_cast<std::size_t>(k)]);
    top_.fall();
    CacheOutputs o;
    o.req_ready = v.req_ready;
    o.fill_ready = v.fill_ready;
    o.accept = v.acc_valid;
    o.acc_index = v.acc_index;
    o.acc_requester = v.acc_requester;
    o.acc_tag = v.acc_tag;
    o.acc_kind = v.acc_kind;
    o.acc_mshr = v.acc_mshr;
    o.resp = v.resp_valid;
    o.resp_index = v.resp_index;
    o.resp_requester = v.resp_requester;
    o.resp_tag = v.resp_tag;
    for (int k = 0; k < words_; ++k)
      o.resp_words[static_cast<std::size_t>(k)] =
          static_cast<std::uint32_t>(get_bits(v.resp_words, 32 * k, 32));
    o.mreq = v.mreq_valid;
    o.mreq_tag = v.mreq_tag;
    o.mreq_bank = v.mreq_bank;
    o.mreq_offset = v.mreq_offset;
    o.mreq_words = v.mreq_words;
    top_.rise();
    return o;
  }

  void start_trace(const std::string& path) override { top_.start_trace(path); }
  void stop_trace() override { top_.stop_trace(); }

 private:
  int words_;
  VerilatedTop<V> top_;
};

class CacheUnitRtl final : public UnitRtl {
 public:
  CacheUnitRtl(const CacheBuild& b, units::UnitId unit, const CacheSizes& c)
      : rtl_(make_cache_rtl(b)), unit_(unit), config_(c) {}
  units::UnitId unit() const override { return unit_; }
  bool cache() const override { return true; }
  std::string name() const override { return units::cache_name(unit_); }
  void reset() override { rtl_->reset(config_); }
  void start_trace(const std::string& path) override { rtl_->start_trace(path); }
  void stop_trace() override { rtl_->stop_trace(); }

  void cycle(std::uint64_t cycle, const std::vector<units::BoundaryEvent>& inputs,
             std::vector<units::BoundaryEvent>& outputs) override {
    const CacheOutputs out = rtl_->cycle(take(inputs));
    add_cache_outputs(outputs, cycle, unit_, config_.words, out);
  }

 private:
  // The model's input events of a cycle as the cache's input ports.
  CacheInputs take(const std::vector<units::BoundaryEvent>& inputs) const {
    using units::BoundaryPort;
    CacheInputs in;
    for (const units::BoundaryEvent& e : inputs) {
      if (e.port == BoundaryPort::kCacheRequest) {
        if (in.req) throw std::logic_error("lockstep: two requests pushed to a cache in a cycle");
        in.req = true;
        in.req_index = static_cast<std::uint32_t>(e.field[0]);
        in.req_requester = static_cast<std::uint32_t>(e.field[1]);
        in.req_tag = static_cast<std::uint32_t>(e.field[2]);
      } else if (e.port == BoundaryPort::kMemTaken) {
        in.mem_take = true;
      } else if (e.port == BoundaryPort::kMemFill) {
        if (in.fill) throw std::logic_error("lockstep: two fills pushed to a cache in a cycle");
        in.fill = true;
        in.fill_tag = static_cast<std::uint32_t>(e.field[0]);
        for (int k = 0; k + 1 < e.fields; ++k)
          in.fill_words[static_cast<std::size_t>(k)] =
              static_cast<std::uint32_t>(e.field[static_cast<std::size_t>(k) + 1]);
      } else {
        throw std::logic_error(std::string("lockstep: a ") + units::boundary_port_name(e.port) +
                               " event given to a cache as an input");
      }
    }
    return in;
  }

  std::unique_ptr<CacheRtl> rtl_;
  units::UnitId unit_;
  CacheSizes config_;
};

}  // namespace

void add_cache_outputs(std::vector<units::BoundaryEvent>& outputs, std::uint64_t cycle,
                       units::UnitId unit, int words, const CacheOutputs& out) {
  using units::BoundaryPort;
  const auto add = [&](BoundaryPort port, std::uint32_t thread, int fields,
                       const char* const* names) -> units::BoundaryEvent& {
    units::BoundaryEvent& e = add_event(outputs, cycle, unit, port, thread);
    e.cache = true;
    e.fields = fields;
    e.names = names;
    return e;
  };
  if (out.accept)
    add(BoundaryPort::kCacheAccept, out.acc_tag, 5, units::kCacheAcceptFields).field = {
        out.acc_index, out.acc_requester, out.acc_tag, out.acc_kind, out.acc_mshr};
  if (out.resp) {
    units::BoundaryEvent& e =
        add(BoundaryPort::kCacheReply, out.resp_tag, 3 + words, units::kCacheReplyFields);
    e.field = {out.resp_index, out.resp_requester, out.resp_tag};
    for (int k = 0; k < words; ++k)
      e.field[3 + static_cast<std::size_t>(k)] = out.resp_words[static_cast<std::size_t>(k)];
  }
  if (out.mreq)
    add(BoundaryPort::kMemRequest, 0, 4, units::kMemRequestFields).field = {
        out.mreq_tag, out.mreq_bank, out.mreq_offset, out.mreq_words};
}

const std::vector<CacheBuild>& cache_builds() {
  static const std::vector<CacheBuild> b = {
#define SAARCOR_CACHE_BUILD(id, cls, items, ways, words, hit, misses, targets, rq, mq, fault) \
  {#id, items, ways, words, hit, misses, targets, rq, mq, fault},
      SAARCOR_CACHE_BUILDS(SAARCOR_CACHE_BUILD)
#undef SAARCOR_CACHE_BUILD
  };
  return b;
}

std::unique_ptr<CacheRtl> make_cache_rtl(const CacheBuild& build) {
#define SAARCOR_CACHE_BUILD(id, cls, items, ways, words, hit, misses, targets, rq, mq, fault) \
  if (build.name == #id) return std::make_unique<CacheRtlOf<cls>>(build);
  SAARCOR_CACHE_BUILDS(SAARCOR_CACHE_BUILD)
#undef SAARCOR_CACHE_BUILD
  throw std::runtime_error("no Verilated cache build named '" + build.name + "'");
}

std::unique_ptr<UnitRtl> make_cache_unit_rtl(const CacheBuild& build, units::UnitId unit,
                                             const CacheSizes& config) {
  return std::make_unique<CacheUnitRtl>(build, unit, config);
}

}  // namespace saarcor::rtl
