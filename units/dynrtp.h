// The cycle model of the DynRTP (paper section 3.1, Figure 2; DESIGN.md sections 5, 6 and 9 model
// 3): the traversal, mailboxed list, transformation and intersection units, the ray source and
// hit sink, the thread table and the memory interface, clocked by the hw/ kernel; one DynRTP as
// in the prototype, or several sharing the memory controller and fed by one RGC (D44).
// Bit-identical to the functional fp24 model by construction (the same thread program per thread,
// executed in the same per-thread order); the timing gives the paper's Table 4 figures.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <thread>
#include <vector>

#include "memif/host_bus.h"
#include "memif/image_format.h"
#include "memif/memory_system.h"
#include "units/cycle_params.h"
#include "units/dynrtc_units.h"
#include "units/figures.h"
#include "units/functional_model.h"
#include "units/run_trace.h"

namespace saarcor::units {

// What a unit of the DynRTP is built with: the kernel, the memory system its cache and ports are
// in, the parameters, the thread table, the RGC, its pipeline and its kernel name
// ("dynrtpN.<unit name>").
struct UnitContext {
  hw::Kernel& kernel;
  memif::MemorySystem& memory;
  const CycleParams& params;
  ThreadTable& threads;
  RayGenerationController& rgc;
  int pipeline;
  std::string name;
};

// A unit's place in the DynRTP (README "adding a unit"): its id, the units whose paths it reads in
// priority order (D25; a path nobody reads would hold its thread until the watchdog names it),
// and how it is built.
struct UnitSpec {
  UnitId id = UnitId::kNone;
  std::vector<UnitId> inputs;
  std::function<CycleUnit&(const UnitContext&)> make;
};

// Figure 2's units in the order the DynRTP builds them, with their input priorities.
std::vector<UnitSpec> dynrtc_units();

// One DynRTP: its units and a path between every two of them (a unit's own loop included), over
// its pipeline's caches in the shared memory system; its threads are ids [pipeline x threads,
// (pipeline + 1) x threads) of the table. `units` must hold the RGS (the ray source).
class DynRtp {
 public:
  DynRtp(hw::Kernel& k, memif::MemorySystem& mi, const CycleParams& p, ThreadTable& threads,
         RayGenerationController& rgc, int pipeline,
         const std::vector<UnitSpec>& units = dynrtc_units());

  RaySource& rgs() { return *rgs_; }
  const RaySource& rgs() const { return *rgs_; }
  CycleUnit& unit(UnitId u) { return *units_[static_cast<std::size_t>(unit_index(u))]; }
  void observe(UnitObserver* o) {
    for (CycleUnit* u : units_)
      if (u != nullptr) u->set_observer(o);
  }

