// The boundary record (docs/hw-interface.md): one record per event on a port of a DynRTP unit,
// emitted identically by the cycle model (through a UnitObserver, below) and by the RTL's port
// monitors (rtl/lockstep.cpp), so the two can be compared cycle by cycle. A unit's ports (paper
// section 3.1, Figure 2): its input paths (a thread arriving with the payload its sender hands
// over), its cache port (a request with its item address and label; a response with the SRAM
// words), the side-band inputs a unit needs from its neighbours (the list unit's packet start,
// D28), and its output paths (a thread leaving with its payload).
//
// What the payload of a port is for each unit is a BoundaryPayload's business: the default one
// carries the thread program's request (phase, item, mask); units/boundary_list.h gives the
// mailboxed list unit's hardware fields (level, list cursor, ray mask, entry).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "units/cycle_unit.h"

namespace saarcor::units {

enum class BoundaryPort : std::uint8_t {
  kInput,          // a thread pushed on a path towards the unit (the cycle of the push)
  kSideBand,       // a neighbour's signal about a thread (the list unit: packet start)
  kCacheRequest,   // the unit's cache request left (item address, requester, tag)
  kCacheResponse,  // the unit took a cache response (item address, the words)
  kCacheBlocked,   // the unit had a request to send and the cache's request queue was full
  kOutput,         // a thread left the unit on a path (or retired)
  // The ports of a unit's cache (its own record, BoundaryEvent::cache; units/boundary_cache.h).
  // The cache's inputs are kCacheRequest (the unit's push), kMemTaken and kMemFill; its outputs
  // kCacheAccept, kCacheReply and kMemRequest.
  kCacheAccept,  // the lookup took a request from the queue: hit, merge or miss, and the MSHR
  kCacheReply,   // a response reached the unit (the cycle the unit takes it)
  kMemRequest,   // a line request pushed towards the routing (a miss)
  kMemTaken,     // the routing took the cache's oldest line request
  kMemFill,      // the routing pushed a fill, labelled with its MSHR
};
inline constexpr int kBoundaryPorts = 11;
const char* boundary_port_name(BoundaryPort p);

// The widest payload: the transformation unit's output (units/boundary_transformation.h).
inline constexpr int kBoundaryFields = 10;
// The cache port's payloads (the same for every unit): a request's item address and label, a
// response's item address and words.
inline constexpr const char* kCacheRequestFields[] = {"address", "requester", "tag"};
inline constexpr const char* kCacheResponseFields[] = {"address", "word0", "word1", "word2",
                                                       "word3",   "word4", "word5", "word6"};

struct BoundaryEvent {
  std::uint64_t cycle = 0;
  int dynrtp = 0;
  UnitId unit = UnitId::kNone;  // (a cache's event: the unit the cache serves)
  bool cache = false;           // an event of the unit's cache, not of the unit
  BoundaryPort port = BoundaryPort::kInput;
  std::uint32_t thread = 0;
  // Input: the sending unit; output: the unit the thread's next request names (kNone: retired).
  UnitId path = UnitId::kNone;
  int fields = 0;  // field[0, fields) hold the payload
  std::array<std::uint64_t, kBoundaryFields> field{};
  // The fields' names (static storage, `fields` of them): payload-specific.
  const char* const* names = nullptr;
  // The words of a wide payload (a path that carries rays: the traversal unit's level start and
  // hit update, units/boundary_traversal.h); empty for the others.
  std::vector<std::uint32_t> wide;
};

// One line: cycle, dynrtp, unit, port, thread, path, name=value (hex) for each field, then the
// wide words (their count, the first eight in hex and a checksum of all).
std::string format_boundary(const BoundaryEvent& e);

// What a unit carries on its ports. Called from the recorder's hooks, in cycle order.
class BoundaryPayload {
 public:
  virtual ~BoundaryPayload() = default;
  // Thread t was pushed towards `unit` by `from`: its payload on the path (e.port kInput).
  virtual void input(UnitId unit, UnitId from, ThreadToken t, BoundaryEvent& e) = 0;
  // Thread t was pushed towards `to` by `from` (any path of the DynRTP). Fills `side` and returns
  // true when that is a side-band event of another unit (side.unit names it).
  virtual bool side_band(UnitId to, UnitId from, ThreadToken t, BoundaryEvent& side) = 0;
  // Every side-band event of the hand-over (several units may see one: the packet start goes to
  // the list and the intersection units), appended to `sides`.
  virtual void side_bands(UnitId to, UnitId from, ThreadToken t,
                          std::vector<BoundaryEvent>& sides) {
    BoundaryEvent side;
    if (side_band(to, from, t, side)) sides.push_back(std::move(side));
  }
  // Thread t's request `r` was executed on `unit` (any unit of the DynRTP).
  virtual void issued(UnitId unit, ThreadToken t, const Request& r) = 0;
  // Thread t, issued on `unit` just now, will leave with this payload (e.port kOutput).
  virtual void output(UnitId unit, ThreadToken t, BoundaryEvent& e) = 0;
};

// The default payload: the thread program's request, as the thread table holds it (phase, item,
// mask); no side band.
class RequestPayload final : public BoundaryPayload {
 public:
  explicit RequestPayload(const ThreadTable& threads) : threads_(threads) {}
  void input(UnitId unit, UnitId from, ThreadToken t, BoundaryEvent& e) override;
  bool side_band(UnitId, UnitId, ThreadToken, BoundaryEvent&) override { return false; }
  void issued(UnitId, ThreadToken, const Request&) override {}
  void output(UnitId unit, ThreadToken t, BoundaryEvent& e) override;

