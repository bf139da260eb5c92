// The units' ports as boundary records (units/boundary*.h), shared by each unit's lockstep
// adapter (rtl/*_rtl.cpp, a Verilated unit alone) and the whole DynRTC's (rtl/dynrtc_rtl.cpp, the
// units wired together): what the RGS drives into a unit (path a and its side bands, the level
// start on RGS -> traversal) and what a unit's outputs say. The drivers take the Verilated top,
// whose boundary ports carry the unit's names in both; the output records take the port values,
// which the whole DynRTC brings out under a unit prefix.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "rtl/cache_rtl.h"
#include "rtl/list_rtl.h"
#include "rtl/port_bits.h"
#include "rtl/unit_rtl.h"
#include "units/boundary.h"
#include "units/boundary_cache.h"
#include "units/boundary_intersection.h"
#include "units/boundary_list.h"
#include "units/boundary_transformation.h"
#include "units/boundary_traversal.h"

namespace saarcor::rtl {

inline constexpr int kPortFloatBits = 24;  // fp24: the builds' float format
inline constexpr int kPortNodeBits = 28;   // NODE_W

// ---- inputs ------------------------------------------------------------------------------------

// A model event the whole DynRTC takes at its boundary (rtl/dynrtc.sv): the RGS's hand-overs
// (path a, RGS -> traversal) and path a's side bands (the traversal unit's hit update is the
// intersection unit's output there), and the memory controller port's events. Every other input
// is another RTL unit's or cache's output, wired inside.
inline bool at_dynrtc_boundary(const units::BoundaryEvent& e) {
  switch (e.port) {
    case units::BoundaryPort::kInput:
      return e.path == units::UnitId::kRgs;
    case units::BoundaryPort::kSideBand:
      return e.unit != units::UnitId::kTraversal;
    case units::BoundaryPort::kPortResponse:
    case units::BoundaryPort::kPortBlocked:
      return true;
    default:
      return false;
  }
}

// The traversal unit's load port k (0: path b, 1: RGS -> traversal): the level start's fields
// and the lanes' rays (units/boundary_traversal.h), in the cycle the thread is pushed.
template <class V>
void drive_level_start(V& v, int k, int tw, int p, const units::BoundaryEvent& e) {
  constexpr int kW = kPortFloatBits, kRay = 3 * kPortFloatBits;
  const bool bottom = e.field[1] != 0;
  const std::size_t words =
      static_cast<std::size_t>(p * units::kTraversalLaneWords) + (bottom ? 6u : 0u);
  if (e.fields != 7 || e.field[0] != 0 || e.wide.size() != words)
    throw std::logic_error("lockstep: a level start without its " + std::to_string(words) +
                           " words for the traversal unit");
  put_bits(v.ld_valid, k, 1, 1);
  put_bits(v.ld_thread, k * tw, tw, e.thread);
  put_bits(v.ld_bottom, k, 1, e.field[1]);
  put_bits(v.ld_shadow, k, 1, e.field[2]);
  put_bits(v.ld_lane_valid, k * p, p, e.field[3]);
  put_bits(v.ld_done, k * p, p, e.field[4]);
  put_bits(v.ld_mask, k * p, p, e.field[5]);
  put_bits(v.ld_root, k * kPortNodeBits, kPortNodeBits, e.field[6]);
  for (int i = 0; i < p; ++i) {
    const std::uint32_t* w = &e.wide[static_cast<std::size_t>(i * units::kTraversalLaneWords)];
    const int lane = (k * p + i) * kRay;
    for (int a = 0; a < 3; ++a) {
      put_bits(v.ld_o, lane + a * kW, kW, w[a]);
      put_bits(v.ld_d, lane + a * kW, kW, w[3 + a]);
    }
    put_bits(v.ld_tbest, (k * p + i) * kW, kW, w[6]);
  }
  const std::size_t box = static_cast<std::size_t>(p * units::kTraversalLaneWords);
  for (int a = 0; a < 3; ++a) {
    const auto s = static_cast<std::size_t>(a);
    put_bits(v.ld_lo, k * kRay + a * kW, kW, bottom ? e.wide[box + s] : 0);
    put_bits(v.ld_hi, k * kRay + a * kW, kW, bottom ? e.wide[box + 3 + s] : 0);
  }
}

// Path a into the transformation unit: a packet to generate, per lane T, R'o, R'd.
template <class V>
void drive_generate(V& v, int p, const units::BoundaryEvent& e) {
  constexpr int kW = kPortFloatBits;
  if (e.path != units::UnitId::kRgs)
    throw std::logic_error(std::string("lockstep: a thread reached the transformation unit "
                                       "from the ") +
                           units::unit_name(e.path) + " unit, which has no path to it");
  if (v.a_valid) throw std::logic_error("lockstep: two threads on path a in a cycle");
  constexpr int kWords = units::kTransformationGenerateWords;
  if (e.fields != 4 || e.wide.size() != static_cast<std::size_t>(p * kWords))
    throw std::logic_error("lockstep: a packet without its " + std::to_string(p * kWords) +
                           " words on path a");
  v.a_valid = 1;
  put_bits(v.a_thread, 0, 32, e.thread);
  v.a_shadow = e.field[1] != 0;
  v.a_shared = e.field[2] != 0;
  put_bits(v.a_valid_lanes, 0, p, e.field[3]);
  for (int i = 0; i < p; ++i) {
    const std::uint32_t* w = &e.wide[static_cast<std::size_t>(i * kWords)];
    for (int k = 0; k < 12; ++k)
      put_bits(v.a_t, (12 * i + k) * kW, kW, w[k]);
    for (int a = 0; a < 3; ++a) {
      put_bits(v.a_ro, (3 * i + a) * kW, kW, w[12 + a]);
      put_bits(v.a_rd, (3 * i + a) * kW, kW, w[15 + a]);
    }
  }
}

// Path a's side band into the intersection unit (a packet starts: its rays' closest hits reset),
// in slot `slot` of two.
template <class V>
void drive_packet_start(V& v, int slot, int tw, const units::BoundaryEvent& e) {
  if (slot == 2) throw std::logic_error("lockstep: three packet starts in one cycle");
  put_bits(v.st_valid, slot, 1, 1);
  put_bits(v.st_thread, slot * tw, tw, e.thread);
  put_bits(v.st_shadow, slot, 1, e.field[0]);
}

// The memory controller's cache port onto a routing's ports: a response pushed towards it, or
// its request channel full. Other events are not the port's (false).
template <class V>
bool drive_controller_port(V& v, const units::BoundaryEvent& e) {
  if (e.port == units::BoundaryPort::kPortBlocked) {
    v.port_blocked = 1;
    return true;
  }
  if (e.port != units::BoundaryPort::kPortResponse) return false;
  if (v.rsp_valid) throw std::logic_error("lockstep: two port responses in one cycle");
  v.rsp_valid = 1;
  v.rsp_client = static_cast<std::uint16_t>(e.field[0]);
  put_bits(v.rsp_tag, 0, 32, e.field[1]);
  for (int k = 0; k + 2 < e.fields; ++k)
    put_bits(v.rsp_words, 32 * k, 32, e.field[static_cast<std::size_t>(k) + 2]);
  return true;
}

// ---- outputs -----------------------------------------------------------------------------------

// The traversal unit's thread leaving on an output port: {node, first, end, mask, level} after
// the destination (0 its loop, 1 a leaf, 2 the top level's list, 3 the RGS).
inline void add_traversal_output(std::vector<units::BoundaryEvent>& out, std::uint64_t cycle,
                                 std::uint32_t thread, std::uint32_t dest,
                                 const std::array<std::uint64_t, 5>& f) {
  using units::UnitId;
  constexpr UnitId kTo[] = {UnitId::kTraversal, UnitId::kList, UnitId::kList, UnitId::kRgs};
  units::BoundaryEvent& e =
      add_event(out, cycle, UnitId::kTraversal, units::BoundaryPort::kOutput, thread);
  e.path = kTo[dest & 3u];
  e.fields = 6;
  e.names = units::kTraversalOutputFields;
  e.field = {dest, f[0], f[1], f[2], f[3], f[4]};
}

// The list unit's cache request and leaving thread.
inline void add_list_outputs(std::vector<units::BoundaryEvent>& out, std::uint64_t cycle,
                             const ListOutputs& o) {
  using units::UnitId;
  if (o.req) add_cache_request(out, cycle, UnitId::kList, o.req_item, o.req_thread);
  if (!o.out) return;
  units::BoundaryEvent& e =
      add_event(out, cycle, UnitId::kList, units::BoundaryPort::kOutput, o.out_thread);
  constexpr UnitId kTo[] = {UnitId::kTransformation, UnitId::kList, UnitId::kTraversal};
  e.path = kTo[o.kind < 2 ? o.kind : 2];
  e.fields = 7;
  e.names = units::kListOutputFields;
  e.field = {o.kind, o.level, o.next, o.entry, o.mask, o.list, o.last};
}

// The transformation unit's leaving thread with its transformed rays (an object's box after
// them): the output ports' values.
template <class Rays, class Box>
void add_transformation_output(std::vector<units::BoundaryEvent>& out, std::uint64_t cycle, int p,
                               std::uint32_t thread, const std::array<std::uint64_t, 10>& f,
                               const Rays& o, const Rays& d, const Box& lo, const Box& hi) {
  using units::UnitId;
  constexpr int kW = kPortFloatBits;
  constexpr UnitId kTo[] = {UnitId::kTraversal, UnitId::kIntersection, UnitId::kRgs, UnitId::kRgs};
  units::BoundaryEvent& e =
      add_event(out, cycle, UnitId::kTransformation, units::BoundaryPort::kOutput, thread);
  e.path = kTo[f[0] & 3u];
  e.fields = 10;
  e.names = units::kTransformationOutputFields;
  for (std::size_t k = 0; k < f.size(); ++k)
    e.field[k] = f[k];
  for (int i = 0; i < p; ++i) {
    for (int a = 0; a < 3; ++a)
      e.wide.push_back(static_cast<std::uint32_t>(get_bits(o, (3 * i + a) * kW, kW)));
    for (int a = 0; a < 3; ++a)
      e.wide.push_back(static_cast<std::uint32_t>(get_bits(d, (3 * i + a) * kW, kW)));
  }
  if (f[1] == 0) return;  // an object's level start carries the box
  for (int a = 0; a < 3; ++a)
    e.wide.push_back(static_cast<std::uint32_t>(get_bits(lo, a * kW, kW)));
  for (int a = 0; a < 3; ++a)
    e.wide.push_back(static_cast<std::uint32_t>(get_bits(hi, a * kW, kW)));
}

// The intersection unit's leaving thread with every lane's closest hit: the output ports' values.
template <class Floats, class Ids>
void add_intersection_output(std::vector<units::BoundaryEvent>& out, std::uint64_t cycle, int p,
                             std::uint32_t thread, std::uint32_t dest, std::uint64_t mask,
                             std::uint64_t done, const Floats& t, const Floats& u, const Floats& v,
                             const Floats& c, const Ids& instance, const Ids& triangle) {
  using units::UnitId;
  constexpr int kW = kPortFloatBits;
  units::BoundaryEvent& e =
      add_event(out, cycle, UnitId::kIntersection, units::BoundaryPort::kOutput, thread);
  e.path = dest != 0 ? UnitId::kTraversal : UnitId::kList;
  e.fields = 3;
  e.names = units::kIntersectionOutputFields;
  e.field[0] = dest;
  e.field[1] = mask;
  e.field[2] = done;
  for (int i = 0; i < p; ++i) {
    for (const Floats* x : {&t, &u, &v, &c})
      e.wide.push_back(static_cast<std::uint32_t>(get_bits(*x, i * kW, kW)));
    e.wide.push_back(static_cast<std::uint32_t>(get_bits(instance, i * 32, 32)));
    e.wide.push_back(static_cast<std::uint32_t>(get_bits(triangle, i * 32, 32)));
  }
}

// A cache's lookup, reply and line request of a cycle (`words`: its item's).
void add_cache_outputs(std::vector<units::BoundaryEvent>& out, std::uint64_t cycle,
                       units::UnitId unit, int words, const CacheOutputs& o);

}  // namespace saarcor::rtl
