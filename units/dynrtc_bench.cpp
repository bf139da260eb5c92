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

#include <algorithm>
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

// Per frame kind (hits, shaded): the functional model's best frame time.
double g_functional_seconds[2] = {0.0, 0.0};

// Frames are timed one by one: the machine is shared, so the best of a few frames is the figure
// compared with the targets (the mean is printed beside it).
struct FrameTimes {
  double best = 0.0, sum = 0.0;
  int n = 0;
  void add(double s) {
    best = n == 0 ? s : std::min(best, s);
    sum += s;
    ++n;
  }
  double mean() const { return n == 0 ? 0.0 : sum / n; }
};

void BM_FunctionalFp24Frame(benchmark::State& state) {
  const Room& r = room();
  const bool shade = state.range(0) != 0;
  units::FunctionalParams params;
  params.shade = shade;
  FrameTimes times;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    const units::FunctionalFrame f = units::run_functional<ff::fp24>(r.built.image, params);
    times.add(cpu_seconds() - t0);
    benchmark::DoNotOptimize(f.rgb.data());
  }
  g_functional_seconds[shade] = times.best;
  state.counters["host_s_per_frame"] = times.best;
  state.counters["host_s_per_frame_mean"] = times.mean();
}
BENCHMARK(BM_FunctionalFp24Frame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_CycleModelFrame(benchmark::State& state) {
  const Room& r = room();
  units::CycleParams p = units::prototype_params();
  p.threads = static_cast<int>(state.range(0));
  const bool shade = state.range(1) != 0;
  units::CycleRunOptions options;
  options.shading.shade = shade;
  FrameTimes times;
  units::CycleFrame last;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    last = units::run_cycle(r.built.image, p, options);
    times.add(cpu_seconds() - t0);
  }
  const double functional = g_functional_seconds[shade];
  const double rate = static_cast<double>(last.cycles) / times.best;
  state.counters["host_s_per_frame"] = times.best;
  state.counters["host_s_per_frame_mean"] = times.mean();
  state.counters["sim_cycles_per_s"] = rate;
  state.counters["cycles"] = static_cast<double>(last.cycles);
  state.counters["evaluations_per_cycle"] =
      static_cast<double>(last.module_evaluations) / static_cast<double>(last.cycles);
  std::printf(
      "cycle model, %d threads, %s: %.3f host s per 512x384 frame (best of %d; mean %.3f), %llu "
      "cycles (%.1f fps at %.0f MHz), %.2f M simulated cycles/s (target >= 5: ratio %.2f), %.1fx "
      "the functional fp24 model's %.3f s (target <= 20x: ratio %.2f)\n",
      p.threads, shade ? "shaded (Table 3 setting)" : "hit sink (the issue's frame)", times.best,
      times.n, times.mean(), static_cast<unsigned long long>(last.cycles), last.fps, p.clock_mhz,
      rate / 1e6, rate / 5e6, functional > 0 ? times.best / functional : 0.0, functional,
      functional > 0 ? times.best / functional / 20.0 : 0.0);
}
BENCHMARK(BM_CycleModelFrame)
    ->Args({64, 0})
    ->Args({64, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

}  // namespace
