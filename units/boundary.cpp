// The model's side of the boundary record (units/boundary.h).
#include "units/boundary.h"

#include <cstdio>
#include <iterator>
#include <sstream>

namespace saarcor::units {
namespace {

constexpr const char* kRequestFields[] = {"phase", "item", "mask"};

}  // namespace

const char* boundary_port_name(BoundaryPort p) {
  constexpr const char* kNames[] = {"input",         "side_band", "cache_request", "cache_response",
                                    "cache_blocked", "output",    "cache_accept",  "cache_reply",
                                    "mem_request",   "mem_taken", "mem_fill"};
  return kNames[static_cast<int>(p)];
}

std::string format_boundary(const BoundaryEvent& e) {
  std::ostringstream s;
  s << "cycle " << e.cycle << " dynrtp" << e.dynrtp << " " << unit_name(e.unit)
    << (e.cache ? " cache " : " ") << boundary_port_name(e.port) << " thread " << e.thread;
  if (e.port == BoundaryPort::kInput) s << " from " << unit_name(e.path);
  if (e.port == BoundaryPort::kOutput) s << " to " << unit_name(e.path);
  for (int k = 0; k < e.fields; ++k) {
    char v[32];
    std::snprintf(v, sizeof v, "%llx", static_cast<unsigned long long>(e.field[k]));
    s << " " << (e.names != nullptr ? e.names[k] : "?") << "=" << v;
  }
  if (!e.wide.empty()) {
    // FNV-1a over the words: two records with the same checksum carry the same words (as far as
    // one line can tell).
    std::uint32_t sum = 2166136261u;
    s << " wide[" << e.wide.size() << "]=";
    for (std::size_t k = 0; k < e.wide.size(); ++k) {
      sum = (sum ^ e.wide[k]) * 16777619u;
      char v[16];
      std::snprintf(v, sizeof v, "%x", static_cast<unsigned>(e.wide[k]));
      if (k < 8) s << (k != 0 ? "," : "") << v;
    }
    char v[16];
    std::snprintf(v, sizeof v, "%08x", static_cast<unsigned>(sum));
    s << (e.wide.size() > 8 ? ",..." : "") << " sum=" << v;
  }
  return s.str();
}

namespace {
void request_fields(const Request& r, BoundaryEvent& e) {
  e.fields = 3;
  e.names = kRequestFields;
  e.field[0] = static_cast<std::uint64_t>(r.phase);
  e.field[1] = r.item;
  e.field[2] = r.mask;
}
}  // namespace

void RequestPayload::input(UnitId, UnitId, ThreadToken t, BoundaryEvent& e) {
  request_fields(threads_.request(t), e);
}
void RequestPayload::output(UnitId, ThreadToken t, BoundaryEvent& e) {
  request_fields(threads_.request(t), e);
}

bool UnitPayloads::side_band(UnitId to, UnitId from, ThreadToken t, BoundaryEvent& side) {
  for (BoundaryPayload* p : of_)
    if (p != nullptr && p->side_band(to, from, t, side)) return true;
  return false;
}

void UnitPayloads::side_bands(UnitId to, UnitId from, ThreadToken t,
                              std::vector<BoundaryEvent>& sides) {
  for (BoundaryPayload* p : of_)
    if (p != nullptr) p->side_bands(to, from, t, sides);
}

void UnitPayloads::issued(UnitId unit, ThreadToken t, const Request& r) {
  for (BoundaryPayload* p : of_)
    if (p != nullptr) p->issued(unit, t, r);
}

BoundaryRecorder::BoundaryRecorder(const ThreadTable& threads, int threads_per_pipeline,
                                   std::vector<UnitId> units, BoundaryPayload& payload, Sink sink)
    : threads_(threads),
      per_pipeline_(threads_per_pipeline < 1 ? 1 : threads_per_pipeline),
      payload_(payload),
      sink_(std::move(sink)),
      at_(static_cast<std::size_t>(threads.size()), UnitId::kRgs),
      leaving_(static_cast<std::size_t>(threads.size())) {
  for (UnitId u : units)
    record_[static_cast<std::size_t>(unit_index(u))] = true;
}

BoundaryEvent BoundaryRecorder::event(std::uint64_t cycle, UnitId unit, BoundaryPort port,
                                      ThreadToken t) const {
  BoundaryEvent e;
  e.cycle = cycle;
  e.dynrtp = static_cast<int>(t) / per_pipeline_;
  e.unit = unit;
  e.port = port;
  e.thread = t;
  return e;
}

void BoundaryRecorder::queued(std::uint64_t cycle, UnitId to, ThreadToken t) {
  sides_.clear();
  payload_.side_bands(to, at_[t], t, sides_);
  for (BoundaryEvent& side : sides_) {
    if (!recorded(side.unit)) continue;
    BoundaryEvent e = event(cycle, side.unit, BoundaryPort::kSideBand, t);
    e.path = at_[t];
    e.fields = side.fields;
    e.field = side.field;
    e.names = side.names;
    e.wide = std::move(side.wide);
    sink_(e);
  }
  if (!recorded(to)) return;
  BoundaryEvent e = event(cycle, to, BoundaryPort::kInput, t);
  e.path = at_[t];
  payload_.input(to, at_[t], t, e);
  sink_(e);
}

void BoundaryRecorder::accepted(std::uint64_t, UnitId unit, ThreadToken t, int) {
  at_[t] = unit;
}

void BoundaryRecorder::issued(std::uint64_t cycle, UnitId unit, ThreadToken t, const Request& r,
                              int, std::uint64_t) {
  at_[t] = unit;
  payload_.issued(unit, t, r);
  if (!recorded(unit)) return;
  BoundaryEvent& out = leaving_[t];
  out = event(cycle, unit, BoundaryPort::kOutput, t);
  payload_.output(unit, t, out);
}

void BoundaryRecorder::left(std::uint64_t cycle, ThreadToken t) {
  if (!recorded(at_[t])) return;
  BoundaryEvent e = leaving_[t];
  e.cycle = cycle;
  e.path = threads_.request(t).unit;
  sink_(e);
}

void BoundaryRecorder::cache_request(std::uint64_t cycle, UnitId unit,
                                     const memif::CacheRequest& r) {
  if (!recorded(unit)) return;
  BoundaryEvent e = event(cycle, unit, BoundaryPort::kCacheRequest, r.label.tag);
  e.fields = 3;
  e.names = kCacheRequestFields;
  e.field[0] = r.index;
  e.field[1] = r.label.requester;
  e.field[2] = r.label.tag;
  sink_(e);
}

void BoundaryRecorder::cache_response(std::uint64_t cycle, UnitId unit,
                                      const memif::CacheResponse& r) {
  if (!recorded(unit)) return;
  BoundaryEvent e = event(cycle, unit, BoundaryPort::kCacheResponse, r.label.tag);
  // The address, then at most as many words as the response's field names have.
  constexpr int kMaxWords = static_cast<int>(std::size(kCacheResponseFields)) - 1;
  const int words = r.count < kMaxWords ? r.count : kMaxWords;
  e.fields = 1 + words;
  e.names = kCacheResponseFields;
  e.field[0] = r.index;
  for (int k = 0; k < words; ++k)
    e.field[static_cast<std::size_t>(k) + 1] = r.words[static_cast<std::size_t>(k)];
  sink_(e);
}

void BoundaryRecorder::cache_blocked(std::uint64_t cycle, UnitId unit) {
  if (!recorded(unit)) return;
  sink_(event(cycle, unit, BoundaryPort::kCacheBlocked, 0));
}

}  // namespace saarcor::units
