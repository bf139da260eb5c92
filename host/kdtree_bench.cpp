// Build rate of the SAH kd-tree builder (host/kdtree.h; paper section 2, docs/memory-image.md) on
// deterministic meshes of about 10K, 100K and 1M triangles: a noisy terrain heightfield (like the
// builtin terrain scene) and a finely tessellated sphere. Prints triangles per second, the ratio
// against the target of 1M triangles/s on one core, and, as a reference measured in the same
// run, Embree 3's single-threaded BVH build on the same mesh. BM_KdTreeBuildExact builds the 1M
// meshes with the exact Wald-Havran sweep alone (no binned stage): the tree-quality reference
// (SAH cost, nodes) for the default hybrid build.
#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <vector>

#include "host/bench_support.h"
#include "host/kdtree.h"

namespace {

using saarcor::host::build_kdtree;
using saarcor::host::KdBuildParams;
using saarcor::host::KdTree;

constexpr double kTargetTrianglesPerSecond = 1e6;

struct Mesh {
  std::vector<glm::vec3> pos;
  std::vector<glm::uvec3> tris;
};

// n x n cells, two triangles each: value noise over a few octaves plus rolling hills.
Mesh terrain(int n) {
  std::mt19937 rng(1234);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> lattice(64 * 64);
  for (auto& v : lattice)
    v = u(rng);
  auto noise = [&](float x, float y) {
    const int xi = static_cast<int>(std::floor(x));
    const int yi = static_cast<int>(std::floor(y));
    const float fx = x - xi;
    const float fy = y - yi;
    auto at = [&](int i, int j) { return lattice[((j & 63) << 6) | (i & 63)]; };
    const float a = at(xi, yi) + fx * (at(xi + 1, yi) - at(xi, yi));
    const float b = at(xi, yi + 1) + fx * (at(xi + 1, yi + 1) - at(xi, yi + 1));
    return a + fy * (b - a);
  };
  Mesh m;
  const float cell = 1000.0f / n;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) {
      const float px = x * cell;
      const float py = y * cell;
      float h = 40.0f * std::sin(px * 0.01f) * std::cos(py * 0.013f);
      for (int o = 0; o < 5; ++o) {
        const float f = 0.01f * static_cast<float>(1 << o);
        h += 60.0f / static_cast<float>(1 << o) * noise(px * f, py * f);
      }
      m.pos.emplace_back(px, h, py);
    }
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const auto i = static_cast<unsigned>(y * (n + 1) + x);
      m.tris.emplace_back(i, i + 1, i + n + 2);
      m.tris.emplace_back(i, i + n + 2, i + n + 1);
    }
  return m;
}

// Latitude-longitude sphere with stacks x 2*stacks quads.
Mesh sphere(int stacks) {
  const int slices = 2 * stacks;
  Mesh m;
  for (int i = 0; i <= stacks; ++i) {
    const double th = M_PI * i / stacks;
    for (int j = 0; j < slices; ++j) {
      const double ph = 2.0 * M_PI * j / slices;
      m.pos.emplace_back(static_cast<float>(10.0 * std::sin(th) * std::cos(ph)),
                         static_cast<float>(10.0 * std::cos(th)),
                         static_cast<float>(10.0 * std::sin(th) * std::sin(ph)));
    }
  }
  for (int i = 0; i < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      const auto a = static_cast<unsigned>(i * slices + j);
      const auto b = static_cast<unsigned>(i * slices + (j + 1) % slices);
      const auto c = a + static_cast<unsigned>(slices);
      const auto d = b + static_cast<unsigned>(slices);
      if (i > 0) m.tris.emplace_back(a, b, d);
      if (i < stacks - 1) m.tris.emplace_back(a, d, c);
    }
  return m;
}

