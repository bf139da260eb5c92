// The Verilated per-type cache (rtl/cache.sv) behind one interface, whichever of its builds (each
// parameter set is one Verilator build, rtl/CMakeLists.txt SAARCOR_CACHE_BUILDS): one clock cycle
// per call, the inputs of that cycle in, the outputs of that cycle out. One build serves the three
// item types and every cache size up to its arrays: the run's lines, ways, item words and region
// base are the cache's configuration inputs.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "memif/image_format.h"
#include "rtl/unit_rtl.h"

namespace saarcor::rtl {

// A Verilated build of cache.sv: its SystemVerilog parameters.
struct CacheBuild {
  std::string name;
  int items = 0, ways = 0, words = 0;  // the arrays: the most lines, ways and item words
  int hit_latency = 0, misses = 0, targets = 0, request_queue = 0, memory_queue = 0;
  int fault = 0;  // tests only: 1 a merge joins the wrong MSHR
};
const std::vector<CacheBuild>& cache_builds();

// The run's cache: lines and ways (powers of two), item words, the type's region base.
struct CacheSizes {
  int items = 512, ways = 1, words = 2;
  std::uint32_t base = 0;
};

// One cycle's inputs: a request the unit pushes, the routing taking the oldest line request, a
// fill the routing pushes.
struct CacheInputs {
  bool req = false;
  std::uint32_t req_index = 0, req_requester = 0, req_tag = 0;
  bool mem_take = false;
  bool fill = false;
  std::uint32_t fill_tag = 0;
  std::array<std::uint32_t, memif::kMaxRequestWords> fill_words{};
};

struct CacheOutputs {
  bool req_ready = false, fill_ready = false;  // (as the cycle's inputs found them)
  bool accept = false;
  std::uint32_t acc_index = 0, acc_requester = 0, acc_tag = 0, acc_kind = 0, acc_mshr = 0;
  bool resp = false;
  std::uint32_t resp_index = 0, resp_requester = 0, resp_tag = 0;
  std::array<std::uint32_t, memif::kMaxRequestWords> resp_words{};
  bool mreq = false;
  std::uint32_t mreq_tag = 0, mreq_bank = 0, mreq_offset = 0, mreq_words = 0;
};

class CacheRtl {
 public:
  virtual ~CacheRtl() = default;
  // Two reset cycles with the configuration applied; the next cycle() is cycle 0.
  virtual void reset(const CacheSizes& c) = 0;
  virtual CacheOutputs cycle(const CacheInputs& in) = 0;
  virtual void start_trace(const std::string& path) = 0;
  virtual void stop_trace() = 0;
};

std::unique_ptr<CacheRtl> make_cache_rtl(const CacheBuild& build);

// The cache serving `unit` (the traversal unit: kd-nodes; list: list entries; transformation:
// matrix rows) behind the lockstep's interface: the caches' record (units/boundary_cache.h) to
// and from its ports. Inputs: cache_request, mem_taken, mem_fill; outputs: cache_accept,
// cache_reply, mem_request.
std::unique_ptr<UnitRtl> make_cache_unit_rtl(const CacheBuild& build, units::UnitId unit,
                                             const CacheSizes& config);

}  // namespace saarcor::rtl
