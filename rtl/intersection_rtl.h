// The Verilated intersection unit with its thread machinery (rtl/intersection_threads.sv) behind
// the lockstep's interface (rtl/unit_rtl.h), whichever of its builds (each parameter set is one
// Verilator build, rtl/CMakeLists.txt SAARCOR_INTERSECTION_BUILDS): the boundary record's
// intersection payloads (units/boundary_intersection.h) to and from its ports, one clock cycle
// per call.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "rtl/unit_rtl.h"

namespace saarcor::rtl {

// A Verilated build of intersection_threads.sv: its SystemVerilog parameters.
struct IntersectionBuild {
  std::string name;
  int threads = 0, packet = 0, lat_add = 0, lat_mul = 0, lat_div = 0, lat_cmp = 0;
  int fault = 0;  // tests only: 1 the acceptance on u + v < 1
};
const std::vector<IntersectionBuild>& intersection_builds();

// The intersection unit behind the lockstep's interface. Inputs: path e (from the transformation
// unit, with the triangle's rays), up to two packet starts a cycle (the side band). Outputs: the
// threads leaving on path f (to the list unit or the traversal unit's pop) with their closest
// hits.
std::unique_ptr<UnitRtl> make_intersection_unit_rtl(const IntersectionBuild& build);

}  // namespace saarcor::rtl
