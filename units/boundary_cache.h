// The per-type caches' ports as hardware carries them (the boundary record, units/boundary.h;
// paper section 3: "individual caches for each type of data"; memif/cache.h, D20): the record of
// one DynRTP's node, list and row caches, each event marked BoundaryEvent::cache and named by the
// unit the cache serves (node: traversal, list: list, row: transformation).
//   request side   input  cache_request: address (the item index), requester, tag (the label:
//                         unit and thread), in the cycle the unit pushes it;
//                  output cache_accept: address, requester, tag, kind (0 hit, 1 merge, 2 miss),
//                         mshr (merge: the outstanding miss it joins; miss: the one it takes;
//                         hit: 0), in the cycle the lookup takes it from the request queue;
//   response side  output cache_reply: address, requester, tag, the item's words, in the cycle
//                         the unit takes the response (push + hit_latency - 1: the unit takes one
//                         every cycle);
//   memory side    output mem_request: tag (the MSHR), bank, offset, words: the line request the
//                         miss pushes towards the routing;
//                  input  mem_taken: the routing took the cache's oldest line request;
//                  input  mem_fill: tag (the MSHR), the words: the routing pushed a fill.
// With record_port, also the memory controller's cache port, where a whole DynRTC in RTL meets the
// model (named by the unit whose cache the response's client is; kNone for the back-pressure):
//   port_response: client, tag, the words: the controller pushed a response towards the routing;
//   port_blocked:  a client had a line request and the port's request channel was full.
// The model emits them through the cache's, the routing's and the port's observers and the units'
// cache hooks (UnitObserver::cache_request, cache_response); the RTL (rtl/cache.sv,
// rtl/dynrtc.sv) through its ports. Several DynRTPs' caches are told apart by `dynrtp`.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "memif/cache.h"
#include "memif/image_format.h"
#include "memif/memory_system.h"
#include "memif/routing.h"
#include "units/boundary.h"

