// The Verilated transformation unit with its thread machinery (rtl/transformation_threads.sv)
// behind the lockstep's interface (rtl/unit_rtl.h), whichever of its builds (each parameter set
// is one Verilator build, rtl/CMakeLists.txt SAARCOR_TRANSFORMATION_BUILDS): the boundary
// record's transformation payloads (units/boundary_transformation.h) to and from its ports, one
// clock cycle per call.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "memif/image_format.h"
#include "rtl/unit_rtl.h"

namespace saarcor::rtl {

// A Verilated build of transformation_threads.sv: its SystemVerilog parameters.
struct TransformationBuild {
  std::string name;
  int threads = 0, packet = 0, lat_add = 0, lat_mul = 0;
  int fault = 0;  // tests only: 1 the n + 1 rule off (2n steps for a shared origin too), 2 an
                  // entry's second and third rows fetched in swapped order
};
const std::vector<TransformationBuild>& transformation_builds();

// The transformation unit behind the lockstep's interface, on the frame's registers
// (instance_row_base). Inputs: path d (from the list unit: an object or a triangle), path a (from
// the RGS: a packet to generate, with its matrices and rays), the row cache's responses and
// back-pressure. Outputs: the row requests and the threads leaving for the traversal unit, the
// intersection unit or the RGS with their transformed rays.
std::unique_ptr<UnitRtl> make_transformation_unit_rtl(const TransformationBuild& build,
                                                      const memif::FrameRegisters& frame);

}  // namespace saarcor::rtl