 private:
  RaySource* rgs_ = nullptr;
  std::array<CycleUnit*, kMaxUnits> units_{};
  std::array<std::array<ThreadPath*, kMaxUnits>, kMaxUnits> paths_{};
};

// Where a simulated thread's requests come from:
enum class ProgramMode {
  kPerStep,      // a thread program per simulated thread, each step run when a unit issues it
                 // (the reference the other modes are tested against)
  kPacketFirst,  // one program runs a packet's whole request sequence when the RGC hands the
                 // packet out, the simulated thread replays it (one host thread)
  kAhead,        // the same sequences recorded on a second host thread, ahead of the simulation
};
const char* program_mode_name(ProgramMode m);  // "per-step", "packet-first", "ahead"

struct CycleRunOptions {
  FunctionalParams shading;     // shade / shadows / secondary / max_depth (packet, stack, mailbox,
                                // shared_origin come from CycleParams)
  std::uint64_t interval = 0;   // != 0: sample the figures every `interval` cycles
  std::ostream* vcd = nullptr;  // VCD trace of cycles [vcd_from, vcd_to]
  std::uint64_t vcd_from = 0, vcd_to = 0;
  // The request trace and the Kanata log (units/run_trace.h, docs/traces.md); neither by default.
  // Tracing changes no figure and no result (tested).
  RunTraceOptions trace;
  std::uint64_t shuffle_seed = 0;  // != 0: random module evaluation order (figures must not move)
  bool idle_skip = true;           // false: evaluate every cycle (figures must not move)
  std::uint64_t max_cycles = 0;    // != 0: stop with an error after this many cycles
  // How the thread programs run beside the simulation (docs/cycle-model.md, "Programs ahead").
  // Results and figures are the same in every mode (tested).
  ProgramMode programs =
      std::thread::hardware_concurrency() > 1 ? ProgramMode::kAhead : ProgramMode::kPacketFirst;
  // kAhead: how many finished packets the program thread may hold ahead of the simulation (>= 1).
  int ahead_packets = 192;
  std::function<void(std::uint64_t cycles, int packets_done, int packets)> progress;
};

struct CycleFrame {
  FunctionalFrame frame;  // hit records, image, per-ray counters, op counts (as the fp24 model)
  CycleParams params;
  std::uint64_t cycles = 0;
  std::uint64_t rays = 0;          // rays issued, all kinds
  double fps = 0, rays_per_s = 0;  // at the modelled clock
  CycleFigures figures;            // the whole frame (units/figures.h)
  std::array<std::uint64_t, kTable4Units> issue_cycles{}, stall_cycles{}, requests{};
  struct CacheCount {
    std::uint64_t requests = 0, hits = 0, misses = 0, merges = 0, mem_bytes = 0;
  };
  std::array<CacheCount, kCacheUnits> caches{};
  // The RGS's memory traffic over the frame (docs/shading.md "Shading traffic"): shading-bank
  // bytes read (records, materials, texels, lights) and frame-buffer bytes written.
  std::uint64_t shading_bytes = 0, frame_bytes = 0;
  double shading_bytes_per_pixel = 0;   // (shading + frame bytes) / pixels
  int frame_bank = memif::kFrameBank0;  // the bank the frame was written into
  // Per DynRTP: the packets the RGC handed it and its units' issue cycles (the load balance).
  struct PipelineCount {
    std::uint64_t packets = 0;
    std::array<std::uint64_t, kTable4Units> issue_cycles{};
  };
  std::vector<PipelineCount> per_pipeline;
  RayCounters per_ray_sum;     // all kinds
  double simd_efficiency = 0;  // active rays per traversal packet step / P
  std::uint64_t packets = 0, packets_retired = 0;
  double host_seconds = 0, sim_cycles_per_s = 0;  // wall clock
  int host_threads = 1;                           // 2: the thread programs ran ahead
  ProgramMode programs = ProgramMode::kPerStep;
  std::uint64_t skipped_cycles = 0;
  std::uint64_t module_evaluations = 0;  // host work: evaluate() calls (sleeping modules skip)
  std::vector<CycleFigures> series;      // with interval != 0: the figures of each interval
  std::string stats_json;                // the hw/ statistics registry
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
// The functional parameters a thread program of a cycle-model run with `p` gets: `shading`'s
// RGS settings with the packet, stack, mailboxes, clip and traversal rules of `p`. The functional
// model run with them is the cycle model's bit-exact reference.
FunctionalParams functional_params(const CycleParams& p, FunctionalParams shading = {});

CycleFrame run_cycle(const memif::MemoryImage& image, const CycleParams& params,
                     const CycleRunOptions& options = {});

// The same frame while the host uploads the next frame's changes over the host bus (paper
// section 5: "uploading changes to the scene between frames ... can be performed in parallel to
// rendering"; docs/frames.md): the upload's words reach `image` through the memory controller,
// competing with the frame's reads for the banks; its registers take bus time and go to no bank.
// Throws std::runtime_error (one line naming the range) before the first cycle when a run of the
// upload overlaps upload.frame_reads: writing what the frame in flight reads is refused.
CycleFrame run_cycle(memif::MemoryImage& image, const CycleParams& params,
                     const CycleRunOptions& options, const memif::HostUpload& upload);

}  // namespace saarcor::units
