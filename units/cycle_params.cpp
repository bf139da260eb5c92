// The cycle model's parameter table and presets (docs/cycle-model.md "Parameters").
#include "units/cycle_params.h"

#include <stdexcept>

#include "memif/request.h"

namespace saarcor::units {
namespace {

using Table = hw::ParamTable<CycleParams>;

// Accessors of cache c's fields (the table binds nested fields through one).
template <int c>
constexpr auto items = [](auto& p) -> auto& {
  return p.cache[c].items;
};
template <int c>
constexpr auto ways = [](auto& p) -> auto& {
  return p.cache[c].ways;
};

// The thread and its units (DynRTPs, threads, packets, stack, mailboxes, clip, traversal).
void declare_threads(Table& t) {
  t.integer("pipelines", &CycleParams::pipelines, "DynRTPs", 1, 16,
            "dynamic ray tracing pipelines sharing the memory controller; the RGC grants them "
            "packets round robin, one pipeline per cycle (D44)")
      .integer("threads", &CycleParams::threads, "threads", 1, 4096,
               "threads (packets in flight) per DynRTP (D24)")
      .power_of_two("packet", &CycleParams::packet, "rays", 1, 64,
                    "rays per packet, a power of two (D24)")
      .integer("stack", &CycleParams::stack, "entries", 1, 4096,
               "traversal stack entries per packet (D26)")
      .integer("mailbox", &CycleParams::mailbox, "entries", 0, 64,
               "object mailbox entries per thread, 0 = off (D28)")
      .integer("triangle_mailbox", &CycleParams::triangle_mailbox, "entries", 0, 64,
               "triangle mailbox entries per thread: the list unit skips triangles the packet's "
               "rays already tested (bottom-level lists), 0 = off")
      .boolean("shared_origin", &CycleParams::shared_origin,
               "n+1 transformation steps for shared-origin packets (D31)")
      .boolean("clip.exit_only", &CycleParams::clip_exit_only,
               "a box clip whose rays all start inside the box divides for the 3 exit faces only "
               "(3 traversal steps instead of 6)")
      .integer("clip.faces_per_step", &CycleParams::clip_faces_per_step, "faces", 1, 6,
               "box faces a clip step divides for: 1 = one divider per ray (Table 2), up to 6")
      .boolean("traversal.skip_empty", &CycleParams::skip_empty,
               "inner nodes flag empty children and the traversal never steps into them");
}

// The DynRTC caches (paper section 4: one per unit).
void declare_caches(Table& t) {
  t.power_of_two("cache.traversal.items", items<0>, "items", 1, 1 << 20,
                 "kd-node cache lines (D20)")
      .integer("cache.traversal.ways", ways<0>, "ways", 1, 64, "kd-node cache associativity")
      .power_of_two("cache.list.items", items<1>, "items", 1, 1 << 20,
                    "list-entry cache lines (D20)")
      .integer("cache.list.ways", ways<1>, "ways", 1, 64, "list-entry cache associativity")
      .power_of_two("cache.transformation.items", items<2>, "items", 1, 1 << 20,
                    "matrix-row cache lines (D20)")
      .integer("cache.transformation.ways", ways<2>, "ways", 1, 64,
               "matrix-row cache associativity")
      .integer("cache.hit_latency", &CycleParams::cache_hit_latency, "cycles", 2, 64,
               "cache hit: request push to response")
      .integer("cache.misses", &CycleParams::cache_misses, "misses", 1, 256,
               "outstanding misses per cache (MSHRs, D20)")
      .integer("cache.merge_targets", &CycleParams::cache_merge_targets, "requests", 1, 1024,
               "requests waiting on one outstanding miss, the first included (secondary misses "
               "merged per MSHR); a full MSHR holds the cache, 1 = no merging")
      .integer("cache.request_queue", &CycleParams::cache_request_queue, "entries", 1, 256,
               "request FIFO from a unit into its cache; full = the unit waits")
      .integer("cache.memory_queue", &CycleParams::cache_memory_queue, "entries", 1, 256,
               "each cache's memory-request and fill channels to and from the simple routing");
}

// The memory controller, the routing of responses and the host bus.
void declare_memory(Table& t) {
  t.integer("mem.latency", &CycleParams::mem_latency, "cycles", 1, 1000, "SRAM read latency (D21)")
      .integer("mem.switch_penalty", &CycleParams::mem_switch_penalty, "cycles", 0, 100,
               "bank switch penalty on a shared path (D21)")
      .choice("mem.scene_paths", &CycleParams::mem_scene_paths, "paths", {1, 3},
              "issue paths over the three scene banks: 3 = one path per bank, as the "
              "prototype's six independent SRAM banks (D21), 1 = one word per cycle from any of "
              "them")
      .integer("mem.queue_depth", &CycleParams::mem_queue_depth, "requests", 1, 1024,
               "requests per bank queue in the memory controller; a full queue holds the port the "
               "request came from (D23)")
      .boolean("mem.reorder", &CycleParams::mem_reorder,
               "an issue path keeps serving its open bank to avoid bank switches (D23); 0 = the "
               "path's oldest request first")
      .integer("mem.max_burst", &CycleParams::mem_max_burst, "starts", 1, 1024,
               "with mem.reorder: starts in a row on a path's open bank while its other banks "
               "wait")
      .integer("mem.port_capacity", &CycleParams::mem_port_capacity, "entries", 2, 256,
               "request and response channel capacity of each memory-controller port (the "
               "caches' routing, shading, frame buffer, host bus)")
      .integer("routing.responses", &CycleParams::routing_responses, "responses/cycle", 1, 64,
               "memory responses the simple routing's labelled broadcast delivers per cycle "
               "(D23)")
      .real("hostbus.mb_s", &CycleParams::hostbus_mb_s, "MB/s", 0.001, 1e6,
            "host-bus upload bandwidth, MB = 2^20 bytes (D40: 32-bit PCI at 33 MHz)")
      .integer("hostbus.burst_words", &CycleParams::hostbus_burst_words, "words", 1,
               memif::kMaxRequestWords, "words per host-bus write burst into a bank");
}

// The float operators, the RGS's shading pipeline, the clock and the watchdog.
void declare_operators(Table& t) {
  t.integer("lat.add", &CycleParams::lat_add, "cycles", 1, 64, "fp adder latency (D7)")
      .integer("lat.mul", &CycleParams::lat_mul, "cycles", 1, 64, "fp multiplier latency (D7)")
      .integer("lat.div", &CycleParams::lat_div, "cycles", 1, 64, "fp divider latency")
      .integer("lat.cmp", &CycleParams::lat_cmp, "cycles", 1, 64, "fp comparator latency (D7)")
      .integer("rgs.depth", &CycleParams::rgs_depth, "cycles", 1, 1000,
               "the RGS's shading pipeline: from a request's issue, or from the last shading-bank "
               "word it read, to its result (integer texture filter, colour products, "
               "accumulation)")
      .real("clock_mhz", &CycleParams::clock_mhz, "MHz", 0.001, 100000,
            "modelled clock (the prototype's 90 MHz)")
      .integer("watchdog", &CycleParams::watchdog, "cycles", 1, 1e12,
               "cycles without progress that stop a run");
}

const Table& table() {
  static const Table t = [] {
    Table t("--set", "known");
    declare_threads(t);
    declare_caches(t);
    declare_memory(t);
    declare_operators(t);
    return t;
  }();
  return t;
}

// Presets are data: named overrides of the table's defaults.
struct Preset {
  const char* name;
  const char* help;
  std::vector<std::pair<const char*, const char*>> settings;
};
const std::vector<Preset>& presets() {
  static const std::vector<Preset> p = {
      {"prototype", "the paper's FPGA prototype (Table 4): 64 threads, 4-ray packets, 90 MHz", {}},
      {"table2", "Table 2's counted configuration: 32 threads", {{"threads", "32"}}},
      {"standard",
       "the 'standard' SaarCOR configuration the paper simulated (section 5): four DynRTPs of the "
       "prototype's",
       {{"pipelines", "4"}}},
  };
  return p;
}

}  // namespace

const std::vector<CycleParamInfo>& cycle_param_table() {
  static const std::vector<CycleParamInfo> t = table().defaults();
  return t;
}

CycleParams prototype_params() {
  return CycleParams{};
}

std::vector<std::string> cycle_preset_names() {
  std::vector<std::string> n;
  for (const auto& p : presets())
    n.emplace_back(p.name);
  return n;
}

CycleParams cycle_preset(const std::string& name) {
  for (const auto& pr : presets()) {
    if (name != pr.name) continue;
    CycleParams p = prototype_params();
    for (const auto& [k, v] : pr.settings)
      apply_cycle_setting(p, std::string(k) + "=" + v);
    return p;
  }
  std::string known;
  for (const auto& pr : presets())
    known += (known.empty() ? "" : ", ") + std::string(pr.name);
  throw std::runtime_error("unknown --preset '" + name + "' (known: " + known + ")");
}

void apply_cycle_setting(CycleParams& params, const std::string& key_value) {
  table().apply(params, key_value);
}

void check_cycle_params(const CycleParams& p) {
  table().check(p);
  for (int c = 0; c < kCacheUnits; ++c) {
    const auto& cc = p.cache[c];
    if (cc.ways > cc.items || cc.items % cc.ways != 0)
      throw std::runtime_error(std::string("bad cache.") + cache_unit_name(CacheUnit(c)) +
                               ".ways=" + std::to_string(cc.ways) + ": must divide cache." +
                               cache_unit_name(CacheUnit(c)) +
                               ".items=" + std::to_string(cc.items));
  }
  if (p.pipelines * p.threads > kMaxChipThreads)
    throw std::runtime_error("bad pipelines=" + std::to_string(p.pipelines) +
                             " with threads=" + std::to_string(p.threads) + ": " +
                             std::to_string(p.pipelines * p.threads) + " threads in all, at most " +
                             std::to_string(kMaxChipThreads));
}

std::vector<CycleParamInfo> describe(const CycleParams& params) {
  return table().describe(params);
}

}  // namespace saarcor::units
