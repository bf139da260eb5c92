// The whole DynRTC in RTL (rtl/dynrtc.sv: the four units, the three per-type caches and the
// simple routing, wired to each other) behind the lockstep's interface (rtl/unit_rtl.h). It takes
// only the model's events at the DynRTC's boundary: what the RGS hands over (path a into the
// transformation unit with its side bands to the list and intersection units, RGS -> traversal)
// and what the memory controller's cache port does (a response pushed towards the routing, the
// request channel full). Every other input event of the model is what another RTL unit computes
// here, so it is not driven; every unit's and cache's outputs are compared, the routing's too
// (each cache's mem_taken and mem_fill).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "memif/image_format.h"
#include "rtl/cache_rtl.h"
#include "rtl/unit_rtl.h"

namespace saarcor::rtl {

// A Verilated build of dynrtc.sv: its SystemVerilog parameters (the latencies and the caches'
// timing are the prototype's; the caches' arrays hold up to 512 items of up to 4 ways).
struct DynrtcBuild {
  std::string name;
  int threads = 0, packet = 0, stack = 0, mailbox = 0, triangle_mailbox = 0;
};
const std::vector<DynrtcBuild>& dynrtc_builds();

// The run's configuration of the DynRTC: the frame registers, each cache's size (node, list,
// row), and the controller client ids of the three caches (the routing's labels).
struct DynrtcConfig {
  memif::FrameRegisters frame;
  std::array<CacheSizes, 3> caches;
  std::array<std::uint16_t, 3> clients{};
};

// One whole DynRTC per configuration: one (with its own routing) or two (pipelines=2: one RTL
// routing over their six caches, the model's routing). name() is "dynrtc"; unit() is
// UnitId::kNone (the lockstep gives it every event of the run).
std::unique_ptr<UnitRtl> make_dynrtc_rtl(const DynrtcBuild& build,
                                         const std::vector<DynrtcConfig>& config);

}  // namespace saarcor::rtl
