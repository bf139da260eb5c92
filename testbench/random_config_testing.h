// Test-only helpers of the random-configuration stress tests (testbench/random_config_test.cpp,
// random_config_deep_test.cpp; docs/fuzzing.md "Random configurations"): a seed names one
// configuration of every cycle key (and sometimes kd.* keys, shadow and secondary rays, the host
// thread mode) on one scene; the configuration runs through the cycle model exactly as
// `saarcor render --model cycle` runs it, and must finish (no watchdog), return every ray exactly
// once and give the functional fp24 model's hit records, per-ray counters, op counts and image bit
// for bit. A failure names the seed and the `saarcor render` command that replays it.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "testbench/cycle_render.h"
#include "testbench/dynrtc_testing.h"
#include "testbench/render_cmd.h"

namespace saarcor::stress {

struct StressScene {
  std::string spec;
  int width = 32, height = 24;
  double bank_mb = 4.0;
  // kd.* keys and secondary-ray depths may be drawn (each new draw rebuilds the image); false:
  // one image (kd.stack=64, no secondary rays) for a scene whose build takes seconds.
  bool vary_image = true;
};

// The CI-size set: the small built-ins and two shared glTF models.
inline std::vector<StressScene> small_scenes() {
  return {{"builtin:room"},
          {"builtin:cube"},
          {"builtin:dynamic"},
          {"builtin:triangle"},
          {units::testing::shared("Duck/Duck.gltf")},
          {units::testing::shared("CesiumMilkTruck/CesiumMilkTruck.gltf")}};
}

// The deep set: those, two more glTF models (a .glb, textures) and BART's kitchen (110,561
// triangles, its image built once).
inline std::vector<StressScene> deep_scenes() {
  std::vector<StressScene> s = small_scenes();
  s.push_back({units::testing::shared("BoxAnimated/BoxAnimated.glb")});
  s.push_back({units::testing::shared("BoxTextured/BoxTextured.gltf")});
  s.push_back({units::testing::shared("BART/kitchen/aff/kitchen.aff"), 32, 24, 16.0, false});
  return s;
}

struct RandomConfig {
  std::uint64_t seed = 0;
  StressScene scene;
  std::vector<std::string> set;  // --set KEY=VALUE, cycle keys then kd.* keys
  bool shadows = false;
  int depth = 0;  // secondary rays up to this depth, 0 = none
  int host_threads = 1;

