// Speed of the two golden models (DESIGN.md section 9) against Intel Embree 3 on the same rays in
// the same run: 512x384 primary rays (the paper's Table 3 resolution) of builtin:room and of the
// largest instanced glTF model that builds quickly (2CylinderEngine, 121K triangles after
// instancing). Rays per second of thread CPU time (the machine is shared; wall time would measure
// the neighbours), all on one core:
//   - float reference: FloatScene::trace on the frame's primary rays (hit only), and the whole
//     render_float (ray generation + trace + docs/shading.md shading);
//   - functional fp24 model: run_functional<fp24> with P = 4, hit only and shaded;
//   - Embree: rtcIntersect1 (single ray) on the float reference's world rays, world-space
//     triangles, high-quality BVH.
// Targets (issue 4): float reference >= 0.25x Embree's single-ray rate; fp24 >= 0.1x.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "host/bench_support.h"
#include "host/embree_oracle.h"
#include "host/float_reference.h"
#include "host/image_builder.h"
#include "host/scene.h"
#include "units/functional_model.h"

namespace {

using namespace saarcor;

const auto cpu_seconds = host::bench::thread_cpu_seconds;

struct BenchScene {
  std::string label;
  host::Scene scene;
  host::BuiltImage built;
  std::unique_ptr<host::FloatScene> float_scene;
  std::vector<host::FloatRay> rays;  // the frame's primary rays, row-major
  std::unique_ptr<host::EmbreeOracle> embree;
};

const std::vector<std::string>& scene_specs() {
  static const std::vector<std::string> specs = {
      "builtin:room", std::string(SAARCOR_SHARED_SCENES) + "/2CylinderEngine/2CylinderEngine.gltf"};
  return specs;
}

BenchScene& bench_scene(std::size_t index) {
  static std::map<std::size_t, std::unique_ptr<BenchScene>> cache;
  auto& slot = cache[index];
  if (!slot) {
    slot = std::make_unique<BenchScene>();
    BenchScene& s = *slot;
    const std::string& spec = scene_specs()[index];
    s.label = spec.substr(spec.rfind('/') + 1);
    s.scene = host::load_scene(spec);
    s.built = host::build_fitting_image(s.scene, 512, 384);
    s.float_scene = std::make_unique<host::FloatScene>(s.built);
    s.rays = host::primary_rays(host::to_float(s.built.basis), s.built.params.width,
                                s.built.params.height);
    s.embree = std::make_unique<host::EmbreeOracle>(s.scene, s.built,
                                                    host::EmbreeOracle::Mode::kFlattened, 1, true);
  }
  return *slot;
}

// Rays per CPU second, by scene and model.
std::map<std::string, std::map<std::string, double>> g_rates;

void record(benchmark::State& state, const BenchScene& s, const char* model, double rays,
            double seconds) {
  const double rate = rays / seconds;
  state.counters["Mrays_per_s"] = rate * 1e-6;
  g_rates[s.label][model] = rate;
}

void BM_Embree(benchmark::State& state) {
  const BenchScene& s = bench_scene(static_cast<std::size_t>(state.range(0)));
  state.SetLabel(s.label);
  double rays = 0.0, seconds = 0.0;
  std::uint64_t hits = 0;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    for (const host::FloatRay& r : s.rays)
      hits += s.embree->intersect(r).hit ? 1u : 0u;
    seconds += cpu_seconds() - t0;
    rays += static_cast<double>(s.rays.size());
  }
  benchmark::DoNotOptimize(hits);
  record(state, s, "embree", rays, seconds);
}

void BM_FloatTrace(benchmark::State& state) {
  const BenchScene& s = bench_scene(static_cast<std::size_t>(state.range(0)));
  state.SetLabel(s.label);
  double rays = 0.0, seconds = 0.0;
  std::uint64_t hits = 0;
  const float inf = std::numeric_limits<float>::infinity();
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    for (const host::FloatRay& r : s.rays)
      hits += s.float_scene->trace(r, 0.0f, inf).hit() ? 1 : 0;
    seconds += cpu_seconds() - t0;
    rays += static_cast<double>(s.rays.size());
  }
  benchmark::DoNotOptimize(hits);
  record(state, s, "float", rays, seconds);
}

void BM_FloatRender(benchmark::State& state) {
  const BenchScene& s = bench_scene(static_cast<std::size_t>(state.range(0)));
  state.SetLabel(s.label);
  double rays = 0.0, seconds = 0.0;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    const host::FloatFrame f = host::render_float(*s.float_scene, s.built, s.scene, {});
    seconds += cpu_seconds() - t0;
    benchmark::DoNotOptimize(f.rgb.data());
    rays += static_cast<double>(f.pixels.size());
  }
  record(state, s, "float_shaded", rays, seconds);
}

void BM_Fp24(benchmark::State& state) {
  const BenchScene& s = bench_scene(static_cast<std::size_t>(state.range(0)));
  const bool shade = state.range(1) != 0;
  state.SetLabel(s.label + (shade ? " shaded" : " hits"));
  units::FunctionalParams p;
  p.shade = shade;
  double rays = 0.0, seconds = 0.0;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    const units::FunctionalFrame f = units::run_functional<ff::fp24>(s.built.image, p);
    seconds += cpu_seconds() - t0;
    benchmark::DoNotOptimize(f.rgb.data());
    rays += static_cast<double>(f.rays_issued[0]);
  }
  record(state, s, shade ? "fp24_shaded" : "fp24", rays, seconds);
}

BENCHMARK(BM_Embree)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_FloatTrace)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_FloatRender)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Fp24)
    ->Args({0, 0})
    ->Args({0, 1})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);  // like Embree's rate, a mean over frames (one frame alone is the cold one)

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  for (const auto& [label, r] : g_rates) {
    const auto get = [&](const char* k) {
      const auto it = r.find(k);
      return it == r.end() ? 0.0 : it->second;
    };
    const double embree = get("embree");
    std::printf("%s, 512x384 primary rays, one core (Mrays/s of thread CPU time):\n",
                label.c_str());
    std::printf("  Embree rtcIntersect1          %8.3f\n", embree * 1e-6);
    const auto line = [&](const char* name, const char* key, double target) {
      const double v = get(key);
      if (v <= 0.0 || embree <= 0.0) return;
      std::printf("  %-29s %8.3f  = %.3fx Embree", name, v * 1e-6, v / embree);
      if (target > 0.0)
        std::printf("  (target >= %.2fx: %s)", target, v / embree >= target ? "met" : "NOT met");
      std::printf("\n");
    };
    line("float reference, hits", "float", 0.25);
    line("float reference, shaded", "float_shaded", 0.0);
    line("functional fp24 P=4, hits", "fp24", 0.1);
    line("functional fp24 P=4, shaded", "fp24_shaded", 0.0);
  }
  return 0;
}
