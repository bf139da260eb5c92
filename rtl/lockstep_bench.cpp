// Speed of the RTL in lockstep (rtl/lockstep.h) on the built-in room at 128x96, prototype
// configuration: the whole DynRTC (rtl/dynrtc.sv: the units, caches and routing wired together,
// only the RGS and the memory controller in the model) and, as the reference, the four units and
// three caches each beside the model's (fed by the model's events). Each run also times the cycle
// model alone on the same frame in the same process (LockstepOptions::bench), and prints the
// co-simulation's simulated k cycles per host second beside the model's and the ratio: the ratio
// moves with the RTL and the harness, not with the machine.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <string>
#include <vector>

#include "rtl/lockstep.h"

namespace {

using namespace saarcor;

void run(benchmark::State& state, std::vector<std::string> units, const char* what) {
  rtl::LockstepOptions o;
  o.scene = "builtin:room";
  o.units = std::move(units);
  o.width = 128;
  o.height = 96;
  o.bench = true;
  rtl::LockstepResult r;
  for (auto _ : state) {
    r = rtl::run_lockstep(o);
    if (r.diverged) state.SkipWithError("the lockstep diverged");
  }
  const double cycles = static_cast<double>(r.model_cycles);
  const double cosim = cycles / r.seconds / 1e3, model = cycles / r.model_seconds / 1e3;
  state.counters["cosim_kcps"] = cosim;
  state.counters["rtl_kcps"] = static_cast<double>(r.cycles) / r.rtl_seconds / 1e3;
  state.counters["model_kcps"] = model;
  state.counters["model_over_cosim"] = model / cosim;
  std::printf(
      "%s, room 128x96, %.0f cycles: co-simulation %.0f k cycles/s, the RTL alone %.0f k, "
      "the cycle model alone %.0f k (%.1fx the co-simulation)\n",
      what, cycles, cosim, static_cast<double>(r.cycles) / r.rtl_seconds / 1e3, model,
      model / cosim);
}

void BM_WholeDynrtcLockstep(benchmark::State& state) {
  run(state, {"dynrtc"}, "whole DynRTC");
}
BENCHMARK(BM_WholeDynrtcLockstep)->Unit(benchmark::kSecond)->Iterations(1);

void BM_UnitsBesideTheModelLockstep(benchmark::State& state) {
  run(state, {"traversal", "list", "transformation", "intersection", "caches"},
      "units and caches beside the model's");
}
BENCHMARK(BM_UnitsBesideTheModelLockstep)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