  // The command that replays this configuration.
  std::string command() const {
    std::string c = "saarcor render " + scene.spec + " --model cycle --res " +
                    std::to_string(scene.width) + "x" + std::to_string(scene.height);
    if (scene.bank_mb != 4.0) c += " --bank-mb " + std::to_string(static_cast<int>(scene.bank_mb));
    if (shadows) c += " --shadows";
    if (depth > 0) c += " --depth " + std::to_string(depth);
    c += " --host-threads " + std::to_string(host_threads);
    for (const std::string& kv : set)
      c += " --set " + kv;
    return c;
  }
  std::string trees() const {
    std::string t;
    for (const std::string& kv : set)
      if (host::is_tree_setting(kv)) t += kv + " ";
    return t;
  }
};

// Configuration `seed` on one of `scenes` (seed modulo their count). Each key is drawn with
// probability 1/2 (else it keeps the prototype's default); values span each key's useful range.
inline RandomConfig random_config(std::uint64_t seed, const std::vector<StressScene>& scenes) {
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + 1);
  const auto pick = [&](std::initializer_list<int> v) {
    return *(v.begin() + static_cast<std::ptrdiff_t>(rng() % v.size()));
  };
  const auto in = [&](int lo, int hi) { return lo + static_cast<int>(rng() % (hi - lo + 1)); };
  const auto coin = [&] { return (rng() & 1) != 0; };
  RandomConfig c;
  c.seed = seed;
  c.scene = scenes[seed % scenes.size()];
  const auto put = [&](const std::string& key, int v) {
    c.set.push_back(key + "=" + std::to_string(v));
  };
  const auto maybe = [&](const std::string& key, int v) {
    if (coin()) put(key, v);
  };
  const int pipelines = coin() ? 1 : pick({2, 3, 4, 8});
  if (pipelines > 1) put("pipelines", pipelines);
  put("threads", pick({1, 2, 3, 4, 5, 8, 13, 16, 32, 64, 128}));
  put("packet", pick({1, 2, 4, 8, 16, 32, 64}));
  // The trees are built for the hardware's stack (kd.stack follows stack; a larger hardware stack
  // than the trees need is fine).
  const int stack = c.scene.vary_image ? pick({16, 24, 32, 48, 64, 100}) : pick({64, 100});
  put("stack", stack);
  maybe("mailbox", in(0, 16));
  maybe("triangle_mailbox", in(0, 16));
  maybe("shared_origin", in(0, 1));
  maybe("clip.exit_only", in(0, 1));
  maybe("clip.faces_per_step", in(1, 6));
  maybe("traversal.skip_empty", in(0, 1));
  for (const char* unit : {"traversal", "list", "transformation"}) {
    if (!coin()) continue;
    const int items = 1 << in(0, 11);
    put(std::string("cache.") + unit + ".items", items);
    maybe(std::string("cache.") + unit + ".ways",
          1 << in(0, std::min(6, std::countr_zero(static_cast<unsigned>(items)))));
  }
  maybe("cache.hit_latency", in(2, 8));
  maybe("cache.misses", in(1, 16));
  maybe("cache.merge_targets", pick({1, 2, 4, 16, 64}));
  maybe("cache.request_queue", in(1, 8));
  maybe("cache.memory_queue", in(1, 4));
  maybe("mem.latency", in(1, 60));
  maybe("mem.switch_penalty", in(0, 5));
  maybe("mem.scene_paths", pick({1, 3}));
  maybe("mem.queue_depth", in(1, 16));
  maybe("mem.reorder", in(0, 1));
  maybe("mem.max_burst", in(1, 16));
  maybe("mem.port_capacity", in(2, 8));
  maybe("routing.responses", in(1, 4));
  maybe("hostbus.burst_words", in(1, 4));
  maybe("lat.add", in(1, 16));
  maybe("lat.mul", in(1, 16));
  maybe("lat.div", in(1, 24));
  maybe("lat.cmp", in(1, 8));
  maybe("clock_mhz", in(10, 500));
  put("kd.stack", c.scene.vary_image ? stack : 64);
  if (c.scene.vary_image && rng() % 4 == 0) {
    maybe("kd.leaf_size", pick({0, 1, 2, 8}));
    maybe("kd.max_depth", pick({-1, 12, 20}));  // shallower: leaves of thousands
    maybe("kd.face_slabs", in(0, 1));
    maybe("kd.traversal_cost", pick({5, 30, 100}));
    maybe("kd.objective", in(0, 1));
  }
  c.shadows = rng() % 10 < 3;
  c.depth = c.scene.vary_image && rng() % 4 == 0 ? in(1, 3) : 0;
  c.host_threads = in(1, 2);
  return c;
}

struct StressTotals {
  std::uint64_t configs = 0, rays = 0, cycles = 0;
  double seconds = 0.0;
};

// Runs configurations `first`..`last` (seeds) and checks each; scenes are loaded once, images
// rebuilt only when the kd.* keys change.
class StressRunner {
 public:
  explicit StressRunner(std::vector<StressScene> scenes, int shrink = 1)
      : scenes_(std::move(scenes)), shrink_(shrink) {}

  void run(std::uint64_t first, std::uint64_t last) {
    for (std::uint64_t seed = first; seed <= last; ++seed)
      check(random_config(seed, scenes_));
  }
  const StressTotals& totals() const { return totals_; }

