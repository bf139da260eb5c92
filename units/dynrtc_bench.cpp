// Speed of the cycle model (units/dynrtp.h) on the built-in room, 512x384 primary rays, prototype
// configuration, with the functional fp24 model on the same image and frame in the same run as the
// yardstick: host seconds per frame, simulated cycles per host second (target >= 5 M), and the
// slowdown against the functional model (target <= 20x).
//
// Two frames (second argument): 0 = the frame, primary rays into a hit sink (what the
// DynRTC computes; also the frame issue 4's functional-model target is measured on), and 1 = the
// paper's Table 3 setting with the RGS's local shading. The cycle model does not time the RGS's
// colour arithmetic (both frames take the same cycles), so the shaded frame adds host work only:
// the thread programs' shading, which is the functional model's code.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <ctime>

#include "host/image_builder.h"
#include "host/scene.h"
#include "units/dynrtp.h"
#include "units/functional_model.h"

namespace {

using namespace saarcor;

struct Room {
  host::Scene scene = host::load_scene("builtin:room");
  host::BuiltImage built = host::build_image(scene, {});
};
const Room& room() {
  static const Room r;
  return r;
}

// CPU seconds of this thread: the machine is shared, so wall time would measure the neighbours.
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double g_functional_seconds[2] = {0.0, 0.0};  // per frame kind (hits, shaded)

void BM_FunctionalFp24Frame(benchmark::State& state) {
  const Room& r = room();
  const bool shade = state.range(0) != 0;
  units::FunctionalParams params;
  params.shade = shade;
  double seconds = 0.0;
  int n = 0;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    const units::FunctionalFrame f = units::run_functional<ff::fp24>(r.built.image, params);
    seconds += cpu_seconds() - t0;
    ++n;
    benchmark::DoNotOptimize(f.rgb.data());
  }
  g_functional_seconds[shade] = seconds / n;
  state.counters["host_s_per_frame"] = g_functional_seconds[shade];
}
BENCHMARK(BM_FunctionalFp24Frame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(2);

void BM_CycleModelFrame(benchmark::State& state) {
  const Room& r = room();
  units::CycleParams p = units::prototype_params();
  p.threads = static_cast<int>(state.range(0));
  const bool shade = state.range(1) != 0;
  units::CycleRunOptions options;
  options.shading.shade = shade;
  double seconds = 0.0;
  std::uint64_t cycles = 0;
  int n = 0;
  units::CycleFrame last;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    last = units::run_cycle(r.built.image, p, options);
    seconds += cpu_seconds() - t0;
    cycles += last.cycles;
    ++n;
  }
  const double per_frame = seconds / n;
  const double functional = g_functional_seconds[shade];
  const double rate = static_cast<double>(cycles) / seconds;
  state.counters["host_s_per_frame"] = per_frame;
  state.counters["sim_cycles_per_s"] = rate;
  state.counters["cycles"] = static_cast<double>(last.cycles);
  state.counters["evaluations_per_cycle"] =
      static_cast<double>(last.module_evaluations) / static_cast<double>(last.cycles);
  std::printf(
      "cycle model, %d threads, %s: %.3f host s per 512x384 frame, %llu cycles (%.1f fps at %.0f "
      "MHz), %.2f M simulated cycles/s (target >= 5: ratio %.2f), %.1fx the functional fp24 "
      "model's %.3f s (target <= 20x: ratio %.2f)\n",
      p.threads, shade ? "shaded (Table 3 setting)" : "hit sink (the issue's frame)", per_frame,
      static_cast<unsigned long long>(last.cycles), last.fps, p.clock_mhz, rate / 1e6, rate / 5e6,
      functional > 0 ? per_frame / functional : 0.0, functional,
      functional > 0 ? per_frame / functional / 20.0 : 0.0);
}
BENCHMARK(BM_CycleModelFrame)
    ->Args({64, 0})
    ->Args({64, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace
