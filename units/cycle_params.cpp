// The cycle model's parameter table and presets (docs/cycle-model.md "Parameters").
#include "units/cycle_params.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "memif/request.h"

namespace saarcor::units {
namespace {

struct Binding {
  CycleParamInfo info;
  double (*get)(const CycleParams&);
  void (*set)(CycleParams&, double);
};

#define SAARCOR_FIELD(expr, type)                                   \
  [](const CycleParams& p) { return static_cast<double>(p.expr); }, \
      [](CycleParams& p, double v) { p.expr = static_cast<type>(v); }

// The thread and its units (DynRTPs, threads, packets, stack, mailboxes, clip, traversal).
std::vector<Binding> thread_bindings() {
  return {
      {{"pipelines", 1, "DynRTPs",
        "dynamic ray tracing pipelines sharing the memory controller; the RGC grants them packets "
        "round robin, one pipeline per cycle (D44)",
        1, 16, false},
       SAARCOR_FIELD(pipelines, int)},
      {{"threads", 64, "threads", "threads (packets in flight) per DynRTP (D24)", 1, 4096, false},
       SAARCOR_FIELD(threads, int)},
      {{"packet", 4, "rays", "rays per packet, a power of two (D24)", 1, 64, true},
       SAARCOR_FIELD(packet, int)},
      {{"stack", 64, "entries", "traversal stack entries per packet (D26)", 1, 4096, false},
       SAARCOR_FIELD(stack, int)},
      {{"mailbox", 8, "entries", "object mailbox entries per thread, 0 = off (D28)", 0, 64, false},
       SAARCOR_FIELD(mailbox, int)},
      {{"triangle_mailbox", 8, "entries",
        "triangle mailbox entries per thread: the list unit skips triangles the packet's rays "
        "already tested (bottom-level lists), 0 = off",
        0, 64, false},
       SAARCOR_FIELD(triangle_mailbox, int)},
      {{"shared_origin", 1, "bool", "n+1 transformation steps for shared-origin packets (D31)", 0,
        1, false},
       SAARCOR_FIELD(shared_origin, bool)},
      {{"clip.exit_only", 1, "bool",
        "a box clip whose rays all start inside the box divides for the 3 exit faces only (3 "
        "traversal steps instead of 6)",
        0, 1, false},
       SAARCOR_FIELD(clip_exit_only, bool)},
      {{"clip.faces_per_step", 1, "faces",
        "box faces a clip step divides for: 1 = one divider per ray (Table 2), up to 6", 1, 6,
        false},
       SAARCOR_FIELD(clip_faces_per_step, int)},
      {{"traversal.skip_empty", 1, "bool",
        "inner nodes flag empty children and the traversal never steps into them", 0, 1, false},
       SAARCOR_FIELD(skip_empty, bool)},
  };
}

// The DynRTC caches (paper section 4: one per unit).
std::vector<Binding> cache_bindings() {
  return {
      {{"cache.traversal.items", 512, "items", "kd-node cache lines (D20)", 1, 1 << 20, true},
       SAARCOR_FIELD(cache[0].items, int)},
      {{"cache.traversal.ways", 1, "ways", "kd-node cache associativity", 1, 64, false},
       SAARCOR_FIELD(cache[0].ways, int)},
      {{"cache.list.items", 512, "items", "list-entry cache lines (D20)", 1, 1 << 20, true},
       SAARCOR_FIELD(cache[1].items, int)},
      {{"cache.list.ways", 1, "ways", "list-entry cache associativity", 1, 64, false},
       SAARCOR_FIELD(cache[1].ways, int)},
      {{"cache.transformation.items", 512, "items", "matrix-row cache lines (D20)", 1, 1 << 20,
        true},
       SAARCOR_FIELD(cache[2].items, int)},
      {{"cache.transformation.ways", 1, "ways", "matrix-row cache associativity", 1, 64, false},
       SAARCOR_FIELD(cache[2].ways, int)},
      {{"cache.hit_latency", 2, "cycles", "cache hit: request push to response", 2, 64, false},
       SAARCOR_FIELD(cache_hit_latency, int)},
      {{"cache.misses", 8, "misses", "outstanding misses per cache (MSHRs, D20)", 1, 256, false},
       SAARCOR_FIELD(cache_misses, int)},
      {{"cache.merge_targets", 16, "requests",
        "requests waiting on one outstanding miss, the first included (secondary misses merged "
        "per MSHR); a full MSHR holds the cache, 1 = no merging",
        1, 1024, false},
       SAARCOR_FIELD(cache_merge_targets, int)},
      {{"cache.request_queue", 4, "entries",
        "request FIFO from a unit into its cache; full = the unit waits", 1, 256, false},
       SAARCOR_FIELD(cache_request_queue, int)},
      {{"cache.memory_queue", 2, "entries",
        "each cache's memory-request and fill channels to and from the simple routing", 1, 256,
        false},
       SAARCOR_FIELD(cache_memory_queue, int)},
  };
}

// The memory controller, the routing of responses and the host bus.
std::vector<Binding> memory_bindings() {
  return {
      {{"mem.latency", 4, "cycles", "SRAM read latency (D21)", 1, 1000, false},
       SAARCOR_FIELD(mem_latency, int)},
      {{"mem.switch_penalty", 1, "cycles", "bank switch penalty on a shared path (D21)", 0, 100,
        false},
       SAARCOR_FIELD(mem_switch_penalty, int)},
      {{"mem.scene_paths", 3, "paths",
        "issue paths over the three scene banks: 3 = one path per bank, as the prototype's six "
        "independent SRAM banks (D21), 1 = one word per cycle from any of them",
        1, 3, false},
       SAARCOR_FIELD(mem_scene_paths, int)},
      {{"mem.queue_depth", 8, "requests",
        "requests per bank queue in the memory controller; a full queue holds the port the "
        "request came from (D23)",
        1, 1024, false},
       SAARCOR_FIELD(mem_queue_depth, int)},
      {{"mem.reorder", 1, "bool",
        "an issue path keeps serving its open bank to avoid bank switches (D23); 0 = the path's "
        "oldest request first",
        0, 1, false},
       SAARCOR_FIELD(mem_reorder, bool)},
      {{"mem.max_burst", 8, "starts",
        "with mem.reorder: starts in a row on a path's open bank while its other banks wait", 1,
        1024, false},
       SAARCOR_FIELD(mem_max_burst, int)},
      {{"mem.port_capacity", 4, "entries",
        "request and response channel capacity of each memory-controller port (the caches' "
        "routing, shading, frame buffer, host bus)",
        2, 256, false},
       SAARCOR_FIELD(mem_port_capacity, int)},
      {{"routing.responses", 1, "responses/cycle",
        "memory responses the simple routing's labelled broadcast delivers per cycle (D23)", 1, 64,
        false},
       SAARCOR_FIELD(routing_responses, int)},
      {{"hostbus.mb_s", 132, "MB/s",
        "host-bus upload bandwidth, MB = 2^20 bytes (D40: 32-bit PCI at 33 MHz)", 0.001, 1e6,
        false},
       SAARCOR_FIELD(hostbus_mb_s, double)},
      {{"hostbus.burst_words", 4, "words", "words per host-bus write burst into a bank", 1,
        memif::kMaxRequestWords, false},
       SAARCOR_FIELD(hostbus_burst_words, int)},
  };
}

// The float operators, the RGS's shading pipeline, the clock and the watchdog.
std::vector<Binding> operator_bindings() {
  return {
      {{"lat.add", 3, "cycles", "fp adder latency (D7)", 1, 64, false},
       SAARCOR_FIELD(lat_add, int)},
      {{"lat.mul", 3, "cycles", "fp multiplier latency (D7)", 1, 64, false},
       SAARCOR_FIELD(lat_mul, int)},
      {{"lat.div", 8, "cycles", "fp divider latency", 1, 64, false}, SAARCOR_FIELD(lat_div, int)},
      {{"lat.cmp", 1, "cycles", "fp comparator latency (D7)", 1, 64, false},
       SAARCOR_FIELD(lat_cmp, int)},
      {{"rgs.depth", 8, "cycles",
        "the RGS's shading pipeline: from a request's issue, or from the last shading-bank word "
        "it read, to its result (integer texture filter, colour products, accumulation)",
        1, 1000, false},
       SAARCOR_FIELD(rgs_depth, int)},
      {{"clock_mhz", 90, "MHz", "modelled clock (the prototype's 90 MHz)", 0.001, 100000, false},
       SAARCOR_FIELD(clock_mhz, double)},
      {{"watchdog", 100000, "cycles", "cycles without progress that stop a run", 1, 1e12, false},
       SAARCOR_FIELD(watchdog, std::uint64_t)},
  };
}

const std::vector<Binding>& bindings() {
  static const std::vector<Binding> table = [] {
    std::vector<Binding> t;
    for (auto* group : {thread_bindings, cache_bindings, memory_bindings, operator_bindings}) {
      const std::vector<Binding> g = group();
      t.insert(t.end(), g.begin(), g.end());
    }
    return t;
  }();
  return table;
}
#undef SAARCOR_FIELD

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

std::string known_keys() {
  std::string s;
  for (const auto& b : bindings())
    s += (s.empty() ? "" : ", ") + b.info.name;
  return s;
}

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.15g", v);
  return buf;
}

bool integral_param(const Binding& b) {
  return b.info.name != "clock_mhz" && b.info.name != "hostbus.mb_s";
}

// Keys whose range check_cycle_params enforces on parameters built in code (--set checks every
// key's range as it parses).
constexpr const char* kRangeChecked[] = {
    "cache.merge_targets", "cache.request_queue", "cache.memory_queue", "mem.queue_depth",
    "mem.reorder",         "mem.max_burst",       "mem.port_capacity",  "routing.responses",
    "hostbus.mb_s",        "hostbus.burst_words"};

}  // namespace