const Mesh& mesh(int kind, int size) {
  static std::map<std::pair<int, int>, Mesh> cache;
  auto it = cache.find({kind, size});
  if (it == cache.end()) {
    // Sizes give ~10K, ~100K, ~1M triangles.
    Mesh m = kind == 0 ? terrain(size) : sphere(size);
    it = cache.emplace(std::make_pair(kind, size), std::move(m)).first;
  }
  return it->second;
}

// CPU time of this process (Embree runs its one build thread under TBB).
const auto cpu_seconds = saarcor::host::bench::process_cpu_seconds;

// Embree 3 BVH build, one thread: the reference build rate on the same machine, same run.
double embree_build_seconds(const Mesh& m) {
  RTCDevice device = rtcNewDevice("threads=1");
  double best = 1e30;
  for (int rep = 0; rep < 3; ++rep) {
    RTCScene scene = rtcNewScene(device);
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.pos.size()));
    std::memcpy(v, m.pos.data(), m.pos.size() * sizeof(glm::vec3));
    auto* ix = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), m.tris.size()));
    std::memcpy(ix, m.tris.data(), m.tris.size() * sizeof(glm::uvec3));
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    const double t0 = cpu_seconds();
    rtcCommitScene(scene);
    best = std::min(best, cpu_seconds() - t0);
    rtcReleaseScene(scene);
  }
  rtcReleaseDevice(device);
  return best;
}

// Times one build per benchmark iteration and sets the counters both benchmarks print; returns
// triangles per CPU second.
double time_builds(benchmark::State& state, const Mesh& m, const KdBuildParams& params) {
  KdTree tree;
  double total = 0.0;
  std::int64_t builds = 0;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    tree = build_kdtree(m.pos, m.tris, {}, params);
    const double t = cpu_seconds() - t0;
    state.SetIterationTime(t);
    total += t;
    ++builds;
    benchmark::DoNotOptimize(tree.nodes.data());
  }
  const double n = static_cast<double>(m.tris.size());
  const double rate = n * static_cast<double>(builds) / total;
  state.counters["triangles"] = n;
  state.counters["tri_per_s"] = rate;
  state.counters["vs_target_1M"] = rate / kTargetTrianglesPerSecond;
  state.counters["nodes"] = tree.stats.nodes;
  state.counters["depth"] = tree.stats.depth;
  state.counters["items_per_leaf"] = tree.stats.items_per_leaf;
  state.counters["sah_cost"] = tree.stats.sah_cost;
  state.counters["exp_steps"] = tree.stats.expected_traversal_steps;
  state.counters["exp_tests"] = tree.stats.expected_item_tests;
  return rate;
}

void BM_KdTreeBuild(benchmark::State& state) {
  const Mesh& m = mesh(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const double embree = embree_build_seconds(m);
  const double rate = time_builds(state, m, {});
  const double n = static_cast<double>(m.tris.size());
  state.SetLabel(state.range(0) == 0 ? "terrain" : "sphere");
  state.counters["embree_tri_per_s"] = n / embree;
  state.counters["vs_embree_bvh"] = rate / (n / embree);
}

// The exact event sweep alone (binned stage off): the same counters, for the quality comparison.
void BM_KdTreeBuildExact(benchmark::State& state) {
  const Mesh& m = mesh(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  KdBuildParams params;
  params.binned_above = std::numeric_limits<int>::max();
  time_builds(state, m, params);
  state.SetLabel(state.range(0) == 0 ? "terrain, exact sweep only" : "sphere, exact sweep only");
}

// (kind, size): terrain n x n cells (2n^2 triangles), sphere with s stacks (~4 s^2 triangles).
BENCHMARK(BM_KdTreeBuild)
    ->Args({0, 71})
    ->Args({0, 224})
    ->Args({0, 708})
    ->Args({1, 50})
    ->Args({1, 158})
    ->Args({1, 500})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()  // the "Time" column is this thread's CPU time per build
    ->MinTime(0.5);
BENCHMARK(BM_KdTreeBuildExact)
    ->Args({0, 708})
    ->Args({1, 500})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
