// The cycle model's parameters (docs/cycle-model.md, docs/memif.md and docs/fidelity.md; decisions
// D7, D20-D33): one table declares every parameter once (name, default, unit, help, range); presets
// are data (named sets of overrides); `--set KEY=VALUE` goes through the same table. The defaults
// are the paper's prototype: one DynRTP, 64 threads of 4-ray packets, 512-item direct-mapped
// caches, 90 MHz.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace saarcor::memif {
struct MemorySystemConfig;
}

namespace saarcor::units {

// Item caches of the DynRTC by the unit that reads them.
enum class CacheUnit { kTraversal = 0, kList = 1, kTransformation = 2 };
inline constexpr int kCacheUnits = 3;
constexpr const char* cache_unit_name(CacheUnit c) {
  constexpr const char* kNames[] = {"traversal", "list", "transformation"};
  return kNames[static_cast<int>(c)];
}

struct CycleParams {
  int pipelines = 0;            // DynRTPs sharing the memory controller (D44)
  int threads = 0;              // threads per DynRTP (D24)
  int packet = 0;               // rays per packet
  int stack = 0;                // traversal stack entries per packet (D26)
  int mailbox = 0;              // object mailbox entries per thread (D28)
  int triangle_mailbox = 0;     // triangle mailbox entries per thread (the list unit, bottom level)
  bool shared_origin = true;    // the n+1 transformation rule (D31)
  bool clip_exit_only = true;   // box clips of packets starting inside the box: exit faces only
  bool skip_empty = true;       // empty children flagged in their parent are never stepped into
  int clip_faces_per_step = 1;  // box faces divided per clip step (dividers per ray)
  struct Cache {
    int items = 0;
    int ways = 0;
  } cache[kCacheUnits];
  int cache_hit_latency = 0;
  int cache_misses = 0;  // outstanding misses per cache (MSHRs)
  int mem_latency = 0;   // SRAM read latency in cycles (D21)
  int mem_switch_penalty = 0;
  int mem_scene_paths = 0;  // issue paths over the three scene banks: 1 (shared) or 3 (D21)
  // The memory interface's remaining knobs (docs/memif.md; memif::MemorySystemConfig).
  int mem_queue_depth = 0;      // requests per bank queue in the memory controller (D23)
  int mem_max_burst = 0;        // starts in a row on a path's open bank while other banks wait
  bool mem_reorder = true;      // prefer the open bank (D23); false: oldest request first
  int mem_port_capacity = 0;    // request and response channel capacity per controller port
  int cache_merge_targets = 0;  // requests waiting on one outstanding miss, the first included
  int cache_request_queue = 0;  // unit -> cache request FIFO entries
  int cache_memory_queue = 0;   // cache <-> routing memory request and fill channel entries
  int routing_responses = 0;    // responses the routing's labelled broadcast delivers per cycle
  double hostbus_mb_s = 0.0;    // host-bus upload bandwidth, MB = 2^20 bytes (D40)
  int hostbus_burst_words = 0;  // words per host-bus write burst
  int lat_add = 0, lat_mul = 0, lat_div = 0, lat_cmp = 0;  // fp unit latencies (D7)
  int rgs_depth = 0;  // RGS shading pipeline (cycles after issue or after the last shading word)
  double clock_mhz = 0.0;
  std::uint64_t watchdog = 0;  // cycles without progress that stop a run

  // Pipeline depths of the units, from the fp latencies (docs/cycle-model.md).
  int traversal_depth() const { return lat_add + lat_div + lat_cmp; }
  int list_depth() const { return lat_cmp; }
  int transformation_depth() const { return lat_mul + lat_add + lat_add; }
  int intersection_depth() const { return lat_div + lat_mul + lat_add + lat_add + lat_cmp; }
};

struct CycleParamInfo {
  std::string name;
  double value;  // the default (in param_table()) or the current value (in describe())
  std::string unit;
  std::string help;
  double min, max;
  bool pow2;  // must be a power of two
};

// Every parameter, with its default.
const std::vector<CycleParamInfo>& cycle_param_table();
// The prototype configuration (the table's defaults).
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
// Cross-parameter checks (cache ways divide items, pipelines x threads); throws naming the key.
void check_cycle_params(const CycleParams& params);
// The resolved configuration: every parameter with its current value.
std::vector<CycleParamInfo> describe(const CycleParams& params);
// The memory interface the parameters describe (pipelines, caches, controller, routing, host
// bus): what the cycle model's chip instantiates (testbench/chip.cpp).
memif::MemorySystemConfig memory_system_config(const CycleParams& params);

}  // namespace saarcor::units
