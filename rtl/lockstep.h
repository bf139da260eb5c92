// The lockstep co-simulation (docs/rtl.md "The units in lockstep with the cycle model"): the cycle
// model runs a frame and the Verilated units (the traversal unit, rtl/traversal_threads.sv; the
// mailboxed list unit, rtl/list_unit.sv; the transformation unit, rtl/transformation_threads.sv;
// the intersection unit, rtl/intersection_threads.sv) run beside it, cycle by cycle, each on its
// own. In every cycle each RTL unit gets what the model's unit gets (threads arriving on its paths
// with their payload, side-band signals, the cache's back-pressure, the cache responses with the
// SRAM words: the boundary record's input events, units/boundary.h), and each of its outputs (cache
// requests, threads leaving with their payload) is compared with the model's unit's. One comparer
// per unit; events are matched `window` cycles behind the RTL's clock, so a divergence is
// classified with both sides' neighbourhood known:
//   payload  the same port, cycle and thread, other bits;
//   order    the same port and cycle, another thread;
//   timing   the same event (port, thread, bits) in another cycle;
//   missing  the model has an event the RTL does not have within the window;
//   extra    the RTL has an event the model does not have within the window.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "rtl/unit_rtl.h"
#include "units/boundary.h"

namespace saarcor::rtl {

struct LockstepOptions {
  std::string scene;  // host::load_scene spec (builtin:room, a glTF path)
  // The RTL units: traversal, list, transformation, intersection, and the caches node-cache,
  // list-cache, row-cache (`caches`: all three).
  std::vector<std::string> units{"traversal", "list"};
  int width = 32, height = 24;
  std::vector<std::string> set;  // cycle-model KEY=VALUE (and kd.* tree keys)
  bool shadows = false;
  int depth = 0;  // secondary-ray depth (0: none)
  // "" or an injected fault (tests): mailbox-never-hits (list), pop-off, short-pipeline
  // (traversal), priorities-swapped (both), strict-uv (intersection), n-plus-one-off
  // and row-out-of-order (transformation), merge-wrong-target (the caches); each unit that has
  // it runs its fault build.
  std::string fault;
  // The RTL waveform around a divergence (with several units: one file per unit, the unit's name
  // before the extension; wave_file).
  std::string wave = "lockstep_divergence.vcd";
  std::uint64_t until = 0;  // != 0: stop both sides after this cycle (replay)
  int window = 64;          // cycles between the RTL's clock and the matching
  // The RTL waveform of cycles [wave_from, wave_to] into `wave` (set by the replay).
  std::uint64_t wave_from = 0, wave_to = 0;
  bool write_wave = false;
  bool bench = false;  // also run the cycle model alone and time it (the speed beside the RTL's)
  // Tests: every event of the model's units, as it is recorded.
  std::function<void(const units::BoundaryEvent&)> model_events;
  // Tests: wraps the Verilated unit (a fault between its ports and the comparison).
  std::function<std::unique_ptr<UnitRtl>(std::unique_ptr<UnitRtl>)> wrap_rtl;
};

struct Divergence {
  std::uint64_t cycle = 0;
  int dynrtp = 0;
  std::string unit, port, field, kind;  // kind: payload, order, timing, missing, extra
  std::uint64_t model_value = 0, rtl_value = 0;
  std::uint64_t other_cycle = 0;  // timing: the RTL's cycle of the model's event (or vice versa)
};

// One RTL unit's part of a run.
struct LockstepUnit {
  std::string unit;   // "traversal", "list", "transformation", "intersection", "node-cache", ...
  std::string build;  // the Verilated build that ran
  // Per port (units::BoundaryPort): events given to the RTL (inputs) or compared (outputs).
  std::array<std::uint64_t, units::kBoundaryPorts> events{};
  std::uint64_t event(units::BoundaryPort p) const { return events[static_cast<std::size_t>(p)]; }
};

struct LockstepResult {
  bool diverged = false;
  Divergence divergence;
  std::string screen;               // the divergence screen (diverged) or the summary
  std::vector<LockstepUnit> units;  // in the order of LockstepOptions::units
  // The unit named `unit` (std::logic_error if it did not run).
  const LockstepUnit& unit(const std::string& unit) const;
  std::uint64_t cycles = 0;             // RTL cycles (the model's and the window after them)
  std::uint64_t model_cycles = 0;       // the frame's cycles in the model
  double rtl_seconds = 0, seconds = 0;  // the RTL units together; the whole co-simulation
  double model_seconds = 0;  // with LockstepOptions::bench: the model alone, the same frame
  // The frame the model's RGS wrote into the frame buffer (pixel (x, y) at y * width + x, RGB8 in
  // bits 0..23), from the hit records every compared port agreed on; empty after a divergence.
  std::vector<std::uint32_t> frame;
};

// Runs the co-simulation. Throws std::runtime_error (one line) for bad input: an unknown unit, a
// configuration no Verilated build has, a fault no unit has, an unreadable scene.
LockstepResult run_lockstep(const LockstepOptions& options);

// The waveform file of `unit` (o.wave; with several units the unit's name before its extension).
std::string wave_file(const LockstepOptions& o, const std::string& unit);

// The command line that runs `o` (for the replay line of a divergence screen).
std::string lockstep_command(const LockstepOptions& o);

}  // namespace saarcor::rtl
