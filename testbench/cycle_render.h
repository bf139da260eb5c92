// `saarcor render --model cycle` (docs/compare.md model 3): the cycle model's options
// (--preset, --set KEY=VALUE, --interval, --vcd) and the printout in the layout of the paper's
// Table 4 (docs/cycle-model.md).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "host/tree_settings.h"

#include "memif/image_format.h"
#include "testbench/chip.h"

namespace saarcor {

struct CycleRenderOptions {
  std::string preset = "prototype";
  std::vector<std::string> set;  // KEY=VALUE overrides, applied in order after the preset
  std::uint64_t interval = 0;    // != 0: figures sampled every this many cycles
  std::string vcd;               // VCD file of cycles [vcd_from, vcd_to]
  std::uint64_t vcd_from = 0;
  std::uint64_t vcd_to = 10000;
  // 2: the thread programs run on a second host thread ahead of the simulation; 1: inline. 0: 2
  // where the machine has two cores or more. The results are the same.
  int host_threads = 0;
  // --sample [SPEC] (testbench/sampling.h): the frame sampled, its figures estimated with 95 %
  // intervals; `sample_spec` "" is the default.
  bool sample = false;
  std::string sample_spec;
  // A sampled frame's simulated packets checked against the functional model (a sweep checks
  // every point; a render checks none, sampled or not).
  bool sample_check = false;
  // Any option of the cycle model's own (the kd.* keys of --set build the trees of every model).
  bool any_given() const {
    bool cycle_keys = false;
    for (const std::string& kv : set)
      cycle_keys = cycle_keys || !host::is_tree_setting(kv);
    return preset != "prototype" || cycle_keys || interval != 0 || !vcd.empty() ||
           host_threads != 0 || sample;
  }
};

// The preset with the overrides applied and checked; throws one line naming the bad key.
units::CycleParams resolve_cycle_params(const CycleRenderOptions& opts);

// Runs the cycle model on the image (VCD written when asked; no partial VCD file on error).
// `heartbeat`: the terminal heartbeat (testbench/heartbeat.h) when stderr wants one; the sweep's
// parallel frames run without, their one heartbeat counts points.
// `trace`: the request trace and Kanata log to write (units/run_trace.h; none by default).
CycleFrame run_cycle_render(const memif::MemoryImage& image, const units::FunctionalParams& shading,
                            const CycleRenderOptions& opts, bool heartbeat = true,
                            const units::RunTraceOptions& trace = {});

// The per-frame JSON report and its statistics are written by testbench/report.h.

// One row of the paper's Table 4 (1024x768, 90 MHz, one DynRTP, 64 threads).
struct Table4Row {
  const char* scene;
  double fps;
  double usage[4];  // traversal, list, transformation, intersection (%)
  double hit[3];    // traversal, list, transformation (%)
  double bw[3];     // DynRTC, shading, total (MB/s)
};
const std::vector<Table4Row>& paper_table4();
// The paper's row to show beside a scene ("builtin:room" -> Scene6), or nullptr.
const Table4Row* paper_row_for(const std::string& scene);

// The model's figures as a Table 4 row (with cycles per packet and rays/s, which do not depend on
// the resolution), and the paper's row beneath when there is one.
std::string table4_text(const CycleFrame& frame, const std::string& scene);

}  // namespace saarcor