const std::vector<CycleParamInfo>& cycle_param_table() {
  static const std::vector<CycleParamInfo> t = [] {
    std::vector<CycleParamInfo> v;
    for (const auto& b : bindings())
      v.push_back(b.info);
    return v;
  }();
  return t;
}

CycleParams prototype_params() {
  CycleParams p;
  for (const auto& b : bindings())
    b.set(p, b.info.value);
  return p;
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
  const auto eq = key_value.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::runtime_error("bad --set '" + key_value + "': expected KEY=VALUE");
  const std::string key = key_value.substr(0, eq);
  const std::string text = key_value.substr(eq + 1);
  for (const auto& b : bindings()) {
    if (b.info.name != key) continue;
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size() || errno != 0 || !std::isfinite(v))
      throw std::runtime_error("bad --set " + key + "=" + text + ": not a number");
    const bool integral = integral_param(b);
    if (integral && v != std::floor(v))
      throw std::runtime_error("bad --set " + key + "=" + text + ": expected an integer");
    if (v < b.info.min || v > b.info.max)
      throw std::runtime_error("bad --set " + key + "=" + text + ": expected " + fmt(b.info.min) +
                               ".." + fmt(b.info.max) + " " + b.info.unit);
    if (b.info.pow2) {
      const auto n = static_cast<std::uint64_t>(v);
      if ((n & (n - 1)) != 0)
        throw std::runtime_error("bad --set " + key + "=" + text + ": expected a power of two");
    }
    b.set(params, v);
    return;
  }
  throw std::runtime_error("unknown --set key '" + key + "' (known: " + known_keys() + ")");
}

