// Per-type item cache of a DynRTP (paper section 3: "individual caches for each type of data";
// Table 2: 512 items each; docs/memif.md; decision D20).
//
// One cache serves one item type (kd-nodes, list entries or matrix rows of MemoryImage); a line
// holds one item; the cache is read-only. Sets = items / ways, set = index mod sets, LRU within a
// set (direct-mapped by default). Non-blocking: up to `max_misses` outstanding misses (MSHRs);
// a request for an item whose fill is on its way is merged into that miss (a secondary miss:
// no second memory request).
//
// Unit-facing interface (the narrow one; all a unit needs):
//   requests(p)  unit pushes CacheRequest{index, label}. Latency 1, capacity `request_capacity`;
//                can_push() false = back-pressure (the cache is stalled on misses).
//   responses(p) unit pops CacheResponse{index, label, words, count}: one response per accepted
//                request of port p, exactly once, carrying the item's words as in the image.
//   p = 0 unless the cache was built with several ports (several units sharing one cache).
//   Timing: a hit pushed in cycle c is poppable at c + hit_latency. A miss takes the memory
//   round trip (see docs/memif.md for the exact count with the default parameters).
//   Ordering: hits answer in request order; a miss answers when its fill returns, so responses
//   may overtake each other: match them by label, never by order.
//   Throughput: one request looked up and one response delivered per cycle; delivering a
//   filled miss's waiting requests takes priority over new hits.
// Classification (what the counters mean): the tag array is updated when a miss is accepted,
// so the hit/miss decision depends only on the order of accepted requests:
//   hit    tag present, data present;
//   merge  tag present, fill pending (a blocking cache, or a simulation with instant fills,
//          would count it a hit);
//   miss   tag absent: a victim line is allocated (LRU) and one memory request is sent.
// Hence hits + merges and misses equal those of a plain cache simulation with instant fills on
// the same request sequence (the reference the tests use).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hw/kernel.h"
#include "hw/ring.h"
#include "memif/config.h"
#include "memif/image_format.h"
#include "memif/request.h"

namespace saarcor::memif {

class Cache;

// What a traced run observes of a cache's lookups (the Perfetto timeline, units/perfetto_trace.h;
// the lockstep's cache record, units/boundary_cache.h): a miss accepted with its MSHR and the
// label of the request that caused it, and the fill that answers it; a hit, and a request merged
// into MSHR `mshr`. Null in a run that traces nothing (one pointer test per lookup).
class CacheObserver {
 public:
  virtual ~CacheObserver() = default;
  virtual void miss(std::uint64_t cycle, const Cache& cache, std::uint32_t item, int mshr,
                    const Label& label) = 0;
  virtual void filled(std::uint64_t cycle, const Cache& cache, int mshr) = 0;
  virtual void hit(std::uint64_t /*cycle*/, const Cache& /*cache*/, const CacheRequest& /*r*/) {}
  virtual void merged(std::uint64_t /*cycle*/, const Cache& /*cache*/, const CacheRequest& /*r*/,
                      int /*mshr*/) {}
};

class Cache : public hw::Module {
 public:
  // `image` gives the item layout (MemoryImage::locate, item_words); the data come from memory.
  // `client` is the memory controller client id the cache's traffic is counted under.
  // Throws std::runtime_error for a bad configuration (one line naming the parameter).
  Cache(hw::Kernel& kernel, std::string name, ItemType type, const MemoryImage& image,
        std::uint16_t client, CacheConfig config = {});

  // Port p's channels (0 <= p < ports): a unit pushes requests into requests(p) and gets the
  // answers to exactly those requests from responses(p). Several ports share the cache's one
  // lookup and one response per cycle; among ports with a request the lookup goes round-robin.
  // Throws std::runtime_error (one line naming the parameter) if the configuration is refused;
  // returns the name. `words` = MemoryImage::item_words of the type.
  static std::string check(std::string name, const CacheConfig& config, int words);

  hw::Channel<CacheRequest>& requests(int port = 0) {
    return *requests_.at(static_cast<std::size_t>(port));
  }
  hw::Channel<CacheResponse>& responses(int port = 0) {
    return *responses_.at(static_cast<std::size_t>(port));
  }
  // Memory side, connected to the simple routing.
  hw::Channel<MemRequest>& memory_requests() { return mem_requests_; }
  hw::Channel<MemResponse>& fills() { return fills_; }

