// The covering design of cycle-model configurations (threads, packet width, pipelines, tiny and
// two-way caches, random latencies, one shared scene path, shadow and secondary rays): eight
// configurations that together meet every pair of those choices. The bit-exactness tests run
// every scene under them (testbench/dynrtc_testing.h), and `saarcor sample-check` validates the
// sampled simulation under them (testbench/sample_check.h).
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "units/cycle_params.h"
#include "units/functional_model.h"

namespace saarcor::covering {

// A configuration of the covering design.
struct Config {
  const char* name;
  std::vector<std::string> set;
  bool shadows_and_secondary = false;
  std::uint64_t random_latencies = 0;  // != 0: seed for random lat.* and mem.latency
};

inline const std::vector<Config>& configs() {
  static const std::vector<Config> c = {
      {"prototype", {}},
      {"t1-p1-tiny",
       {"threads=1", "packet=1", "cache.traversal.items=8", "cache.list.items=8",
        "cache.transformation.items=8"}},
      {"t4x3-p16-tiny-2way",
       {"pipelines=3", "threads=4", "packet=16", "cache.traversal.items=8",
        "cache.traversal.ways=2", "cache.list.items=8", "cache.list.ways=2",
        "cache.transformation.items=8", "cache.transformation.ways=2"}},
      {"t16x2-p4-random-lat-1path", {"pipelines=2", "threads=16", "mem.scene_paths=1"}, false, 7},
      {"t64-p16-tiny",
       {"packet=16", "cache.traversal.items=8", "cache.list.items=8",
        "cache.transformation.items=8", "mailbox=2"}},
      {"t4x4-p1-random-lat-shadows", {"pipelines=4", "threads=4", "packet=1"}, true, 11},
      {"t64-p4-shadows-secondary", {"stack=48", "cache.misses=2"}, true},
      {"t16-p16-random-lat-tiny",
       {"threads=16", "packet=16", "cache.traversal.items=8", "cache.list.items=8",
        "cache.transformation.items=8", "shared_origin=0"},
       false,
       23},
  };
  return c;
}

inline units::CycleParams params_of(const Config& c) {
  units::CycleParams p = units::prototype_params();
  for (const auto& kv : c.set)
    units::apply_cycle_setting(p, kv);
  if (c.random_latencies != 0) {
    std::mt19937 rng(static_cast<unsigned>(c.random_latencies));
    std::uniform_int_distribution<int> d(1, 12), m(1, 40);
    p.lat_add = d(rng);
    p.lat_mul = d(rng);
    p.lat_div = d(rng);
    p.lat_cmp = d(rng);
    p.mem_latency = m(rng);
    p.cache_hit_latency = 2 + d(rng) % 4;
  }
  return p;
}

inline units::FunctionalParams shading_of(const Config& c) {
  units::FunctionalParams f;
  f.shadows = c.shadows_and_secondary;
  f.secondary = c.shadows_and_secondary;
  return f;
}

}  // namespace saarcor::covering