void check_cycle_params(const CycleParams& p) {
  for (const char* key : kRangeChecked) {
    for (const auto& b : bindings()) {
      if (b.info.name != key) continue;
      const double v = b.get(p);
      if (!std::isfinite(v) || v < b.info.min || v > b.info.max)
        throw std::runtime_error("bad " + b.info.name + "=" + fmt(v) + ": expected " +
                                 fmt(b.info.min) + ".." + fmt(b.info.max) + " " + b.info.unit);
    }
  }
  for (int c = 0; c < kCacheUnits; ++c) {
    const auto& cc = p.cache[c];
    if (cc.ways > cc.items || cc.items % cc.ways != 0)
      throw std::runtime_error(std::string("bad cache.") + cache_unit_name(CacheUnit(c)) +
                               ".ways=" + std::to_string(cc.ways) + ": must divide cache." +
                               cache_unit_name(CacheUnit(c)) +
                               ".items=" + std::to_string(cc.items));
  }
  if (p.threads < 1) throw std::runtime_error("bad threads=" + std::to_string(p.threads));
  if (p.mem_scene_paths != 1 && p.mem_scene_paths != 3)
    throw std::runtime_error("bad mem.scene_paths=" + std::to_string(p.mem_scene_paths) +
                             ": 1 (the banks share one path) or 3 (one path per bank)");
  if (p.pipelines < 1) throw std::runtime_error("bad pipelines=" + std::to_string(p.pipelines));
  if (p.pipelines * p.threads > kMaxChipThreads)
    throw std::runtime_error("bad pipelines=" + std::to_string(p.pipelines) +
                             " with threads=" + std::to_string(p.threads) + ": " +
                             std::to_string(p.pipelines * p.threads) + " threads in all, at most " +
                             std::to_string(kMaxChipThreads));
}

std::vector<CycleParamInfo> describe(const CycleParams& params) {
  std::vector<CycleParamInfo> v;
  for (const auto& b : bindings()) {
    CycleParamInfo i = b.info;
    i.value = b.get(params);
    v.push_back(i);
  }
  return v;
}

}  // namespace saarcor::units
