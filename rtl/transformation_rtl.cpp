// The Verilated transformation unit builds (rtl/transformation_rtl.h). The builds and their
// parameters come from one list in rtl/CMakeLists.txt, which generates
// rtl_transformation_builds.h (the Verilated headers and the table below) and passes the same
// values to Verilator as -G parameters.
#include "rtl/transformation_rtl.h"

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "rtl/port_bits.h"
#include "rtl/verilated_top.h"
#include "rtl_transformation_builds.h"
#include "units/boundary_transformation.h"
#include "verilated.h"

namespace saarcor::rtl {
namespace {

using units::BoundaryEvent;
using units::BoundaryPort;
using units::UnitId;

constexpr int kW = 24;  // fp24: the builds' float format

template <class V>
class TransformationRtlOf final : public UnitRtl {
 public:
  TransformationRtlOf(const TransformationBuild& b, const memif::FrameRegisters& frame)
      : p_(b.packet) {
    top_->instance_row_base = frame.instance_row_base;
  }

  UnitId unit() const override { return UnitId::kTransformation; }
  void reset() override { top_.reset(); }

  void cycle(std::uint64_t cycle, const std::vector<BoundaryEvent>& inputs,
             std::vector<BoundaryEvent>& outputs) override {
    V& v = *top_;
    v.d_valid = 0;
    v.a_valid = 0;
    v.resp_valid = 0;
    v.req_ready = 1;
    for (const BoundaryEvent& e : inputs)
      drive(e);
    top_.fall();
    if (v.req_valid && v.req_ready)
      add_cache_request(outputs, cycle, UnitId::kTransformation, v.req_item,
                        static_cast<std::uint32_t>(v.req_thread));
    if (v.out_valid) leaving(outputs, cycle);
    top_.rise();
  }

  void start_trace(const std::string& path) override { top_.start_trace(path); }
  void stop_trace() override { top_.stop_trace(); }

 private:
  void drive(const BoundaryEvent& e) {
    V& v = *top_;
    switch (e.port) {
      case BoundaryPort::kInput:
        return e.path == UnitId::kList ? entry(e) : generate(e);
      case BoundaryPort::kCacheBlocked:
        v.req_ready = 0;
        return;
      case BoundaryPort::kCacheResponse:
        if (v.resp_valid) throw std::logic_error("lockstep: two row responses in a cycle");
        v.resp_valid = 1;
        v.resp_thread = static_cast<std::remove_reference_t<decltype(v.resp_thread)>>(e.thread);
        v.resp_item = static_cast<std::uint32_t>(e.field[0]);
        for (int k = 0; k < 3; ++k)
          put_bits(v.resp_words, 32 * k, 32, e.field[static_cast<std::size_t>(k) + 1]);
        return;
      default:
        throw std::logic_error(std::string("lockstep: the transformation unit has no ") +
                               units::boundary_port_name(e.port) + " input");
    }
  }

  // Path d: an object or a triangle.
  void entry(const BoundaryEvent& e) {
    V& v = *top_;
    if (v.d_valid) throw std::logic_error("lockstep: two threads on path d in a cycle");
    if (e.fields != 6 || e.field[0] != 0)
      throw std::logic_error("lockstep: a list entry without its fields on path d");
    v.d_valid = 1;
    v.d_thread = static_cast<std::remove_reference_t<decltype(v.d_thread)>>(e.thread);
    v.d_kind = e.field[1] != 0;
    v.d_entry = static_cast<std::uint32_t>(e.field[2]);
    put_bits(v.d_mask, 0, p_, e.field[3]);
    put_bits(v.d_list, 0, p_, e.field[4]);
    v.d_last = e.field[5] != 0;
  }

