// Speed of the functional fp24 model (units/functional_model.h) on the built-in room scene at the
// paper's Table 3 setting (512x384, primary rays, textured shading), with the float reference
// (host/float_reference.h) on the same image in the same run as the yardstick: prints rays per
// CPU second of both and their ratio, and the work per ray.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <ctime>

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

// CPU seconds of this thread: the machine is shared, so wall time would measure the neighbours.
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
double g_float_rays_per_s = 0.0;

void BM_FunctionalFp24Room(benchmark::State& state) {
  const Room& r = room();
  units::FunctionalParams p;
  p.packet = static_cast<int>(state.range(0));
  double rays = 0.0, seconds = 0.0;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    const units::FunctionalFrame f = units::run_functional<ff::fp24>(r.built.image, p);
    seconds += cpu_seconds() - t0;
    benchmark::DoNotOptimize(f.rgb.data());
    rays += static_cast<double>(f.rays_issued[0]);
  }
  state.counters["rays_per_s"] = rays / seconds;
  if (p.packet == 4) g_fp24_rays_per_s = rays / seconds;
  if (p.packet == 4) {
    const units::FunctionalFrame f = units::run_functional<ff::fp24>(r.built.image, p);
    const auto& k = f.by_kind[0];
    const double n = static_cast<double>(f.rays_issued[0]);
    std::printf(
        "per primary ray: %.2f traversal steps, %.2f list entries, %.2f mailbox skips, "
        "%.2f transformations, %.2f intersections; per packet: %.2f inner steps, %.2f "
        "clip steps, %.2f transformation steps, %.2f intersection packets, %.3f sub-packets\n",
        static_cast<double>(k.traversal_steps) / n, static_cast<double>(k.list_entries) / n,
        static_cast<double>(k.mailbox_skips) / n, static_cast<double>(k.transformations) / n,
        static_cast<double>(k.intersections) / n,
        static_cast<double>(f.units.inner_steps) / static_cast<double>(f.units.packets),
        static_cast<double>(f.units.clip_steps) / static_cast<double>(f.units.packets),
        static_cast<double>(f.units.transformation_steps) / static_cast<double>(f.units.packets),
        static_cast<double>(f.units.intersection_packets) / static_cast<double>(f.units.packets),
        static_cast<double>(f.units.sub_packets) / static_cast<double>(f.units.packets));
    const double ops =
        static_cast<double>(f.units.traversal_ops.total() + f.units.transformation_ops.total() +
                            f.units.intersection_ops.total() + f.units.rgs_ops.total());
    std::printf(
        "float ops per primary ray: %.1f (traversal %.1f, transformation %.1f, "
        "intersection %.1f, rgs %.1f)\n",
        ops / n, static_cast<double>(f.units.traversal_ops.total()) / n,
        static_cast<double>(f.units.transformation_ops.total()) / n,
        static_cast<double>(f.units.intersection_ops.total()) / n,
        static_cast<double>(f.units.rgs_ops.total()) / n);
  }
}
BENCHMARK(BM_FunctionalFp24Room)->Arg(1)->Arg(4)->Unit(benchmark::kMillisecond)->Iterations(2);

// One transformation step (18 float ops) on normal operands: the cost floor of the datapath ops.
void BM_TransformStep(benchmark::State& state) {
  using F = ff::fp24;
  units::UnitFp<F> fp;
  units::Mat34<F> m{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      m[r][c] = F::from_double(0.3 + 0.17 * r - 0.11 * c);
  units::Vec3<F> v{F::from_double(1.25), F::from_double(-0.75), F::from_double(2.5)};
  for (auto _ : state) {
    benchmark::DoNotOptimize(v);
    units::Vec3<F> o = units::transform_step(fp, m, v, true);
    benchmark::DoNotOptimize(o);
  }
  state.counters["ops_per_s"] = benchmark::Counter(18.0 * static_cast<double>(state.iterations()),
                                                   benchmark::Counter::kIsRate);
}
BENCHMARK(BM_TransformStep);

void BM_FloatReferenceRoom(benchmark::State& state) {
  const Room& r = room();
  host::FloatParams p;
  const double pixels = static_cast<double>(r.built.image.registers().width) *
                        static_cast<double>(r.built.image.registers().height);
  double rays = 0.0, seconds = 0.0;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    const host::FloatFrame f = host::render_float(r.built, r.scene, p);
    seconds += cpu_seconds() - t0;
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
