// The chip of the cycle model instantiated and clocked (README.md "Layout": testbench/
// "instantiates the chip and clocks it"; section 9 model 3): the RGC, one DynRTP as in the
// prototype or several sharing the memory controller (D44; units/dynrtp.h), the memory system,
// and the frame loop with its figures (units/figures.h). Bit-identical to the functional fp24
// model by construction (the same thread program per thread, executed in the same per-thread
// order); the timing gives the paper's Table 4 figures.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "memif/host_bus.h"
#include "memif/image_format.h"
#include "units/cycle_params.h"
#include "units/dynrtp.h"
#include "units/figures.h"
#include "units/functional_model.h"
#include "units/run_trace.h"

namespace saarcor {

struct SampleSummary;  // testbench/sampling.h

struct CycleRunOptions {
  units::FunctionalParams shading;  // shade / shadows / secondary / max_depth (packet, stack,
                                    // mailbox, shared_origin come from units::CycleParams)
  std::uint64_t interval = 0;       // != 0: sample the figures every `interval` cycles
  std::ostream* vcd = nullptr;      // VCD trace of cycles [vcd_from, vcd_to]
  std::uint64_t vcd_from = 0, vcd_to = 0;
  // The request trace and the Kanata log (units/run_trace.h, docs/traces.md); neither by default.
  // Tracing changes no figure and no result (tested).
  units::RunTraceOptions trace;
  std::uint64_t shuffle_seed = 0;  // != 0: random module evaluation order (figures must not move)
  bool idle_skip = true;           // false: evaluate every cycle (figures must not move)
  std::uint64_t max_cycles = 0;    // != 0: stop with an error after this many cycles
  // How the thread programs run beside the simulation (docs/cycle-model.md, "Programs ahead").
  // Results and figures are the same in every mode (tested).
  units::ProgramMode programs = std::thread::hardware_concurrency() > 1
                                    ? units::ProgramMode::kAhead
                                    : units::ProgramMode::kPacketFirst;
  // kAhead: how many finished packets the program thread may hold ahead of the simulation (>= 1).
  int ahead_packets = 192;
  std::function<void(std::uint64_t cycles, int packets_done, int packets)> progress;
  // A sampled frame (testbench/sampling.h): the packets the RGC hands out, in its order (empty:
  // the whole frame in tiling order), and the hand-out counts (ascending) at which the chip's
  // counts are read into CycleFrame::marks: mark m is read once m packets have been handed out.
  std::vector<int> packet_order;
  std::vector<int> marks;
  // A sampled frame: charge each packet its share of the cycles (units::PacketCharges) into
  // CycleFrame::packet_charges.
  bool charge_packets = false;
};

struct CycleFrame {
  units::FunctionalFrame
      frame;  // hit records, image, per-ray counters, op counts (as the fp24 model)
  units::CycleParams params;
  std::uint64_t cycles = 0;
  std::uint64_t rays = 0;          // rays issued, all kinds
  double fps = 0, rays_per_s = 0;  // at the modelled clock
  units::CycleFigures figures;     // the whole frame (units/figures.h)
  std::array<std::uint64_t, units::kTable4Units> issue_cycles{}, stall_cycles{}, requests{};
  struct CacheCount {
    std::uint64_t requests = 0, hits = 0, misses = 0, merges = 0, mem_bytes = 0;
  };
  std::array<CacheCount, units::kCacheUnits> caches{};
  // The RGS's memory traffic over the frame (docs/shading.md "Shading traffic"): shading-bank
  // bytes read (records, materials, texels, lights) and frame-buffer bytes written.
  std::uint64_t shading_bytes = 0, frame_bytes = 0;
  double shading_bytes_per_pixel = 0;   // (shading + frame bytes) / pixels
  int frame_bank = memif::kFrameBank0;  // the bank the frame was written into
  // Per DynRTP: the packets the RGC handed it and its units' issue cycles (the load balance).
  struct PipelineCount {
    std::uint64_t packets = 0;
    std::array<std::uint64_t, units::kTable4Units> issue_cycles{};
  };
  std::vector<PipelineCount> per_pipeline;
  units::RayCounters per_ray_sum;  // all kinds
  double simd_efficiency = 0;      // active rays per traversal packet step / P
  std::uint64_t packets = 0, packets_retired = 0;
  double host_seconds = 0, sim_cycles_per_s = 0;  // wall clock
  int host_threads = 1;                           // 2: the thread programs ran ahead
  units::ProgramMode programs = units::ProgramMode::kPerStep;
  std::uint64_t skipped_cycles = 0;
  std::uint64_t module_evaluations = 0;     // host work: evaluate() calls (sleeping modules skip)
  std::vector<units::CycleFigures> series;  // with interval != 0: the figures of each interval
  std::vector<units::FigureCounts> marks;   // the counts at CycleRunOptions::marks
  // With CycleRunOptions::charge_packets: the cycles charged to each handed-out packet, by
  // hand-out ordinal (units::PacketCharges), and the cycles in which no packet was in flight.
  std::vector<double> packet_charges;
  std::uint64_t uncharged_cycles = 0;
  // A sampled frame (testbench/sampling.h): how it was sampled and each estimate's interval; the
  // figures above are then the estimates. Null for a frame simulated whole.
  std::shared_ptr<const SampleSummary> sampling;
  std::string stats_json;  // the hw/ statistics registry
  // With a host upload (run_cycle with a memif::HostUpload): the bytes it sent over the host bus
  // (SRAM words and registers) and the cycle by which its last word was stored, counted from the
  // frame's start like `cycles`; it exceeds `cycles` when the upload outlasts the frame, and the
  // run then goes on until it is done. The figures above are the frame's alone.
  std::uint64_t upload_bytes = 0;
  std::uint64_t upload_cycles = 0;
};

// Renders the image's frame: an fp24 image (the prototype), or e7m23 (the same units 31 bits wide,
// for the width study), on a copy of `image` (the chip's memory: the RGS writes the frame into its
// back frame-buffer bank, FrameRegisters::frame_bank). The frame's image (frame.rgb) is read back
// from that bank: the words the hardware wrote. Throws std::runtime_error for a bad configuration
// or image (a frame-buffer bank too small for the frame), and when the watchdog fires (the message
// names every thread and where it waits).
CycleFrame run_cycle(const memif::MemoryImage& image, const units::CycleParams& params,
                     const CycleRunOptions& options = {});

// The same frame while the host uploads the next frame's changes over the host bus (paper
// section 5: "uploading changes to the scene between frames ... can be performed in parallel to
// rendering"; docs/frames.md): the upload's words reach `image` through the memory controller,
// competing with the frame's reads for the banks; its registers take bus time and go to no bank.
// Throws std::runtime_error (one line naming the range) before the first cycle when a run of the
// upload overlaps upload.frame_reads: writing what the frame in flight reads is refused.
CycleFrame run_cycle(memif::MemoryImage& image, const units::CycleParams& params,
                     const CycleRunOptions& options, const memif::HostUpload& upload);

// An upload with nothing rendering (a sequence's initial load, an upload in a frame gap): the
// chip's memory system with only its host bus busy, the words stored into `image`. Returns the
// cycles until the last word is stored (upload.frame_reads is ignored: no frame is in flight).
std::uint64_t run_upload(memif::MemoryImage& image, const units::CycleParams& params,
                         memif::HostUpload upload);

}  // namespace saarcor