 private:
  const ThreadTable& threads_;
};

// Each unit's payload from its own BoundaryPayload (the others: RequestPayload), so several units
// are recorded at once. A hand-over is a side-band event of each unit whose payload claims it (the
// packet start on path a: the list and the intersection units; the hit update from the
// intersection unit: the traversal unit); side_band() alone gives the first claim.
class UnitPayloads final : public BoundaryPayload {
 public:
  explicit UnitPayloads(const ThreadTable& threads) : fallback_(threads) {}
  void set(UnitId unit, BoundaryPayload& p) {
    of_[static_cast<std::size_t>(unit_index(unit))] = &p;
  }
  void input(UnitId unit, UnitId from, ThreadToken t, BoundaryEvent& e) override {
    payload(unit).input(unit, from, t, e);
  }
  bool side_band(UnitId to, UnitId from, ThreadToken t, BoundaryEvent& side) override;
  void side_bands(UnitId to, UnitId from, ThreadToken t,
                  std::vector<BoundaryEvent>& sides) override;
  void issued(UnitId unit, ThreadToken t, const Request& r) override;
  void output(UnitId unit, ThreadToken t, BoundaryEvent& e) override {
    payload(unit).output(unit, t, e);
  }

 private:
  BoundaryPayload& payload(UnitId u) {
    BoundaryPayload* p = of_[static_cast<std::size_t>(unit_index(u))];
    return p != nullptr ? *p : fallback_;
  }
  RequestPayload fallback_;
  std::array<BoundaryPayload*, kMaxUnits> of_{};
};

// The model's side of the record: a UnitObserver on every unit of a DynRTP (DynRtp::observe)
// that emits the events of the units in `units` to `sink`, in cycle order.
class BoundaryRecorder final : public UnitObserver {
 public:
  using Sink = std::function<void(const BoundaryEvent&)>;
  BoundaryRecorder(const ThreadTable& threads, int threads_per_pipeline, std::vector<UnitId> units,
                   BoundaryPayload& payload, Sink sink);

  void queued(std::uint64_t cycle, UnitId to, ThreadToken t) override;
  void accepted(std::uint64_t cycle, UnitId unit, ThreadToken t, int items) override;
  void fetched(std::uint64_t, ThreadToken) override {}
  void ready(std::uint64_t, ThreadToken) override {}
  void issued(std::uint64_t cycle, UnitId unit, ThreadToken t, const Request& r, int steps,
              std::uint64_t done_at) override;
  void left(std::uint64_t cycle, ThreadToken t) override;
  void cache_request(std::uint64_t cycle, UnitId unit, const memif::CacheRequest& r) override;
  void cache_response(std::uint64_t cycle, UnitId unit, const memif::CacheResponse& r) override;
  void cache_blocked(std::uint64_t cycle, UnitId unit) override;

 private:
  bool recorded(UnitId u) const { return record_[static_cast<std::size_t>(unit_index(u))]; }
  BoundaryEvent event(std::uint64_t cycle, UnitId unit, BoundaryPort port, ThreadToken t) const;

  const ThreadTable& threads_;
  int per_pipeline_;
  std::array<bool, kMaxUnits> record_{};
  BoundaryPayload& payload_;
  Sink sink_;
  std::vector<UnitId> at_;              // per thread: the unit it was last taken into
  std::vector<BoundaryEvent> leaving_;  // per thread: the output payload, from its issue
  std::vector<BoundaryEvent> sides_;    // queued(): the hand-over's side-band events
};

}  // namespace saarcor::units
