// The cycle model's request trace and Kanata log (units/run_trace.h, docs/traces.md).
#include "units/run_trace.h"

#include <algorithm>
#include <ostream>
#include <sstream>
#include <stdexcept>

namespace saarcor::units {

RunTracer::RunTracer(const RunTraceOptions& options, const ThreadTable& threads,
                     int threads_per_pipeline)
    : o_(options),
      threads_(threads),
      per_pipeline_(threads_per_pipeline < 1 ? 1 : threads_per_pipeline),
      open_(static_cast<std::size_t>(threads.size())) {
  konata_all_ = o_.konata_threads.empty();
  for (const std::uint32_t t : o_.konata_threads) {
    if (t >= konata_thread_.size()) konata_thread_.resize(t + 1u, false);
    konata_thread_[t] = true;
  }
  if (o_.trace != nullptr) *o_.trace << kTraceHeader << '\n';
}

void RunTracer::queued(std::uint64_t cycle, UnitId to, ThreadToken t) {
  Record& r = open_[t];
  if (r.open) close(r, cycle);
  r = Record{};
  r.open = true;
  r.unit = to;
  r.thread = t;
  r.queued = cycle;
}

void RunTracer::accepted(std::uint64_t cycle, UnitId unit, ThreadToken t, int items) {
  Record& r = open_[t];
  r.unit = unit;
  r.accepted = cycle;
  if (items == 0) r.ready = cycle;
}

void RunTracer::fetched(std::uint64_t cycle, ThreadToken t) {
  open_[t].fetched = cycle;
}

void RunTracer::ready(std::uint64_t cycle, ThreadToken t) {
  open_[t].ready = cycle;
}

// A thread issuing while its record has issued already comes from a chain: the chained request
// ends here and a record without queue or fetch stages starts.
void RunTracer::issued(std::uint64_t cycle, UnitId unit, ThreadToken t, const Request& req,
                       int steps, std::uint64_t done_at) {
  Record& r = open_[t];
  if (!r.open || r.issued != kUnset) {
    if (r.open) close(r, cycle);
    r = Record{};
    r.open = true;
    r.thread = t;
  }
  const TracedStep& s = threads_.traced(t);
  r.unit = unit;
  r.phase = req.phase;
  r.item = req.item;
  r.steps = steps;
  r.packet = s.packet;
  r.seq = s.seq;
  r.mask = s.mask;
  r.kind = s.kind;
  r.issued = cycle;
  r.done_at = done_at == 0 ? kUnset : done_at;
  if (o_.trace == nullptr || cycle < o_.from || cycle > o_.to) return;
  if (o_.packet >= 0 && s.packet != o_.packet) return;
  TraceLine l;
  l.cycle = cycle;
  l.dynrtp = static_cast<int>(t) / per_pipeline_;
  l.thread = static_cast<int>(t);
  l.packet = s.packet;
  l.seq = s.seq;
  l.unit = unit;
  l.phase = req.phase;
  l.item = req.item;
  l.steps = req.steps;
  l.mask = s.mask;
  l.kind = s.kind;
  l.txn = s.txn;
  *o_.trace << format_trace_line(l) << '\n';
}

void RunTracer::left(std::uint64_t cycle, ThreadToken t) {
  Record& r = open_[t];
  if (r.open) close(r, cycle);
}

void RunTracer::close(Record& r, std::uint64_t cycle) {
  r.open = false;
  r.left = cycle;
  if (o_.konata == nullptr || !konata_thread(r.thread)) return;
  if (o_.packet >= 0 && r.packet != o_.packet) return;
  const std::uint64_t start = r.queued != kUnset ? r.queued : r.issued;
  if (start < o_.from || start > o_.to) return;
  done_.push_back(r);
}

void RunTracer::finish() {
  if (o_.konata == nullptr) return;
  write_konata(*o_.konata, std::move(done_), per_pipeline_);
  done_.clear();
}

namespace {

struct Command {
  std::uint64_t cycle;
  std::string text;
};

// The record's stages as [begin, end) spans in kKonataStages order (empty ones dropped).
std::vector<std::pair<std::uint64_t, std::uint64_t>> spans(const RunTracer::Record& r,
                                                           std::vector<const char*>& names) {
  constexpr std::uint64_t kUnset = RunTracer::kUnset;
  const std::uint64_t issue_end = r.issued + static_cast<std::uint64_t>(r.steps);
  const std::uint64_t fetch_end = r.fetched != kUnset ? r.fetched + 1 : kUnset;
  const bool chained = r.done_at == kUnset;
  const std::uint64_t bounds[7][2] = {{r.queued, r.accepted},
                                      {r.accepted, r.fetched != kUnset ? fetch_end : kUnset},
                                      {fetch_end, r.ready},
                                      {r.ready, r.issued},
                                      {r.issued, chained ? r.left : issue_end},
                                      {chained ? kUnset : issue_end, r.done_at},
                                      {chained ? kUnset : r.done_at, r.left}};
  std::vector<std::pair<std::uint64_t, std::uint64_t>> out;
  names.clear();
  for (int i = 0; i < 7; ++i) {
    const std::uint64_t b = bounds[i][0], e = bounds[i][1];
    if (b == kUnset || e == kUnset || e <= b) continue;
    out.emplace_back(b, e);
    names.push_back(kKonataStages[i]);
  }
  return out;
}

void record_commands(const RunTracer::Record& r, std::size_t id, std::size_t retire_id,
                     int per_pipeline, std::vector<Command>& out) {
  std::vector<const char*> names;
  const auto st = spans(r, names);
  const std::uint64_t start = r.queued != RunTracer::kUnset ? r.queued : r.issued;
  const std::string sid = std::to_string(id);
  out.push_back({start, "I\t" + sid + "\t" + sid + "\t" + std::to_string(r.thread)});
  std::ostringstream label;
  label << r.packet << '.' << r.seq << ' ' << unit_name(r.unit) << ' ' << phase_name(r.phase);
  if (r.item != memif::kNone) label << ' ' << r.item;
  out.push_back({start, "L\t" + sid + "\t0\t" + label.str()});
  std::ostringstream detail;
  detail << "dynrtp " << r.thread / static_cast<ThreadToken>(per_pipeline) << " thread " << r.thread
         << " packet " << r.packet << " request " << r.seq << " steps " << r.steps << " mask 0x"
         << std::hex << r.mask << std::dec << ' ' << ray_kind_name(r.kind);
  out.push_back({start, "L\t" + sid + "\t1\t" + detail.str()});
  for (std::size_t i = 0; i < st.size(); ++i) {
    out.push_back({st[i].first, "S\t" + sid + "\t0\t" + names[i]});
    out.push_back({st[i].second, "E\t" + sid + "\t0\t" + names[i]});
  }
  out.push_back({r.left, "R\t" + sid + "\t" + std::to_string(retire_id) + "\t0"});
}

}  // namespace

void write_konata(std::ostream& out, std::vector<RunTracer::Record> records, int per_pipeline) {
  const auto start = [](const RunTracer::Record& r) {
    return r.queued != RunTracer::kUnset ? r.queued : r.issued;
  };
  // Ids in the order the records enter (ties: by thread); retire ids in the order they leave.
  std::stable_sort(records.begin(), records.end(), [&](const auto& a, const auto& b) {
    return start(a) != start(b) ? start(a) < start(b) : a.thread < b.thread;
  });
  std::vector<std::size_t> by_left(records.size());
  for (std::size_t i = 0; i < by_left.size(); ++i)
    by_left[i] = i;
  std::stable_sort(by_left.begin(), by_left.end(),
                   [&](std::size_t a, std::size_t b) { return records[a].left < records[b].left; });
  std::vector<std::size_t> retire_id(records.size());
  for (std::size_t k = 0; k < by_left.size(); ++k)
    retire_id[by_left[k]] = k;
  std::vector<Command> cmds;
  for (std::size_t i = 0; i < records.size(); ++i)
    record_commands(records[i], i, retire_id[i], per_pipeline, cmds);
  // A record's commands are in rising cycles; a stable sort by cycle keeps them in that order.
  std::stable_sort(cmds.begin(), cmds.end(),
                   [](const Command& a, const Command& b) { return a.cycle < b.cycle; });
  out << "Kanata\t0004\n";
  std::uint64_t now = cmds.empty() ? 0 : cmds.front().cycle;
  out << "C=\t" << now << '\n';
  for (const Command& c : cmds) {
    if (c.cycle != now) out << "C\t" << c.cycle - now << '\n';
    now = c.cycle;
    out << c.text << '\n';
  }
}

}  // namespace saarcor::units
