// The cycle model's timeline in the Chrome trace-event format (units/perfetto_trace.h,
// docs/traces.md "Perfetto timeline").
#include "units/perfetto_trace.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <stdexcept>

namespace saarcor::units {
namespace {

// Track ids inside a DynRTP's process: the units from 1, the caches' miss slots from 16.
int unit_tid(UnitId u) {
  return unit_index(u) + 1;
}
constexpr int kMissTid = 16;

// The Table 4 column of a unit, or -1 (the RGS and added units).
int table4_column(UnitId u) {
  switch (u) {
    case UnitId::kTraversal:
      return 0;
    case UnitId::kList:
      return 1;
    case UnitId::kTransformation:
      return 2;
    case UnitId::kIntersection:
      return 3;
    default:
      return -1;
  }
}

// The units a DynRTP may have: Figure 2's five and the added ones that are registered.
bool unit_exists(int u) {
  const auto id = static_cast<UnitId>(u);
  return id < UnitId::kNone || (id > UnitId::kNone && std::string(unit_name(id)) != "?");
}

}  // namespace

PerfettoTracer::PerfettoTracer(const RunTraceOptions& options, const ThreadTable& threads,
                               PerfettoChip chip)
    : o_(options), threads_(threads), chip_(std::move(chip)) {
  const auto pipes = static_cast<std::size_t>(chip_.pipelines);
  queues_.assign(pipes, {});
  busy_.assign(pipes, 0);
  busy_thread_.assign(static_cast<std::size_t>(threads.size()), false);
  last_cache_.assign(pipes, {});
  open_miss_.assign(pipes * kCacheUnits * static_cast<std::size_t>(chip_.max_misses), {});
  flows_.assign(static_cast<std::size_t>(threads.size()), {});
  next_sample_ = o_.from;
}

std::string PerfettoTracer::ts(std::uint64_t cycle) const {
  // Tenths of a nanosecond: a cycle at any clock up to 10 GHz stays apart from the next.
  const auto t = static_cast<unsigned long long>(
      std::llround(static_cast<double>(cycle) * 10000.0 / chip_.clock_mhz));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%llu.%04llu", t / 10000, t % 10000);
  return buf;
}

std::string PerfettoTracer::dur(std::uint64_t from, std::uint64_t to) const {
  const auto t = [&](std::uint64_t c) {
    return std::llround(static_cast<double>(c) * 10000.0 / chip_.clock_mhz);
  };
  const auto d = static_cast<unsigned long long>(t(to) - t(from));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%llu.%04llu", d / 10000, d % 10000);
  return buf;
}

std::string PerfettoTracer::head(const char* ph, const std::string& name, int pid, int tid,
                                 std::uint64_t cycle) const {
  return std::string("{\"ph\":\"") + ph + "\",\"name\":\"" + name +
         "\",\"pid\":" + std::to_string(pid) + ",\"tid\":" + std::to_string(tid) +
         ",\"ts\":" + ts(cycle);
}

void PerfettoTracer::queued(std::uint64_t, UnitId to, ThreadToken t) {
  // No sample here: a thread leaving a unit is left() then queued() in one step, and a sample
  // between the two would miss it among the busy threads.
  const int p = pipeline_of(t);
  ++queues_[static_cast<std::size_t>(p)][static_cast<std::size_t>(unit_index(to))];
  if (!busy_thread_[t]) {
    busy_thread_[t] = true;
    ++busy_[static_cast<std::size_t>(p)];
  }
}

void PerfettoTracer::accepted(std::uint64_t cycle, UnitId unit, ThreadToken t, int) {
  sample(cycle);
  --queues_[static_cast<std::size_t>(pipeline_of(t))][static_cast<std::size_t>(unit_index(unit))];
}

void PerfettoTracer::left(std::uint64_t cycle, ThreadToken t) {
  sample(cycle);
  if (!busy_thread_[t]) return;
  busy_thread_[t] = false;
  --busy_[static_cast<std::size_t>(pipeline_of(t))];
}

// The request's slice on its unit's track covers the cycles it holds the issue slot.
void PerfettoTracer::issued(std::uint64_t cycle, UnitId unit, ThreadToken t, const Request& r,
                            int steps, std::uint64_t) {
  sample(cycle);
  if (!in_window(cycle)) {
    flows_[t].clear();
    return;
  }
  const TracedStep& s = threads_.traced(t);
  const std::uint64_t end = cycle + static_cast<std::uint64_t>(std::max(steps, 1));
  std::string e = head("X", std::string(phase_name(r.phase)) + " t" + std::to_string(t),
                       pipeline_of(t) + 1, unit_tid(unit), cycle);
  e += ",\"dur\":" + dur(cycle, end) + ",\"cat\":\"" + unit_name(unit) +
       "\",\"args\":{\"cycle\":" + std::to_string(cycle) + ",\"thread\":" + std::to_string(t) +
       ",\"packet\":" + std::to_string(s.packet) + ",\"request\":" + std::to_string(s.seq) +
       ",\"steps\":" + std::to_string(steps) +
       ",\"item\":" + (r.item == memif::kNone ? std::string("-1") : std::to_string(r.item)) +
       ",\"kind\":\"" + ray_kind_name(s.kind) + "\"}}";
  events_.push_back({cycle, std::move(e)});
  ++counts_.slices;
  if (const int col = table4_column(unit); col >= 0)
    ++counts_.unit_slices[static_cast<std::size_t>(col)];
  add_flows(cycle, unit, t);
}

// A flow from each miss the thread's request waited for to the request's issue.
void PerfettoTracer::add_flows(std::uint64_t cycle, UnitId unit, ThreadToken t) {
  const int pid = pipeline_of(t) + 1;
  for (const PendingFlow& f : flows_[t]) {
    const std::string id = ",\"id\":" + std::to_string(next_flow_++) + ",\"cat\":\"miss\"}";
    events_.push_back({f.cycle, head("s", "miss", pid, f.tid, f.cycle) + id});
    events_.push_back(
        {cycle, head("f", "miss", pid, unit_tid(unit), cycle) + ",\"bp\":\"e\"" + id});
    ++counts_.flows;
  }
  flows_[t].clear();
}

int PerfettoTracer::cache_slot(const memif::Cache& cache, int& pipeline) const {
  for (int p = 0; p < chip_.pipelines; ++p)
    for (int c = 0; c < kCacheUnits; ++c)
      if (chip_.caches[static_cast<std::size_t>(p)][static_cast<std::size_t>(c)] == &cache) {
        pipeline = p;
        return c;
      }
  throw std::logic_error("perfetto trace: a miss in a cache the chip did not name");
}

void PerfettoTracer::miss(std::uint64_t cycle, const memif::Cache& cache, std::uint32_t item,
                          int mshr, const memif::Label& label) {
  sample(cycle);
  int p = 0;
  const int c = cache_slot(cache, p);
  const int slot = c * chip_.max_misses + mshr;
  OpenMiss& m = open_miss_[static_cast<std::size_t>(p * kCacheUnits * chip_.max_misses + slot)];
  m = {cycle, item, label.tag, true};
  if (in_window(cycle) && label.tag < flows_.size())
    flows_[label.tag].push_back({cycle, kMissTid + slot});
}

void PerfettoTracer::filled(std::uint64_t cycle, const memif::Cache& cache, int mshr) {
  sample(cycle);
  int p = 0;
  const int c = cache_slot(cache, p);
  const int slot = c * chip_.max_misses + mshr;
  OpenMiss& m = open_miss_[static_cast<std::size_t>(p * kCacheUnits * chip_.max_misses + slot)];
  if (!m.open) return;
  m.open = false;
  if (!in_window(m.cycle)) return;
  std::string e = head("X", "miss " + std::to_string(m.item), p + 1, kMissTid + slot, m.cycle);
  e += ",\"dur\":" + dur(m.cycle, cycle) +
       ",\"cat\":\"miss\",\"args\":{\"item\":" + std::to_string(m.item) +
       ",\"thread\":" + std::to_string(m.thread) +
       ",\"cycles\":" + std::to_string(cycle - m.cycle) + "}}";
  events_.push_back({m.cycle, std::move(e)});
  ++counts_.misses;
}

void PerfettoTracer::sample(std::uint64_t cycle) {
  if (cycle < next_sample_ || !in_window(cycle)) return;
  next_sample_ = (cycle / kPerfettoCounterPeriod + 1) * kPerfettoCounterPeriod;
  for (int p = 0; p < chip_.pipelines; ++p)
    sample_pipeline(cycle, p);
}

// The DynRTP's counters: threads waiting on each unit's input paths, threads holding a packet,
// and each cache's hit rate (merges counted as hits, as the report does) since its last sample.
void PerfettoTracer::sample_pipeline(std::uint64_t cycle, int p) {
  const auto pi = static_cast<std::size_t>(p);
  std::string q = head("C", "queued threads", p + 1, 0, cycle) + ",\"args\":{";
  bool first = true;
  for (int u = 0; u < kMaxUnits; ++u) {
    if (!unit_exists(u)) continue;
    q += std::string(first ? "" : ",") + "\"" + unit_name(static_cast<UnitId>(u)) +
         "\":" + std::to_string(queues_[pi][static_cast<std::size_t>(u)]);
    first = false;
  }
  events_.push_back({cycle, q + "}}"});
  events_.push_back({cycle, head("C", "busy threads", p + 1, 0, cycle) +
                                ",\"args\":{\"threads\":" + std::to_string(busy_[pi]) + "}}"});
  counts_.counters += 2;
  for (std::size_t c = 0; c < kCacheUnits; ++c) {
    const memif::Cache::Counters k = chip_.caches[pi][c]->counters();
    const std::uint64_t req = k.requests->value, hits = k.hits->value + k.merges->value;
    const std::uint64_t dreq = req - last_cache_[pi][c][0], dhit = hits - last_cache_[pi][c][1];
    last_cache_[pi][c] = {req, hits};
    if (dreq == 0) continue;
    char pct[32];
    std::snprintf(pct, sizeof pct, "%.3f", 100.0 * static_cast<double>(dhit) / dreq);
    events_.push_back(
        {cycle, head("C", std::string(kTable4UnitNames[c]) + " cache hit %", p + 1, 0, cycle) +
                    ",\"args\":{\"hit_pct\":" + pct + "}}"});
    ++counts_.counters;
  }
}

void PerfettoTracer::write_names(std::ostream& out) const {
  const auto meta = [&](const char* what, int pid, int tid, const std::string& arg) {
    out << "{\"ph\":\"M\",\"name\":\"" << what << "\",\"pid\":" << pid << ",\"tid\":" << tid
        << ",\"args\":{" << arg << "}},\n";
  };
  for (int p = 0; p < chip_.pipelines; ++p) {
    meta("process_name", p + 1, 0, "\"name\":\"DynRTP " + std::to_string(p) + "\"");
    meta("process_sort_index", p + 1, 0, "\"sort_index\":" + std::to_string(p));
    for (int u = 0; u < kMaxUnits; ++u) {
      if (!unit_exists(u)) continue;
      const int tid = unit_tid(static_cast<UnitId>(u));
      meta("thread_name", p + 1, tid,
           std::string("\"name\":\"") + unit_name(static_cast<UnitId>(u)) + "\"");
      meta("thread_sort_index", p + 1, tid, "\"sort_index\":" + std::to_string(tid));
    }
    for (int c = 0; c < kCacheUnits; ++c)
      for (int m = 0; m < chip_.max_misses; ++m) {
        const int tid = kMissTid + c * chip_.max_misses + m;
        meta("thread_name", p + 1, tid,
             std::string("\"name\":\"") + kTable4UnitNames[c] + " cache miss " + std::to_string(m) +
                 "\"");
        meta("thread_sort_index", p + 1, tid, "\"sort_index\":" + std::to_string(tid));
      }
  }
}

void PerfettoTracer::finish(std::uint64_t cycles) {
  if (o_.from > cycles)
    throw std::runtime_error("--trace-from " + std::to_string(o_.from) +
                             " is after the frame's last cycle " + std::to_string(cycles));
  std::stable_sort(events_.begin(), events_.end(),
                   [](const Event& a, const Event& b) { return a.cycle < b.cycle; });
  std::ostream& out = *o_.perfetto;
  out << "{\"displayTimeUnit\":\"ns\",\"otherData\":{\"clock_mhz\":" << chip_.clock_mhz
      << ",\"from_cycle\":" << o_.from << ",\"to_cycle\":" << std::min(o_.to, cycles)
      << ",\"frame_cycles\":" << cycles << "},\n\"traceEvents\":[\n";
  write_names(out);
  for (const Event& e : events_)
    out << e.json << ",\n";
  // The last entry: the window's end, so a viewer's time axis spans the whole window.
  out << head("i", "window end", 1, 0, std::min(o_.to, cycles)) << ",\"s\":\"g\"}\n]}\n";
  events_.clear();
}

}  // namespace saarcor::units
