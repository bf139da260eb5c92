// The Verilated mailboxed list unit (rtl/list_unit.sv) behind one interface, whichever of its
// builds (each parameter set is one Verilator build, rtl/CMakeLists.txt SAARCOR_LIST_BUILDS):
// one clock cycle per call, the inputs of that cycle in, the outputs of that cycle out.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rtl/unit_rtl.h"

namespace saarcor::rtl {

// A Verilated build of list_unit.sv: its SystemVerilog parameters.
struct ListBuild {
  std::string name;
  int threads = 0, packet = 0, mailbox = 0, triangle_mailbox = 0, depth = 0;
  int fault = 0;  // the injected fault (tests only): 1 mailbox never hits, 2 priorities swapped
};
const std::vector<ListBuild>& list_builds();

// One cycle's inputs: threads arriving on the three paths (0 the unit's loop, 1 from the
// intersection unit, 2 from the traversal unit), packet starts, the cache's ready and response.
struct ListInputs {
  std::array<bool, 3> valid{}, start{}, level{};
  std::array<std::uint32_t, 3> thread{}, next{}, end{};
  std::array<std::uint64_t, 3> mask{};
  std::array<bool, 2> clear{};
  std::array<std::uint32_t, 2> clear_thread{};
  bool req_ready = true;
  bool resp = false;
  std::uint32_t resp_thread = 0, resp_word = 0;
};

struct ListOutputs {
  bool req = false;  // a cache request went out (valid and ready)
  std::uint32_t req_item = 0, req_thread = 0;
  bool out = false;
  std::uint32_t out_thread = 0, kind = 0, level = 0, next = 0, entry = 0;
  std::uint64_t mask = 0;
  std::uint64_t list = 0;  // kind 0: the level's rays still in the list
  bool last = false;       // kind 0: the entry was the list's last
};

class ListRtl {
 public:
  virtual ~ListRtl() = default;
  // Two reset cycles; the next cycle() is cycle 0.
  virtual void reset() = 0;
  virtual ListOutputs cycle(const ListInputs& in) = 0;
  // VCD of the cycles from now until stop_trace() (or destruction) into `path`.
  virtual void start_trace(const std::string& path) = 0;
  virtual void stop_trace() = 0;
};

std::unique_ptr<ListRtl> make_list_rtl(const ListBuild& build);

// The list unit behind the lockstep's interface: the boundary record's list payloads
// (units/boundary_list.h) to and from its ports. Inputs: the paths from the list unit itself,
// the intersection unit and the traversal unit (ports 0, 1, 2), up to two packet starts, the
// cache response's word, the cache's back-pressure.
std::unique_ptr<UnitRtl> make_list_unit_rtl(const ListBuild& build);

}  // namespace saarcor::rtl
