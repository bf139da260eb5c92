// Speed of the cycle model (units/dynrtp.h) on the built-in room at the paper's Table 3 setting
// (512x384 primary rays, shaded, prototype configuration), with the functional fp24 model on the
// same image in the same run as the yardstick: host seconds per frame, simulated cycles per host
// second (target >= 5 M), and the slowdown against the functional model (target <= 20x).
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

double g_functional_seconds = 0.0;

void BM_FunctionalFp24Frame(benchmark::State& state) {
  const Room& r = room();
  double seconds = 0.0;
  int n = 0;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    const units::FunctionalFrame f = units::run_functional<ff::fp24>(r.built.image, {});
    seconds += cpu_seconds() - t0;
    ++n;
    benchmark::DoNotOptimize(f.rgb.data());
  }
  g_functional_seconds = seconds / n;
  state.counters["host_s_per_frame"] = g_functional_seconds;
}
BENCHMARK(BM_FunctionalFp24Frame)->Unit(benchmark::kMillisecond)->Iterations(2);

void BM_CycleModelFrame(benchmark::State& state) {
  const Room& r = room();
  units::CycleParams p = units::prototype_params();
  p.threads = static_cast<int>(state.range(0));
  double seconds = 0.0;
  std::uint64_t cycles = 0;
  int n = 0;
  units::CycleFrame last;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    last = units::run_cycle(r.built.image, p);
    seconds += cpu_seconds() - t0;
    cycles += last.cycles;
    ++n;
  }
  const double per_frame = seconds / n;
  const double rate = static_cast<double>(cycles) / seconds;
  state.counters["host_s_per_frame"] = per_frame;
  state.counters["sim_cycles_per_s"] = rate;
  state.counters["cycles"] = static_cast<double>(last.cycles);
  state.counters["evaluations_per_cycle"] =
      static_cast<double>(last.module_evaluations) / static_cast<double>(last.cycles);
  std::printf(
      "cycle model, %d threads: %.3f host s per 512x384 frame, %llu cycles (%.1f fps at %.0f "
      "MHz), %.2f M simulated cycles/s (target >= 5: ratio %.2f), %.1fx the functional fp24 "
      "model's %.3f s (target <= 20x: ratio %.2f)\n",
      p.threads, per_frame, static_cast<unsigned long long>(last.cycles), last.fps, p.clock_mhz,
      rate / 1e6, rate / 5e6, g_functional_seconds > 0 ? per_frame / g_functional_seconds : 0.0,
      g_functional_seconds,
      g_functional_seconds > 0 ? per_frame / g_functional_seconds / 20.0 : 0.0);
}
BENCHMARK(BM_CycleModelFrame)->Arg(64)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
