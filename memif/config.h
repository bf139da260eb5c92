// The memory interface's parameters and their defaults (docs/memif.md "Knobs"; decisions D20-D23,
// D39, D40, D44), apart from the modules they configure so that a parameter table can take its
// defaults from here without the modules' headers: each default is declared once, here, and the
// cycle model's configuration keys (units/cycle_params.h) start from these values.
#pragma once

#include <vector>

namespace saarcor::memif {

// The prototype's clock (90 MHz): bandwidth is reported in MB/s at it (D39), and the host bus
// turns its MB/s into credit per cycle at it.
inline constexpr double kDefaultClockHz = 90.0e6;

// A per-type item cache (memif/cache.h).
struct CacheConfig {
  int items = 512;       // lines (docs/memif.md)
  int ways = 1;          // associativity; items must be a multiple
  int hit_latency = 2;   // cycles from the unit's push to the response being poppable (>= 2)
  int max_misses = 8;    // outstanding misses (D20)
  int max_targets = 16;  // requests waiting on one miss (the first included)
  int ports = 1;         // request/response channel pairs (one per requesting unit)
  int request_capacity = 4;
  int memory_capacity = 2;  // capacity of the memory request and fill channels
};

// The memory controller and its banks (memif/memory_controller.h).
struct MemoryControllerConfig {
  int queue_depth = 8;     // per-bank request queue (D23)
  int latency = 4;         // cycles from a word's read slot to its data (D21: SRAM + pads)
  int switch_penalty = 1;  // cycles lost when a shared path starts another bank (D21)
  int max_burst = 8;       // consecutive starts on the open bank while other banks wait
  bool reorder = true;     // prefer the open bank (D23); false: oldest request first
  // Issue path of each bank; banks with the same number share one issue stage.
  std::vector<int> bank_path = {0, 1, 2, 3, 3, 3};
  int port_capacity = 4;              // request and response channel capacity per port
  double clock_hz = kDefaultClockHz;  // modelled clock, for MB/s (D39)
};

// The host bus (memif/host_bus.h).
struct HostBusConfig {
  double mb_per_s = 132.0;            // MB = 2^20 bytes (D39); 32-bit PCI at 33 MHz (D40)
  double clock_hz = kDefaultClockHz;  // the modelled core clock
  int burst_words = 4;                // 1..kMaxRequestWords
};

// The memory interface assembled (memif/memory_system.h).
struct MemorySystemConfig {
  int pipelines = 1;  // DynRTPs sharing the controller (D44)
  CacheConfig node_cache{};
  CacheConfig list_cache{};
  CacheConfig row_cache{};
  MemoryControllerConfig controller{};
  int responses_per_cycle = 1;  // labelled broadcast width of the simple routing (and of the
                                // controller's response channel to it)
  HostBusConfig host{};
};

}  // namespace saarcor::memif
