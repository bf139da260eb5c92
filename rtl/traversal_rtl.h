// The Verilated traversal unit with its thread machinery (rtl/traversal_threads.sv) behind the
// lockstep's interface (rtl/unit_rtl.h), whichever of its builds (each parameter set is one
// Verilator build, rtl/CMakeLists.txt SAARCOR_TRAVERSAL_BUILDS): the boundary record's traversal
// payloads (units/boundary_traversal.h) to and from its ports, one clock cycle per call.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "memif/image_format.h"
#include "rtl/unit_rtl.h"

namespace saarcor::rtl {

// A Verilated build of traversal_threads.sv: its SystemVerilog parameters.
struct TraversalBuild {
  std::string name;
  int threads = 0, packet = 0, stack = 0, lat_add = 0, lat_div = 0, lat_cmp = 0;
  int fault = 0;  // tests only: 1 a stack pop one entry off, 2 a pipeline one cycle short, 3 the
                  // priorities of f and b swapped
};
const std::vector<TraversalBuild>& traversal_builds();

// Tests: the stack size of a thread in the Verilated unit (traversal_threads' dbg port), as the
// last cycle left it.
class TraversalStackProbe {
 public:
  virtual ~TraversalStackProbe() = default;
  virtual int stack_size(std::uint32_t thread) = 0;
};

// The traversal unit behind the lockstep's interface, on the frame's registers (scene box, top
// root). Inputs: the paths f (from the intersection unit), list -> traversal, RGS -> traversal
// (with its level start on load port 1) and b (load port 0); the unit's own loop is its own (the
// model's loop events are not driven); the hit update; the cache's response words and
// back-pressure. Outputs: cache requests and the threads leaving on either output port. The
// object it returns is also a TraversalStackProbe.
std::unique_ptr<UnitRtl> make_traversal_unit_rtl(const TraversalBuild& build,
                                                 const memif::FrameRegisters& frame);

}  // namespace saarcor::rtl
