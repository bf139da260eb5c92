// Speed of the two golden models (docs/compare.md) against Intel Embree 3 on the same rays in
// the same run: 512x384 primary rays (the paper's Table 3 resolution) of builtin:room and of the
// largest instanced glTF model that builds quickly (2CylinderEngine, 121K triangles after
// instancing). Rays per second of thread CPU time (the machine is shared; wall time would measure
// the neighbours), all on one core:
//   - float reference: FloatScene::trace on the frame's primary rays (hit only), and the whole
//     render_float (ray generation + trace + docs/shading.md shading);
//   - functional fp24 model: run_functional<fp24> with P = 4, hit only and shaded;
//   - Embree: rtcIntersect1 (single ray) on the float reference's world rays, world-space
//     triangles, high-quality BVH.
// Targets: float reference >= 0.25x Embree's single-ray rate; fp24 >= 0.1x.
//
// BM_PaperTable3: the paper's Table 3 compares the prototype (one DynRTP at 90 MHz) with OpenRT
// on a 2.66 GHz Pentium 4. Its software column becomes Embree's single-ray rate on this host, on
// the same primary rays of each stand-in (room, terrain, suncor) at 512x384, in the same run as
// the cycle model's frame: the printout sets the model's speed-up over Embree beside the paper's
// speed-up over OpenRT (testbench/paper_cmd.h has the tables).
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
#include "testbench/bench_summaries.h"
#include "testbench/paper_cmd.h"
#include "testbench/render_cmd.h"
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

// Model fps (simulated, 90 MHz) and Embree single-ray fps (this host, one core) per stand-in.
struct Table3Measure {
  std::string paper;
  double model_fps = 0.0;
  double embree_fps = 0.0;
};
std::vector<Table3Measure> g_table3;

void BM_PaperTable3(benchmark::State& state) {
  const std::vector<PaperScene> scenes = paper_scenes("");
  const PaperScene& ps = scenes.at(static_cast<std::size_t>(state.range(0)));
  state.SetLabel(ps.paper + " (" + ps.spec + ")");
  RenderSettings settings = frame_settings("512x384", 0.0, false, 0, ps.bank_mb);
  const PreparedScene prep = prepare_scene(ps.spec, settings);
  const FrameResult frame = render_model(parse_model("cycle"), prep, settings);
  const std::vector<host::FloatRay> rays =
      host::primary_rays(host::to_float(prep.built.basis), 512, 384);
  // Instanced: SunCOR's 187M triangles cannot be flattened; Embree transforms the rays itself.
  const host::EmbreeOracle embree(prep.scene, prep.built, host::EmbreeOracle::Mode::kInstanced, 1,
                                  true);
  double seconds = 0.0, frames = 0.0;
  std::uint64_t hits = 0;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    for (const host::FloatRay& r : rays)
      hits += embree.intersect(r).hit ? 1u : 0u;
    seconds += cpu_seconds() - t0;
    frames += 1.0;
  }
  benchmark::DoNotOptimize(hits);
  Table3Measure m{ps.paper, frame.cycle["fps"].get<double>(), frames / seconds};
  state.counters["model_fps"] = m.model_fps;
  state.counters["embree_fps"] = m.embree_fps;
  g_table3.push_back(m);
}

BENCHMARK(BM_PaperTable3)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->Iterations(3);

void print_table3() {
  if (g_table3.empty()) return;
  std::printf(
      "Table 3, 512x384 primary rays: the paper's prototype (90 MHz) over OpenRT (P4 2.66 GHz) "
      "beside the model (90 MHz) over Embree rtcIntersect1 (this host, one core)\n");
  std::printf("%-10s %9s %9s %8s | %9s %10s %8s | %s\n", "scene", "SaarCOR", "OpenRT", "speed-up",
              "model", "Embree", "speed-up", "ratio of speed-ups");
  for (const Table3Measure& m : g_table3) {
    const Table3Row* p = paper_table3_row(m.paper);
    if (p == nullptr) continue;
    const double paper_up = p->saarcor_fps / p->openrt_fps;
    const double model_up = m.model_fps / m.embree_fps;
    std::printf("%-10s %9.1f %9.1f %8.2f | %9.1f %10.1f %8.2f | %.2f\n", m.paper.c_str(),
                p->saarcor_fps, p->openrt_fps, paper_up, m.model_fps, m.embree_fps, model_up,
                model_up / paper_up);
  }
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  saarcor::testbench::print_functional_model_ratio();
  print_table3();
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
