// The cycle model's parameters (docs/cycle-model.md, docs/memif.md and docs/fidelity.md; decisions
// D7, D20-D33): one parameter table (hw/param_table.h) declares every key once with its type,
// unit, range and help, bound to a field of CycleParams, whose default member initialiser is the
// key's default: the paper's prototype (one DynRTP, 64 threads of 4-ray packets, 512-item
// direct-mapped caches, 90 MHz). The memory interface's keys start from memif's own defaults
// (memif/config.h) and the watchdog from the kernel's, so neither is declared twice. Presets are
// data (named sets of overrides); `--set KEY=VALUE` goes through the same table.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "hw/kernel.h"
#include "hw/param_table.h"
#include "memif/config.h"

namespace saarcor::units {

// Item caches of the DynRTC by the unit that reads them.
enum class CacheUnit { kTraversal = 0, kList = 1, kTransformation = 2 };
inline constexpr int kCacheUnits = 3;
constexpr const char* cache_unit_name(CacheUnit c) {
  constexpr const char* kNames[] = {"traversal", "list", "transformation"};
  return kNames[static_cast<int>(c)];
}

// memif's defaults, built once (MemoryControllerConfig holds a vector).
inline const memif::MemorySystemConfig& memif_defaults() {
  static const memif::MemorySystemConfig d;
  return d;
}

struct CycleParams {
  int pipelines = memif_defaults().pipelines;  // DynRTPs sharing the memory controller (D44)
  int threads = 64;                            // threads per DynRTP (D24)
  int packet = 4;                              // rays per packet
  int stack = 64;                              // traversal stack entries per packet (D26)
  int mailbox = 8;                             // object mailbox entries per thread (D28)
  int triangle_mailbox = 8;     // triangle mailbox entries per thread (the list unit, bottom level)
  bool shared_origin = true;    // the n+1 transformation rule (D31)
  bool clip_exit_only = true;   // box clips of packets starting inside the box: exit faces only
  bool skip_empty = true;       // empty children flagged in their parent are never stepped into
  int clip_faces_per_step = 1;  // box faces divided per clip step (dividers per ray)
  struct Cache {
    int items = memif::CacheConfig{}.items;
    int ways = memif::CacheConfig{}.ways;
  } cache[kCacheUnits];
  int cache_hit_latency = memif::CacheConfig{}.hit_latency;
  int cache_misses = memif::CacheConfig{}.max_misses;     // outstanding misses per cache (MSHRs)
  int mem_latency = memif_defaults().controller.latency;  // SRAM read latency in cycles (D21)
  int mem_switch_penalty = memif_defaults().controller.switch_penalty;
  // Issue paths over the three scene banks (D21): 3, one per bank as the prototype's independent
  // SRAMs (memif's own default shares one path: 1).
  int mem_scene_paths = 3;
  // The memory interface's remaining knobs (docs/memif.md; memif::MemorySystemConfig).
  int mem_queue_depth = memif_defaults().controller.queue_depth;      // per bank queue (D23)
  int mem_max_burst = memif_defaults().controller.max_burst;          // starts in a row, open bank
  bool mem_reorder = memif_defaults().controller.reorder;             // prefer the open bank (D23)
  int mem_port_capacity = memif_defaults().controller.port_capacity;  // per controller port
  // Requests waiting on one outstanding miss, the first included; unit -> cache request FIFO
  // entries; cache <-> routing memory request and fill channel entries.
  int cache_merge_targets = memif::CacheConfig{}.max_targets;
  int cache_request_queue = memif::CacheConfig{}.request_capacity;
  int cache_memory_queue = memif::CacheConfig{}.memory_capacity;
  // Responses the routing's labelled broadcast delivers per cycle.
  int routing_responses = memif_defaults().responses_per_cycle;
  double hostbus_mb_s = memif_defaults().host.mb_per_s;         // MB = 2^20 bytes (D40)
  int hostbus_burst_words = memif_defaults().host.burst_words;  // words per host-bus write burst
  int lat_add = 3, lat_mul = 3, lat_div = 8, lat_cmp = 1;       // fp unit latencies (D7)
  int rgs_depth = 8;  // RGS shading pipeline (cycles after issue or after the last shading word)
  double clock_mhz = memif::kDefaultClockHz / 1e6;
  std::uint64_t watchdog = hw::KernelConfig{}.watchdog_cycles;  // cycles without progress

  // Pipeline depths of the units, from the fp latencies (docs/cycle-model.md).
  int traversal_depth() const { return lat_add + lat_div + lat_cmp; }
  int list_depth() const { return lat_cmp; }
  int transformation_depth() const { return lat_mul + lat_add + lat_add; }
  int intersection_depth() const { return lat_div + lat_mul + lat_add + lat_add + lat_cmp; }
};

// A key as declared (hw::ParamInfo: name, value, unit, help, range, type).
using CycleParamInfo = hw::ParamInfo;

// Every parameter, with its default (CycleParams{}'s).
const std::vector<CycleParamInfo>& cycle_param_table();
// The prototype configuration: CycleParams{}.
CycleParams prototype_params();
// Names of the presets ("prototype", ...).
std::vector<std::string> cycle_preset_names();
// The preset `name`; throws std::runtime_error "unknown --preset 'x' (known: ...)".
CycleParams cycle_preset(const std::string& name);
// Applies "KEY=VALUE"; throws std::runtime_error naming the key for an unknown key, a value that
// is not a number, or one out of range.
void apply_cycle_setting(CycleParams& params, const std::string& key_value);
// Threads of all DynRTPs together at most (pipelines x threads).
inline constexpr int kMaxChipThreads = 4096;
// Every key's value valid (a configuration built in code), then the cross-parameter checks (cache
// ways divide items, pipelines x threads); throws one line naming the key.
void check_cycle_params(const CycleParams& params);
// The resolved configuration: every parameter with its current value.
std::vector<CycleParamInfo> describe(const CycleParams& params);
// The memory interface the parameters describe (pipelines, caches, controller, routing, host
// bus): what the cycle model's chip instantiates (testbench/chip.cpp).
memif::MemorySystemConfig memory_system_config(const CycleParams& params);

}  // namespace saarcor::units