namespace saarcor::units {

inline constexpr const char* kCacheAcceptFields[] = {"address", "requester", "tag", "kind", "mshr"};
inline constexpr const char* kCacheReplyFields[] = {"address", "requester", "tag",  "word0",
                                                    "word1",   "word2",     "word3"};
inline constexpr const char* kMemRequestFields[] = {"tag", "bank", "offset", "words"};
inline constexpr const char* kMemFillFields[] = {"tag", "word0", "word1", "word2", "word3"};
inline constexpr const char* kPortFields[] = {"client", "tag", "word0", "word1", "word2", "word3"};

enum class CacheKind : std::uint8_t { kHit = 0, kMerge = 1, kMiss = 2 };

// The unit a cache of `type` serves (DynRtp: the traversal unit reads kd-nodes, the list unit
// list entries, the transformation unit matrix rows).
inline UnitId cache_unit(memif::ItemType type) {
  constexpr UnitId kOf[] = {UnitId::kTraversal, UnitId::kList, UnitId::kTransformation};
  return kOf[static_cast<int>(type)];
}
// The lockstep's name of the cache serving `unit`: node-cache, list-cache, row-cache.
inline const char* cache_name(UnitId unit) {
  return unit == UnitId::kTraversal ? "node-cache"
         : unit == UnitId::kList    ? "list-cache"
                                    : "row-cache";
}

// The model's side of the caches' record: the observer of DynRTP 0's caches and of the routing,
// and a UnitObserver that takes the units' cache hooks (and hands every hook on to `next`, the
// units' own recorder, if any). Emits the events of the caches in `types` to `sink`.
class CacheRecorder final : public UnitObserver,
                            public memif::CacheObserver,
                            public memif::RoutingObserver,
                            public memif::PortObserver {
 public:
  using Sink = std::function<void(const BoundaryEvent&)>;
  // The caches of the first `pipelines` DynRTPs, whose threads are ids [p x
  // threads_per_pipeline, (p + 1) x threads_per_pipeline) (BoundaryEvent::dynrtp is p).
  CacheRecorder(memif::MemorySystem& mi, const memif::MemoryImage& image,
                const std::vector<memif::ItemType>& types, UnitObserver* next, Sink sink,
                int pipelines = 1, int threads_per_pipeline = 0)
      : image_(image), next_(next), sink_(std::move(sink)), per_pipeline_(threads_per_pipeline) {
    for (int p = 0; p < pipelines; ++p)
      for (memif::ItemType t : types) {
        memif::Cache& c = mi.cache(p, t);
        c.set_observer(this);
        recorded_[static_cast<std::size_t>(unit_index(cache_unit(t)))] = true;
        if (client_.size() <= c.client()) client_.resize(c.client() + 1u, {UnitId::kNone, 0});
        client_[c.client()] = {cache_unit(t), p};
      }
    mi.routing().set_observer(this);
  }

  // Also the memory controller's cache port: the responses it pushes towards the routing and
  // the routing's waits on its request channel (where a whole DynRTC in RTL meets the model).
  void record_port(memif::MemorySystem& mi) {
    mi.routing().port().observer = this;
    port_ = true;
  }

  // UnitObserver: the units' hooks on to `next`; their cache port's push and take recorded.
  void queued(std::uint64_t c, UnitId to, ThreadToken t) override {
    if (next_ != nullptr) next_->queued(c, to, t);
  }
  void accepted(std::uint64_t c, UnitId u, ThreadToken t, int items) override {
    if (next_ != nullptr) next_->accepted(c, u, t, items);
  }
  void fetched(std::uint64_t c, ThreadToken t) override {
    if (next_ != nullptr) next_->fetched(c, t);
  }
  void ready(std::uint64_t c, ThreadToken t) override {
    if (next_ != nullptr) next_->ready(c, t);
  }
  void issued(std::uint64_t c, UnitId u, ThreadToken t, const Request& r, int steps,
              std::uint64_t done_at) override {
    if (next_ != nullptr) next_->issued(c, u, t, r, steps, done_at);
  }
  void left(std::uint64_t c, ThreadToken t) override {
    if (next_ != nullptr) next_->left(c, t);
  }
  void cache_blocked(std::uint64_t c, UnitId u) override {
    if (next_ != nullptr) next_->cache_blocked(c, u);
  }
  void cache_request(std::uint64_t c, UnitId u, const memif::CacheRequest& r) override {
    if (next_ != nullptr) next_->cache_request(c, u, r);
    if (!recorded(u)) return;
    BoundaryEvent& e =
        event(c, u, BoundaryPort::kCacheRequest, r.label.tag, 3, kCacheRequestFields);
    e.dynrtp = thread_pipe(r.label.tag);
    e.field = {r.index, r.label.requester, r.label.tag};
    sink_(e);
  }
  void cache_response(std::uint64_t c, UnitId u, const memif::CacheResponse& r) override {
    if (next_ != nullptr) next_->cache_response(c, u, r);
    if (!recorded(u)) return;
    BoundaryEvent& e =
        event(c, u, BoundaryPort::kCacheReply, r.label.tag, 3 + r.count, kCacheReplyFields);
    e.dynrtp = thread_pipe(r.label.tag);
    e.field = {r.index, r.label.requester, r.label.tag};
    for (int k = 0; k < r.count; ++k)
      e.field[3 + static_cast<std::size_t>(k)] = r.words[static_cast<std::size_t>(k)];
    sink_(e);
  }

  // memif::CacheObserver: the lookups and the line requests.
  void hit(std::uint64_t c, const memif::Cache& cache, const memif::CacheRequest& r) override {
    accept(c, cache, r.index, r.label, CacheKind::kHit, 0);
  }
  void merged(std::uint64_t c, const memif::Cache& cache, const memif::CacheRequest& r,
              int mshr) override {
    accept(c, cache, r.index, r.label, CacheKind::kMerge, mshr);
  }
  void miss(std::uint64_t c, const memif::Cache& cache, std::uint32_t item, int mshr,
            const memif::Label& label) override {
    accept(c, cache, item, label, CacheKind::kMiss, mshr);
    const memif::WordLocation loc = image_.locate(cache.type(), item, 0);
    BoundaryEvent& e =
        event(c, cache_unit(cache.type()), BoundaryPort::kMemRequest, 0, 4, kMemRequestFields);
    e.dynrtp = client_pipe(cache.client());
    e.field = {static_cast<std::uint64_t>(mshr), static_cast<std::uint64_t>(loc.bank), loc.offset,
               static_cast<std::uint64_t>(image_.item_words(cache.type()))};
    sink_(e);
  }
  void filled(std::uint64_t, const memif::Cache&, int) override {}

  // memif::RoutingObserver: the memory side's inputs.
  void forwarded(std::uint64_t c, const memif::MemRequest& r) override {
    const UnitId u = of_client(r.client);
    if (u == UnitId::kNone) return;
    event(c, u, BoundaryPort::kMemTaken, 0, 0, nullptr).dynrtp = client_pipe(r.client);
    sink_(e_);
  }
  void delivered(std::uint64_t c, const memif::MemResponse& r) override {
    const UnitId u = of_client(r.client);
    if (u == UnitId::kNone) return;
    BoundaryEvent& e = event(c, u, BoundaryPort::kMemFill, 0, 1 + r.count, kMemFillFields);
    e.dynrtp = client_pipe(r.client);
    e.field = {r.tag};
    for (int k = 0; k < r.count; ++k)
      e.field[1 + static_cast<std::size_t>(k)] = r.words[static_cast<std::size_t>(k)];
    sink_(e);
  }
  void blocked(std::uint64_t c) override {
    if (port_) sink_(event(c, UnitId::kNone, BoundaryPort::kPortBlocked, 0, 0, nullptr));
  }

  // memif::PortObserver: a response towards the routing, labelled with its client.
  void responded(std::uint64_t c, const memif::MemResponse& r) override {
    BoundaryEvent& e =
        event(c, of_client(r.client), BoundaryPort::kPortResponse, 0, 2 + r.count, kPortFields);
    e.dynrtp = client_pipe(r.client);
    e.field = {r.client, r.tag};
    for (int k = 0; k < r.count; ++k)
      e.field[2 + static_cast<std::size_t>(k)] = r.words[static_cast<std::size_t>(k)];
    sink_(e);
  }

 private:
  bool recorded(UnitId u) const { return recorded_[static_cast<std::size_t>(unit_index(u))]; }
  UnitId of_client(std::uint16_t client) const {
    return client < client_.size() ? client_[client].unit : UnitId::kNone;
  }
  int client_pipe(std::uint16_t client) const {
    return client < client_.size() ? client_[client].pipe : 0;
  }
  int thread_pipe(std::uint32_t thread) const {
    return per_pipeline_ > 0 ? static_cast<int>(thread) / per_pipeline_ : 0;
  }
  BoundaryEvent& event(std::uint64_t cycle, UnitId u, BoundaryPort port, std::uint32_t thread,
                       int fields, const char* const* names) {
    e_ = BoundaryEvent{};
    e_.cycle = cycle;
    e_.unit = u;
    e_.cache = true;
    e_.port = port;
    e_.thread = thread;
    e_.fields = fields;
    e_.names = names;
    return e_;
  }
  void accept(std::uint64_t c, const memif::Cache& cache, std::uint32_t item,
              const memif::Label& label, CacheKind kind, int mshr) {
    BoundaryEvent& e = event(c, cache_unit(cache.type()), BoundaryPort::kCacheAccept, label.tag, 5,
                             kCacheAcceptFields);
    e.field = {item, label.requester, label.tag, static_cast<std::uint64_t>(kind),
               static_cast<std::uint64_t>(mshr)};
    e.dynrtp = client_pipe(cache.client());
    sink_(e);
  }

  const memif::MemoryImage& image_;
  UnitObserver* next_;
  Sink sink_;
  std::array<bool, kMaxUnits> recorded_{};
  struct Client {
    UnitId unit;
    int pipe;
  };
  std::vector<Client> client_;  // controller client id -> the unit its cache serves, its DynRTP
  int per_pipeline_;
  bool port_ = false;  // record_port: the port's events too
  BoundaryEvent e_;
};

}  // namespace saarcor::units
