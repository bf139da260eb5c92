// Speed of the functional fp24 model (units/functional_model.h) on the built-in room scene at the
// paper's Table 3 setting (512x384, primary rays, textured shading), with the float reference
// (host/float_reference.h) on the same image in the same run as the yardstick: prints rays/s of
// both and their ratio.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>

#include "host/float_reference.h"
#include "host/image_builder.h"
#include "host/scene.h"
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

double g_fp24_rays_per_s = 0.0;
double g_float_rays_per_s = 0.0;

void BM_FunctionalFp24Room(benchmark::State& state) {
  const Room& r = room();
  units::FunctionalParams p;
  p.packet = static_cast<int>(state.range(0));
  double rays = 0.0, seconds = 0.0;
  for (auto _ : state) {
    const units::FunctionalFrame f = units::run_functional<ff::fp24>(r.built.image, p);
    benchmark::DoNotOptimize(f.rgb.data());
    rays += static_cast<double>(f.rays_issued[0]);
    seconds += f.seconds;
  }
  state.counters["rays_per_s"] = rays / seconds;
  if (p.packet == 4) g_fp24_rays_per_s = rays / seconds;
}
BENCHMARK(BM_FunctionalFp24Room)->Arg(1)->Arg(4)->Unit(benchmark::kMillisecond)->Iterations(2);

void BM_FloatReferenceRoom(benchmark::State& state) {
  const Room& r = room();
  host::FloatParams p;
  const double pixels = static_cast<double>(r.built.image.registers().width) *
                        static_cast<double>(r.built.image.registers().height);
  double rays = 0.0, seconds = 0.0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const host::FloatFrame f = host::render_float(r.built, r.scene, p);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    benchmark::DoNotOptimize(f.rgb.data());
    rays += pixels;
  }
  state.counters["rays_per_s"] = rays / seconds;
  g_float_rays_per_s = rays / seconds;
}
BENCHMARK(BM_FloatReferenceRoom)->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  if (g_fp24_rays_per_s > 0.0 && g_float_rays_per_s > 0.0)
    std::printf(
        "functional fp24 model (P=4): %.3f Mrays/s; float reference: %.3f Mrays/s; "
        "ratio fp24/float = %.3f\n",
        g_fp24_rays_per_s * 1e-6, g_float_rays_per_s * 1e-6,
        g_fp24_rays_per_s / g_float_rays_per_s);
  return 0;
}
