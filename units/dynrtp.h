// The DynRTP of the cycle model (paper section 3.1, Figure 2; docs/cycle-model.md, docs/memif.md
// and docs/compare.md model 3): the traversal, mailboxed list, transformation and intersection
// units and the ray source, built from a list of unit specs, with a path between every two units,
// over its pipeline's caches and memory ports. testbench/chip.h instantiates the chip (one DynRTP
// as in the prototype, or several sharing the memory controller and fed by one RGC, D44) and clocks
// it.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "memif/memory_system.h"
#include "units/cycle_params.h"
#include "units/dynrtc_units.h"
#include "units/functional_model.h"

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

// The functional parameters a thread program of a cycle-model run with `p` gets: `shading`'s
// RGS settings with the packet, stack, mailboxes, clip and traversal rules of `p`. The functional
// model run with them is the cycle model's bit-exact reference.
FunctionalParams functional_params(const CycleParams& p, FunctionalParams shading = {});

}  // namespace saarcor::units