  // Drops every line (between frames, after a host upload; D20). Outstanding misses still answer
  // their requests but are not kept.
  void invalidate();
  // Test hook: appends the index of every accepted request, in acceptance order (the sequence a
  // reference cache simulation must see). nullptr switches it off.
  void set_accept_log(std::vector<std::uint32_t>* log) { accept_log_ = log; }
  // Every lookup and fill reports to `o` (null: none, the default). Timing does not change.
  void set_observer(CacheObserver* o) { observer_ = o; }

  int evaluate() override;
  std::string dump_state() const override;
  std::uint64_t next_wakeup(std::uint64_t) const override { return hw::kNever; }

  ItemType type() const { return type_; }
  std::uint16_t client() const { return client_; }
  const CacheConfig& config() const { return config_; }
  std::uint64_t requests_count() const { return requests_stat_->value; }
  std::uint64_t hits() const { return hits_->value; }
  std::uint64_t misses() const { return misses_->value; }
  std::uint64_t merges() const { return merges_->value; }
  // The same counts as the registry's counters, for readers that keep them.
  struct Counters {
    const hw::Counter *requests, *hits, *misses, *merges;
  };
  Counters counters() const { return {requests_stat_, hits_, misses_, merges_}; }
  bool idle() const;  // no miss outstanding, all four channels empty

 private:
  // A line: the item it holds, its state and its words, in 32 aligned bytes, so a lookup and the
  // hit's words read one host cache line (the LRU stamps, used only with ways > 1, sit apart).
  static constexpr std::int32_t kValid = -1;  // data present
  static constexpr std::int32_t kEmpty = -2;  // no item (reset, invalidated)
  struct alignas(32) Line {
    std::uint32_t item = kNone;
    std::int32_t state = kEmpty;  // kValid, kEmpty, or the MSHR whose fill is pending (>= 0)
    std::array<std::uint32_t, kMaxRequestWords> words{};
  };
  struct Mshr {
    bool busy = false;
    bool filled = false;
    std::uint32_t item = 0;
    int line = -1;  // the line waiting for this fill; -1 once the line was reallocated
    struct Target {
      Label label;
      int port;
    };
    hw::Ring<Target> targets;  // at most max_targets
    std::array<std::uint32_t, kMaxRequestWords> words{};
  };

  // The cycle, as a script.
  int accept_fill();           // a returning fill is written into its line
  int deliver();               // one waiting request of a filled miss, if any
  int lookup(bool port_free);  // the next request: hit, merge or miss
  // The lookup's steps (each returns 1 when the request was served, 0 when it must wait).
  int next_request_port() const;
  int hit(const CacheRequest& req, int port, std::size_t line, bool port_free);
  int merge(const CacheRequest& req, int port, std::size_t line);
  int miss(const CacheRequest& req, int port, std::size_t first);
  std::size_t allocate(std::size_t first, std::uint32_t item, int mshr);

  // What every evaluation reads first, together.
  hw::Channel<CacheRequest>* request0_;  // port 0's request channel
  bool one_port_;
  int ways_;
  int sets_;
  std::uint32_t set_mask_ = 0;  // sets - 1 when sets is a power of two (else 0 and a modulo)
  int words_;
  hw::Ring<int> filled_;  // MSHRs with data, in fill order
  hw::Channel<MemResponse> fills_;
  std::vector<Line> lines_;
  std::vector<std::uint64_t> lru_;  // per line, last use (kept only with ways > 1)
  std::vector<Mshr> mshrs_;
  std::vector<std::uint64_t> free_mshrs_;  // bit i: MSHR i is free
  std::uint64_t use_clock_ = 0;
  int next_port_ = 0;  // round-robin among request ports
  hw::Counter *requests_stat_, *hits_, *misses_, *merges_;
  std::vector<std::uint32_t>* accept_log_ = nullptr;
  CacheObserver* observer_ = nullptr;
  ItemType type_;
  const MemoryImage& image_;
  std::uint16_t client_;
  CacheConfig config_;
  std::vector<std::unique_ptr<hw::Channel<CacheRequest>>> requests_;
  std::vector<std::unique_ptr<hw::Channel<CacheResponse>>> responses_;
  hw::Channel<MemRequest> mem_requests_;
};

}  // namespace saarcor::memif