  // Path a: a packet to generate, per lane T, R'o, R'd.
  void generate(const BoundaryEvent& e) {
    V& v = *top_;
    if (e.path != UnitId::kRgs)
      throw std::logic_error(std::string("lockstep: a thread reached the transformation unit "
                                         "from the ") +
                             units::unit_name(e.path) + " unit, which has no path to it");
    if (v.a_valid) throw std::logic_error("lockstep: two threads on path a in a cycle");
    constexpr int kWords = units::kTransformationGenerateWords;
    if (e.fields != 4 || e.wide.size() != static_cast<std::size_t>(p_ * kWords))
      throw std::logic_error("lockstep: a packet without its " + std::to_string(p_ * kWords) +
                             " words on path a");
    v.a_valid = 1;
    v.a_thread = static_cast<std::remove_reference_t<decltype(v.a_thread)>>(e.thread);
    v.a_shadow = e.field[1] != 0;
    v.a_shared = e.field[2] != 0;
    put_bits(v.a_valid_lanes, 0, p_, e.field[3]);
    for (int i = 0; i < p_; ++i) {
      const std::uint32_t* w = &e.wide[static_cast<std::size_t>(i * kWords)];
      for (int k = 0; k < 12; ++k)
        put_bits(v.a_t, (12 * i + k) * kW, kW, w[k]);
      for (int a = 0; a < 3; ++a) {
        put_bits(v.a_ro, (3 * i + a) * kW, kW, w[12 + a]);
        put_bits(v.a_rd, (3 * i + a) * kW, kW, w[15 + a]);
      }
    }
  }

  // The thread leaving with its transformed rays (an object's box after them).
  void leaving(std::vector<BoundaryEvent>& out, std::uint64_t cycle) const {
    V& v = *top_;
    constexpr UnitId kTo[] = {UnitId::kTraversal, UnitId::kIntersection, UnitId::kRgs,
                              UnitId::kRgs};
    BoundaryEvent& e =
        add_event(out, cycle, UnitId::kTransformation, BoundaryPort::kOutput, v.out_thread);
    e.path = kTo[v.out_dest & 3u];
    e.fields = 10;
    e.names = units::kTransformationOutputFields;
    e.field = {v.out_dest,     v.out_level,
               v.out_shared,   get_bits(v.out_mask, 0, p_),
               v.out_root,     get_bits(v.out_list, 0, p_),
               v.out_last,     v.out_instance,
               v.out_triangle, v.out_shadow};
    for (int i = 0; i < p_; ++i) {
      for (int a = 0; a < 3; ++a)
        e.wide.push_back(static_cast<std::uint32_t>(get_bits(v.out_o, (3 * i + a) * kW, kW)));
      for (int a = 0; a < 3; ++a)
        e.wide.push_back(static_cast<std::uint32_t>(get_bits(v.out_d, (3 * i + a) * kW, kW)));
    }
    if (!v.out_level) return;
    for (int a = 0; a < 3; ++a)
      e.wide.push_back(static_cast<std::uint32_t>(get_bits(v.out_lo, a * kW, kW)));
    for (int a = 0; a < 3; ++a)
      e.wide.push_back(static_cast<std::uint32_t>(get_bits(v.out_hi, a * kW, kW)));
  }

  int p_;
  VerilatedTop<V> top_;
};

}  // namespace

const std::vector<TransformationBuild>& transformation_builds() {
  static const std::vector<TransformationBuild> b = {
#define SAARCOR_TRANSFORMATION_BUILD(id, cls, threads, packet, add, mul, fault) \
  {#id, threads, packet, add, mul, fault},
      SAARCOR_TRANSFORMATION_BUILDS(SAARCOR_TRANSFORMATION_BUILD)
#undef SAARCOR_TRANSFORMATION_BUILD
  };
  return b;
}

std::unique_ptr<UnitRtl> make_transformation_unit_rtl(const TransformationBuild& build,
                                                      const memif::FrameRegisters& frame) {
#define SAARCOR_TRANSFORMATION_BUILD(id, cls, threads, packet, add, mul, fault) \
  if (build.name == #id) return std::make_unique<TransformationRtlOf<cls>>(build, frame);
  SAARCOR_TRANSFORMATION_BUILDS(SAARCOR_TRANSFORMATION_BUILD)
#undef SAARCOR_TRANSFORMATION_BUILD
  throw std::runtime_error("no Verilated transformation unit build named '" + build.name + "'");
}

}  // namespace saarcor::rtl
