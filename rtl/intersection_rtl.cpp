// The Verilated intersection unit builds (rtl/intersection_rtl.h). The builds and their
// parameters come from one list in rtl/CMakeLists.txt, which generates rtl_intersection_builds.h
// (the Verilated headers and the table below) and passes the same values to Verilator as -G
// parameters.
#include "rtl/intersection_rtl.h"

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "rtl/port_bits.h"
#include "rtl/unit_ports.h"
#include "rtl/verilated_top.h"
#include "rtl_intersection_builds.h"
#include "units/boundary_intersection.h"
#include "verilated.h"

namespace saarcor::rtl {
namespace {

using units::BoundaryEvent;
using units::BoundaryPort;
using units::UnitId;

constexpr int kW = kPortFloatBits;

template <class V>
class IntersectionRtlOf final : public UnitRtl {
 public:
  explicit IntersectionRtlOf(const IntersectionBuild& b)
      : tw_(thread_bits(b.threads)), p_(b.packet) {}

  UnitId unit() const override { return UnitId::kIntersection; }
  void reset() override { top_.reset(); }

  void cycle(std::uint64_t cycle, const std::vector<BoundaryEvent>& inputs,
             std::vector<BoundaryEvent>& outputs) override {
    V& v = *top_;
    v.in_valid = 0;
    v.st_valid = 0;
    int starts = 0;
    for (const BoundaryEvent& e : inputs) {
      if (e.port == BoundaryPort::kInput) {
        arrive(e);
      } else if (e.port == BoundaryPort::kSideBand) {
        drive_packet_start(v, starts++, tw_, e);
      } else {
        throw std::logic_error(std::string("lockstep: the intersection unit has no ") +
                               units::boundary_port_name(e.port) + " input");
      }
    }
    top_.fall();
    if (v.out_valid) leaving(outputs, cycle);
    top_.rise();
  }

  void start_trace(const std::string& path) override { top_.start_trace(path); }
  void stop_trace() override { top_.stop_trace(); }

 private:
  // A thread on path e with the triangle's rays in unit-triangle space.
  void arrive(const BoundaryEvent& e) {
    V& v = *top_;
    if (e.path != UnitId::kTransformation)
      throw std::logic_error(std::string("lockstep: a thread reached the intersection unit from "
                                         "the ") +
                             units::unit_name(e.path) + " unit, which has no path to it");
    if (v.in_valid) throw std::logic_error("lockstep: two threads on path e in a cycle");
    const auto words = static_cast<std::size_t>(p_ * units::kIntersectionRayWords);
    if (e.fields != 5 || e.wide.size() != words)
      throw std::logic_error("lockstep: a triangle without its " + std::to_string(words) +
                             " words for the intersection unit");
    v.in_valid = 1;
    v.in_thread = static_cast<std::remove_reference_t<decltype(v.in_thread)>>(e.thread);
    put_bits(v.in_mask, 0, p_, e.field[0]);
    put_bits(v.in_list, 0, p_, e.field[1]);
    v.in_last = e.field[2] != 0;
    v.in_instance = static_cast<std::uint32_t>(e.field[3]);
    v.in_triangle = static_cast<std::uint32_t>(e.field[4]);
    for (int i = 0; i < p_; ++i)
      for (int a = 0; a < 3; ++a) {
        const auto w = static_cast<std::size_t>(i * units::kIntersectionRayWords + a);
        put_bits(v.in_o, (3 * i + a) * kW, kW, e.wide[w]);
        put_bits(v.in_d, (3 * i + a) * kW, kW, e.wide[w + 3]);
      }
  }

  // The thread leaving on path f with every lane's closest hit.
  void leaving(std::vector<BoundaryEvent>& out, std::uint64_t cycle) const {
    V& v = *top_;
    add_intersection_output(out, cycle, p_, static_cast<std::uint32_t>(v.out_thread), v.out_dest,
                            get_bits(v.out_mask, 0, p_), get_bits(v.out_done, 0, p_), v.out_t,
                            v.out_u, v.out_v, v.out_c, v.out_instance, v.out_triangle);
  }

  int tw_, p_;
  VerilatedTop<V> top_;
};

}  // namespace

const std::vector<IntersectionBuild>& intersection_builds() {
  static const std::vector<IntersectionBuild> b = {
#define SAARCOR_INTERSECTION_BUILD(id, cls, threads, packet, add, mul, div, cmp, fault) \
  {#id, threads, packet, add, mul, div, cmp, fault},
      SAARCOR_INTERSECTION_BUILDS(SAARCOR_INTERSECTION_BUILD)
#undef SAARCOR_INTERSECTION_BUILD
  };
  return b;
}

std::unique_ptr<UnitRtl> make_intersection_unit_rtl(const IntersectionBuild& build) {
#define SAARCOR_INTERSECTION_BUILD(id, cls, threads, packet, add, mul, div, cmp, fault) \
  if (build.name == #id) return std::make_unique<IntersectionRtlOf<cls>>(build);
  SAARCOR_INTERSECTION_BUILDS(SAARCOR_INTERSECTION_BUILD)
#undef SAARCOR_INTERSECTION_BUILD
  throw std::runtime_error("no Verilated intersection unit build named '" + build.name + "'");
}

}  // namespace saarcor::rtl