  void check(RandomConfig c) {
    c.scene.width /= shrink_;
    c.scene.height /= shrink_;
    const std::string what = "seed " + std::to_string(c.seed) + ", replay: " + c.command();
    SCOPED_TRACE(what);
    const auto t0 = std::chrono::steady_clock::now();
    RenderSettings s;
    s.res = {c.scene.width, c.scene.height};
    s.shadows = c.shadows;
    s.depth = c.depth;
    s.bank_mb = c.scene.bank_mb;
    s.cycle.set = c.set;
    s.cycle.host_threads = c.host_threads;
    const PreparedScene& prep = prepared(c, s);
    const units::FunctionalParams shading = functional_params(s);
    CycleFrame cy;
    try {
      cy = run_cycle_render(prep.built.image, shading, s.cycle);
    } catch (const std::runtime_error& e) {
      ADD_FAILURE() << "the cycle model stopped: " << e.what();
      return;
    }
    const units::FunctionalFrame fn =
        units::run_functional(prep.built.image, units::functional_params(cy.params, shading));
    expect_same_frame(cy, fn);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("seed %llu: %llu rays, %llu cycles, %.2f s: %s\n",
                static_cast<unsigned long long>(c.seed), static_cast<unsigned long long>(cy.rays),
                static_cast<unsigned long long>(cy.cycles), seconds, c.command().c_str());
    ++totals_.configs;
    totals_.rays += cy.rays;
    totals_.cycles += cy.cycles;
    totals_.seconds += seconds;
  }

 private:
  const PreparedScene& prepared(const RandomConfig& c, const RenderSettings& s) {
    const std::string key = c.scene.spec + " " + std::to_string(c.scene.width) + "x" +
                            std::to_string(c.scene.height) + " " + c.trees() +
                            std::to_string(c.depth);
    auto& slot = cache_[c.scene.spec];
    if (!slot || slot->first != key) {
      if (!slot || slot->second.spec != c.scene.spec) {
        slot.emplace(key, prepare_scene(c.scene.spec, s));
      } else {
        slot->first = key;
        build_prepared_image(slot->second, s, ff::kFp24);
      }
    }
    return slot->second;
  }

  static void expect_same_frame(const CycleFrame& cy, const units::FunctionalFrame& fn) {
    ASSERT_EQ(cy.frame.pixels.size(), fn.pixels.size());
    int bad = 0;
    for (std::size_t i = 0; i < fn.pixels.size(); ++i)
      if (!units::testing::same_record(cy.frame.pixels[i], fn.pixels[i]) && ++bad <= 3)
        ADD_FAILURE() << "pixel " << i % static_cast<std::size_t>(fn.width) << ","
                      << i / static_cast<std::size_t>(fn.width)
                      << " differs from the functional fp24 model (replay it with --pixel)";
    EXPECT_EQ(bad, 0);
    EXPECT_EQ(cy.frame.rgb, fn.rgb) << "image";
    EXPECT_EQ(cy.frame.units.traversal_ops, fn.units.traversal_ops);
    EXPECT_EQ(cy.frame.units.transformation_ops, fn.units.transformation_ops);
    EXPECT_EQ(cy.frame.units.intersection_ops, fn.units.intersection_ops);
    // Every ray issued returns exactly once; every packet frees its thread.
    for (int k = 0; k < units::kRayKinds; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      EXPECT_EQ(cy.frame.rays_issued[kk], cy.frame.rays_returned[kk])
          << units::ray_kind_name(static_cast<units::RayKind>(k)) << " rays";
      EXPECT_EQ(cy.frame.rays_issued[kk], fn.rays_issued[kk])
          << units::ray_kind_name(static_cast<units::RayKind>(k)) << " rays";
    }
    EXPECT_EQ(cy.frame.rays_issued[0],
              static_cast<std::uint64_t>(fn.width) * static_cast<std::uint64_t>(fn.height));
    EXPECT_EQ(cy.packets_retired, cy.packets);
    EXPECT_GT(cy.cycles, 0u);
  }

  std::vector<StressScene> scenes_;
  int shrink_;
  // Per scene: the key (scene, resolution, kd.* keys, depth) of the image it holds.
  std::map<std::string, std::optional<std::pair<std::string, PreparedScene>>> cache_;
  StressTotals totals_;
};

}  // namespace saarcor::stress
