// The report module (testbench/report.h): the statistics' places in the reports, the JSON and
// stats.txt made from them, and the run folder's one writer.
#include "testbench/report.h"

#include <algorithm>
#include <array>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string_view>

#include "host/tree_settings.h"
#include "testbench/compare.h"
#include "testbench/cycle_render.h"
#include "testbench/frame_sequence.h"
#include "testbench/image_io.h"
#include "testbench/paper_cmd.h"
#include "testbench/precision_cmd.h"
#include "testbench/render_cmd.h"
#include "testbench/sampling.h"
#include "testbench/scene_cmd.h"
#include "testbench/sweep_cmd.h"

namespace saarcor {
namespace {

bool shell_safe(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
         std::string_view("_@%+=:,./-").find(c) != std::string_view::npos;
}

std::string format_value(double v) {
  char buf[64];
  // Integers (counts, cycles) exactly; the rest at gem5's six decimals.
  if (std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 9007199254740992.0)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else
    std::snprintf(buf, sizeof buf, "%.6f", v);
  return buf;
}

void append_lines(std::string& s, const std::vector<StatLine>& lines) {
  for (const StatLine& l : lines) {
    const std::string desc = l.unit.empty() ? l.desc : l.desc + " (" + l.unit + ")";
    char buf[512];
    std::snprintf(buf, sizeof buf, "%-56s %20s  # %s\n", l.name.c_str(),
                  format_value(l.value).c_str(), desc.c_str());
    s += buf;
  }
}

double num(const nlohmann::json& j) {
  if (j.is_boolean()) return j.get<bool>() ? 1.0 : 0.0;
  return j.is_number() ? j.get<double>() : 0.0;
}

double per(std::uint64_t a, std::uint64_t b) {
  return b == 0 ? 0.0 : static_cast<double>(a) / static_cast<double>(b);
}

// A counter's total and its mean per ray ({name}.total, {name}.per_ray).
void add_counter(std::vector<ReportStat>& out, const std::string& name, const char* unit,
                 const char* desc, std::uint64_t total, std::uint64_t rays) {
  out.push_back({name + ".total", unit, std::string(desc) + ", total", total});
  out.push_back({name + ".per_ray", std::string(unit) + "/ray", std::string(desc) + ", per ray",
                 per(total, rays)});
}

}  // namespace

// ---- statistics --------------------------------------------------------------------------------

nlohmann::json nest(const std::vector<ReportStat>& stats) {
  nlohmann::json j = nlohmann::json::object();
  for (const ReportStat& s : stats) {
    nlohmann::json* at = &j;
    std::size_t from = 0;
    for (std::size_t dot = s.name.find('.'); dot != std::string::npos;
         from = dot + 1, dot = s.name.find('.', from))
      at = &(*at)[s.name.substr(from, dot - from)];
    (*at)[s.name.substr(from)] = s.value;
  }
  return j;
}

const nlohmann::json& json_at(const nlohmann::json& j, const std::string& dotted) {
  static const nlohmann::json null;
  const nlohmann::json* at = &j;
  std::size_t from = 0;
  while (true) {
    const std::size_t dot = dotted.find('.', from);
    const std::string key = dotted.substr(from, dot == std::string::npos ? dot : dot - from);
    if (!at->is_object() || !at->contains(key)) return null;
    at = &(*at)[key];
    if (dot == std::string::npos) return *at;
    from = dot + 1;
  }
}

std::vector<StatLine> stat_lines(const std::vector<ReportStat>& stats, const std::string& prefix) {
  std::vector<StatLine> lines;
  lines.reserve(stats.size());
  for (const ReportStat& s : stats)
    lines.push_back({prefix + s.name, num(s.value), s.desc, s.unit});
  return lines;
}

std::string stats_text(const std::vector<StatLine>& lines) {
  std::string s = "\n---------- Begin Simulation Statistics ----------\n";
  append_lines(s, lines);
  s += "\n---------- End Simulation Statistics   ----------\n";
  return s;
}

std::string stats_text_blocks(
    const std::vector<std::pair<std::string, std::vector<StatLine>>>& blocks) {
  std::string s;
  for (const auto& [title, lines] : blocks) {
    s += "\n---------- Begin Simulation Statistics ----------\n# " + title + "\n";
    append_lines(s, lines);
    s += "\n---------- End Simulation Statistics   ----------\n";
  }
  return s;
}

// ---- the models' counters ----------------------------------------------------------------------

std::vector<ReportStat> op_stats(const units::UnitStats& u) {
  std::vector<ReportStat> out;
  for (const units::OpUnitDecl& unit : units::kOpUnitDecls) {
    const ff::OpCounts& ops = u.*unit.member;
    const std::string pre = std::string("ops.") + unit.name + ".";
    for (const auto& d : units::kOpCounterDecls)
      out.push_back({pre + d.name, d.unit, d.desc, ops.*d.member});
    out.push_back({pre + "total", "ops", units::kOpTotalDesc, ops.total()});
  }
  return out;
}

std::vector<ReportStat> functional_counter_stats(const units::FunctionalFrame& frame,
                                                 std::uint64_t& rays) {
  std::vector<ReportStat> out;
  rays = 0;
  for (int k = 0; k < units::kRayKinds; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    const units::RayCounters& c = frame.by_kind[kk];
    const std::uint64_t n = frame.rays_issued[kk];
    rays += n;
    const std::string pre =
        std::string("per_ray.") + units::ray_kind_name(static_cast<units::RayKind>(k)) + ".";
    for (const auto& d : units::kRayCounterDecls)
      add_counter(out, pre + d.name, d.unit, d.desc, c.*d.member, n);
    out.push_back({pre + "rays_issued", "rays", "rays issued", n});
    out.push_back({pre + "rays_returned", "rays", "rays returned", frame.rays_returned[kk]});
  }
  for (ReportStat& s : op_stats(frame.units))
    out.push_back(std::move(s));
  for (const auto& d : units::kUnitCounterDecls)
    out.push_back({std::string("units.") + d.name, d.unit, d.desc, frame.units.*d.member});
  for (const auto& d : units::kFrameCounterDecls)
    out.push_back({std::string("units.") + d.name, d.unit, d.desc, frame.units.*d.member});
  return out;
}

std::vector<ReportStat> float_counter_stats(const host::FloatTraceStats& s) {
  // host::FloatTraceStats counts what the functional model's RayCounters count, and the leaves.
  const struct {
    const char* name;
    const char* unit;
    const char* desc;
    std::uint64_t value;
  } counters[] = {
      {"traversal_steps", "steps", "kd-tree traversal steps (inner, leaf and clip)",
       s.traversal_steps},
      {"leaves", "leaves", "kd-tree leaves visited", s.leaves},
      {"list_entries", "entries", "list entries read (objects and triangles)", s.list_entries},
      {"mailbox_skips", "entries", "list entries skipped by the mailbox", s.mailbox_skips},
      {"transformations", "steps", "rays transformed (into object or unit-triangle space)",
       s.transformations},
      {"intersections", "tests", "ray-triangle intersection tests", s.intersections},
  };
  std::vector<ReportStat> out;
  for (const auto& c : counters)
    add_counter(out, std::string("per_ray.") + c.name, c.unit, c.desc, c.value, s.rays);
  return out;
}

// ---- the cycle model's frame report ------------------------------------------------------------

namespace {

// A statistic of the cycle model's frame report: its place, unit, description and its formula
// over the frame.
struct CycleStatDecl {
  std::string name, unit, desc;
  std::function<nlohmann::json(const CycleFrame&)> value;
};

void frame_decls(std::vector<CycleStatDecl>& d) {
  d.push_back({"cycles", "cycles", "simulated cycles of the frame",
               [](const CycleFrame& c) { return nlohmann::json(c.cycles); }});
  d.push_back({"fps", "frames/s", "frames per second at the modelled clock",
               [](const CycleFrame& c) { return nlohmann::json(c.fps); }});
  d.push_back({"rays", "rays", "rays traced, all kinds",
               [](const CycleFrame& c) { return nlohmann::json(c.rays); }});
  d.push_back({"rays_per_s", "rays/s", "rays per second at the modelled clock",
               [](const CycleFrame& c) { return nlohmann::json(c.rays_per_s); }});
  d.push_back({"packets", "packets", "ray packets",
               [](const CycleFrame& c) { return nlohmann::json(c.packets); }});
  d.push_back({"cycles_per_packet", "cycles", "cycles per packet",
               [](const CycleFrame& c) { return nlohmann::json(per(c.cycles, c.packets)); }});
  d.push_back({"simd_efficiency", "ratio", "active rays per packet step / packet width",
               [](const CycleFrame& c) { return nlohmann::json(c.simd_efficiency); }});
  // The Table 4 figures the report writes (units/figures.h), each with its own declaration.
  for (int i = 0; i < units::kFigureCount; ++i) {
    const units::FigureInfo& f = units::kFigures[i];
    if (!f.in_report) continue;
    d.push_back({f.name, f.unit, f.help,
                 [i](const CycleFrame& c) { return nlohmann::json(c.figures.at(i)); }});
  }
}

// The RGS's traffic (docs/shading.md "Shading traffic") and the per-ray counters.
void rgs_and_ray_decls(std::vector<CycleStatDecl>& d) {
  d.push_back({"rgs.shading_bytes", "bytes", "shading-bank bytes the RGS read",
               [](const CycleFrame& c) { return nlohmann::json(c.shading_bytes); }});
  d.push_back({"rgs.frame_buffer_bytes", "bytes", "frame-buffer bytes the RGS wrote",
               [](const CycleFrame& c) { return nlohmann::json(c.frame_bytes); }});
  d.push_back({"rgs.shading_bytes_per_pixel", "bytes/pixel",
               "shading reads and frame-buffer writes over the pixels",
               [](const CycleFrame& c) { return nlohmann::json(c.shading_bytes_per_pixel); }});
  d.push_back({"rgs.frame_bank", "bank", "the frame-buffer bank the frame was written into",
               [](const CycleFrame& c) { return nlohmann::json(c.frame_bank); }});
  for (const auto& r : units::kRayCounterDecls)
    d.push_back({std::string("per_ray.") + r.name, std::string(r.unit) + "/ray",
                 std::string(r.desc) + ", per ray", [m = r.member](const CycleFrame& c) {
                   return nlohmann::json(per(c.per_ray_sum.*m, c.rays));
                 }});
  d.push_back({"ops.traversal_to_intersection", "ratio",
               "traversal float ops over intersection float ops", [](const CycleFrame& c) {
                 const units::UnitStats& u = c.frame.units;
                 return nlohmann::json(per(u.traversal_ops.total(), u.intersection_ops.total()));
               }});
}

// Per unit of Table 4 and per cache, summed over the DynRTPs.
void unit_and_cache_decls(std::vector<CycleStatDecl>& d) {
  using Counts = std::array<std::uint64_t, units::kTable4Units>;
  const struct {
    const char* key;
    const char* unit;
    const char* desc;
    Counts CycleFrame::*member;
  } per_unit[] = {
      {"issue_cycles", "cycles", "cycles the unit issued a step", &CycleFrame::issue_cycles},
      {"stall_cycles", "cycles", "cycles the unit was stalled", &CycleFrame::stall_cycles},
      {"requests", "requests", "thread-program requests the unit served", &CycleFrame::requests},
  };
  for (int i = 0; i < units::kTable4Units; ++i)
    for (const auto& u : per_unit)
      d.push_back({std::string("units.") + units::kTable4UnitNames[i] + "." + u.key, u.unit, u.desc,
                   [i, m = u.member](const CycleFrame& c) {
                     return nlohmann::json((c.*m)[static_cast<std::size_t>(i)]);
                   }});
  using Cache = CycleFrame::CacheCount;
  const struct {
    const char* key;
    const char* unit;
    const char* desc;
    std::uint64_t Cache::*member;
  } per_cache[] = {
      {"requests", "requests", "packet requests to the cache", &Cache::requests},
      {"hits", "requests", "requests served from a present line", &Cache::hits},
      {"merges", "requests", "requests merged into an outstanding miss", &Cache::merges},
      {"misses", "requests", "requests that fetched their line", &Cache::misses},
      {"mem_bytes", "bytes", "bytes the cache read from memory", &Cache::mem_bytes},
  };
  for (int i = 0; i < units::kCacheUnits; ++i)
    for (const auto& k : per_cache)
      d.push_back(
          {std::string("caches.") + units::cache_unit_name(units::CacheUnit(i)) + "." + k.key,
           k.unit, k.desc, [i, m = k.member](const CycleFrame& c) {
             return nlohmann::json(c.caches[static_cast<std::size_t>(i)].*m);
           }});
}

const std::vector<CycleStatDecl>& cycle_decls() {
  static const std::vector<CycleStatDecl> decls = [] {
    std::vector<CycleStatDecl> d;
    frame_decls(d);
    rgs_and_ray_decls(d);
    unit_and_cache_decls(d);
    return d;
  }();
  return decls;
}

// Per DynRTP (one in the prototype): the packets the RGC handed it, its units' usage.
nlohmann::json pipelines_json(const CycleFrame& c) {
  nlohmann::json pipes = nlohmann::json::array();
  // A sampled frame's counts are those of the packets it simulated, over the cycles it ran.
  const std::uint64_t cycles = c.sampling ? c.sampling->cycles_simulated : c.cycles;
  for (const CycleFrame::PipelineCount& pc : c.per_pipeline) {
    nlohmann::json e;
    e["packets"] = pc.packets;
    for (int i = 0; i < units::kTable4Units; ++i)
      e["usage"][units::kTable4UnitNames[i]] =
          100.0 * per(pc.issue_cycles[static_cast<std::size_t>(i)], cycles);
    pipes.push_back(e);
  }
  return pipes;
}

// The figures of a span (units/figures.h kFigures) the frame's report writes, into `j` at their
// dotted names ({"usage": {...}, "cache_hit": {...}, "bandwidth_mb_s": {...}}).
void add_figures(nlohmann::json& j, const units::CycleFigures& f) {
  for (int i = 0; i < units::kFigureCount; ++i) {
    const units::FigureInfo& info = units::kFigures[i];
    if (!info.in_report) continue;
    const std::string_view n = info.name;
    const std::size_t dot = n.find('.');
    j[std::string(n.substr(0, dot))][std::string(n.substr(dot + 1))] = f.at(i);
  }
}

}  // namespace

std::vector<ReportStat> cycle_stats(const CycleFrame& c) {
  std::vector<ReportStat> out;
  for (const CycleStatDecl& d : cycle_decls())
    out.push_back({d.name, d.unit, d.desc, d.value(c)});
  return out;
}

namespace {

// A sampled frame's `sampling` object (testbench/sampling.h): how it was sampled and, beside each
// estimated figure's usual key, its 95 % interval as ci95.<key> = [low, high].
nlohmann::json sampling_json(const CycleFrame& c) {
  const SampleSummary& s = *c.sampling;
  nlohmann::json j = {{"window", s.spec.window},
                      {"period", s.spec.period},
                      {"warmup", s.spec.warmup},
                      {"cooldown", s.spec.cooldown},
                      {"windows", s.windows},
                      {"packets", s.packets},
                      {"packets_simulated", s.packets_simulated},
                      {"cycles_simulated", s.cycles_simulated},
                      {"cycles_per_packet_cov", s.cycles_per_packet_cov},
                      {"covariate_seconds", s.covariate_seconds},
                      {"covariate_correlation", s.covariate_correlation},
                      {"costly_packets", s.costly_packets},
                      {"costly_windows", s.costly_windows},
                      {"trusted", s.defeated.empty()}};
  // A frame that defeats the sampling says why, and gives no interval to read as a narrow one.
  if (!s.defeated.empty()) {
    j["defeated"] = s.defeated;
    return j;
  }
  nlohmann::json ci;
  const auto put = [&ci](const std::string& key, const SampleInterval& i) {
    ci[nlohmann::json::json_pointer("/" + key)] = {i.low, i.high};
  };
  put("cycles", s.cycles);
  put("fps", s.fps);
  put("rays_per_s", s.rays_per_s);
  for (int k = 0; k < units::kFigureCount; ++k) {
    if (!units::kFigures[k].in_report) continue;
    std::string key = units::kFigures[k].name;
    std::replace(key.begin(), key.end(), '.', '/');
    put(key, s.figures[static_cast<std::size_t>(k)]);
  }
  j["ci95"] = ci;
  return j;
}

}  // namespace

nlohmann::json cycle_report_json(const CycleFrame& c, const host::ImageParams* trees) {
  nlohmann::json j = nest(cycle_stats(c));
  j["host"] = {{"seconds", c.host_seconds},
               {"sim_cycles_per_s", c.sim_cycles_per_s},
               {"threads", c.host_threads},
               {"programs", units::program_mode_name(c.programs)},
               {"skipped_cycles", c.skipped_cycles}};
  j["pipelines"] = pipelines_json(c);
  j["configuration"] = parameters_json(&c.params, trees);
  // The hw/ statistics registry in full: per unit, cache, path and memory client.
  j["stats"] = nlohmann::json::parse(c.stats_json);
  if (c.sampling) j["sampling"] = sampling_json(c);
  if (!c.series.empty()) {
    nlohmann::json s = nlohmann::json::array();
    for (const units::CycleFigures& f : c.series) {
      nlohmann::json e;
      add_figures(e, f);
      e["cycle"] = f.cycle;
      s.push_back(e);
    }
    j["time_series"] = s;
  }
  return j;
}

std::vector<StatLine> cycle_stat_lines(const nlohmann::json& cycle) {
  std::vector<StatLine> lines;
  for (const CycleStatDecl& d : cycle_decls())
    lines.push_back({"frame." + d.name, num(json_at(cycle, d.name)), d.desc, d.unit});
  // The registry's statistics carry their declarations in the report (hw/stats.h).
  if (cycle.contains("stats"))
    for (const auto& [name, s] : cycle["stats"].items())
      lines.push_back({name, num(s["value"]), s.value("desc", ""), s.value("unit", "")});
  return lines;
}

// ---- frame sequences ---------------------------------------------------------------------------

namespace {

using Row = const SequenceFrame&;
using Run = const SequenceResult&;

// Which of the two per-frame tables (the cycle model's, a functional model's) prints a column.
enum class Printed : unsigned char { kNo, kAlways, kCycle, kFunctional };

// A declared column's cell in a printed table: its header and the printf format of its value.
struct Cell {
  Printed printed = Printed::kNo;
  const char* head = "";
  const char* format = "%.0f";
};

// One column of a frame sequence's per-frame rows, declared once: its JSON key (dotted: nested)
// and CSV column ('.' -> '_'), unit, description, value and printed cell. The rows are written
// from this table as JSON (report.json), CSV (frames.csv), statistics (stats.txt) and the printed
// table (sequence_table).
struct RowColumn {
  const char* name;
  const char* unit;
  const char* desc;
  bool cycle_only;  // timed: the cycle model's rows only
  bool in_csv;      // frames.csv has it
  nlohmann::json (*value)(const SequenceFrame&);
  Cell cell = {};
  const char* (*word)(const SequenceFrame&) = nullptr;  // printed in place of the value
  bool upload = false;  // frame 0 prints "-": its upload is the initial load (the table's header)
  bool host = false;    // the host's wall clock: the printout, and the report outside a run folder
};

const char* yes_no(bool b) {
  return b ? "yes" : "no";
}

// A Table 4 figure of the frame, as units/figures.h declares it.
template <int kFigure>
constexpr RowColumn figure_column(Cell cell = {}) {
  const units::FigureInfo& f = units::kFigures[kFigure];
  return {f.name, f.unit, f.help,
          true,   true,   [](Row r) { return nlohmann::json(r.figures.at(kFigure)); },
          cell};
}

constexpr RowColumn kRowColumns[] = {
    {"frame",
     "frame",
     "the frame's index",
     false,
     true,
     [](Row f) { return nlohmann::json(f.index); },
     {Printed::kAlways, "frame"}},
    {"time",
     "s",
     "animation time",
     false,
     true,
     [](Row f) { return nlohmann::json(f.time); },
     {Printed::kAlways, "time s", "%.3f"}},
    {"frame_bank",
     "bank",
     "the frame-buffer bank written",
     false,
     true,
     [](Row f) { return nlohmann::json(f.frame_bank); },
     {Printed::kAlways, "bank"}},
    {"top_copy",
     "copy",
     "the top-level copy the frame reads",
     false,
     true,
     [](Row f) { return nlohmann::json(f.top_copy); },
     {Printed::kAlways, "copy"}},
    {"top_rebuilt", "bool", "the top-level tree was rebuilt (1 = yes)", false, true,
     [](Row f) { return nlohmann::json(f.top_rebuilt); }},
    {"moved_instances",
     "instances",
     "instances moved since the previous frame",
     false,
     true,
     [](Row f) { return nlohmann::json(f.moved_instances); },
     {Printed::kAlways, "moved"}},
    {"top_level_builds",
     "trees",
     "top-level trees built for the frame",
     false,
     true,
     [](Row f) { return nlohmann::json(f.top_level_builds); },
     {Printed::kAlways, "top"}},
    {"bottom_level_builds",
     "trees",
     "bottom-level trees built for the frame",
     false,
     true,
     [](Row f) { return nlohmann::json(f.bottom_level_builds); },
     {Printed::kAlways, "bot"}},
    {"upload_bytes",
     "bytes",
     "bytes uploaded: changed SRAM words and the registers",
     false,
     true,
     [](Row f) { return nlohmann::json(f.upload_bytes); },
     {Printed::kAlways, "upload B"},
     nullptr,
     true},
    {"upload_words", "words", "changed SRAM words uploaded", false, true,
     [](Row f) { return nlohmann::json(f.upload_words); }},
    {"upload_runs", "runs", "runs of consecutive words uploaded", false, true,
     [](Row f) { return nlohmann::json(f.upload_runs); }},
    {"upload_in_gap",
     "bool",
     "the upload waited for the previous frame's end (1 = yes)",
     false,
     true,
     [](Row f) { return nlohmann::json(f.gap); },
     {Printed::kFunctional, "gap"},
     [](Row f) { return yes_no(f.gap); },
     true},
    {"upload_cycles",
     "cycles",
     "from the previous frame's start until the upload was stored",
     true,
     true,
     [](Row f) { return nlohmann::json(f.upload_cycles); },
     {Printed::kCycle, "upload cyc"},
     nullptr,
     true},
    {"upload_hidden",
     "bool",
     "the upload was done within the previous frame (1 = yes)",
     true,
     true,
     [](Row f) { return nlohmann::json(f.hidden); },
     {Printed::kCycle, "hidden"},
     [](Row f) { return f.gap ? "gap" : yes_no(f.hidden); },
     true},
    {"stall_cycles",
     "cycles",
     "cycles the frame started after the previous frame's end",
     true,
     true,
     [](Row f) { return nlohmann::json(f.stall_cycles); },
     {Printed::kCycle, "stall"},
     nullptr,
     true},
    {"start_cycle", "cycles", "the frame's start on the sequence's clock", true, true,
     [](Row f) { return nlohmann::json(f.start_cycle); }},
    {"cycles",
     "cycles",
     "simulated cycles of the frame",
     true,
     true,
     [](Row f) { return nlohmann::json(f.cycles); },
     {Printed::kCycle, "render cyc"}},
    {"fps",
     "frames/s",
     "frames per second rendering alone, at the modelled clock",
     true,
     true,
     [](Row f) { return nlohmann::json(f.fps); },
     {Printed::kCycle, "fps", "%.1f"}},
    figure_column<units::figure_index("usage.traversal")>({Printed::kCycle, "trav"}),
    figure_column<units::figure_index("usage.list")>({Printed::kCycle, "list"}),
    figure_column<units::figure_index("usage.transformation")>({Printed::kCycle, "xfrm"}),
    figure_column<units::figure_index("usage.intersection")>({Printed::kCycle, "int"}),
    figure_column<units::figure_index("cache_hit.traversal")>({Printed::kCycle, "hit t"}),
    figure_column<units::figure_index("cache_hit.list")>({Printed::kCycle, "hit l"}),
    figure_column<units::figure_index("cache_hit.transformation")>({Printed::kCycle, "hit x"}),
    figure_column<units::figure_index("bandwidth_mb_s.dynrtc")>(),
    {"cycles_per_packet", "cycles", "cycles per packet", true, true,
     [](Row f) { return nlohmann::json(f.cycles_per_packet); }},
    figure_column<units::figure_index("bandwidth_mb_s.rgs")>(),
    {"shading_bytes_per_pixel", "bytes/pixel",
     "shading reads and frame-buffer writes over the pixels", true, true,
     [](Row f) { return nlohmann::json(f.shading_bytes_per_pixel); }},
    {"bit_identical_to_functional_model", "bool",
     "hit records and image equal to the functional model's (1 = yes)", true, false,
     [](Row f) { return nlohmann::json(f.checked); }},
    {"rays", "rays", "rays traced, all kinds", false, true,
     [](Row f) { return nlohmann::json(f.rays); }},
    {"digest", "hash", "FNV-1a of the hit records and the image", false, true,
     [](Row f) { return nlohmann::json(f.digest); }},
    // The host's top-level (re)build on this machine: not on the model's clock (D46).
    {"host_rebuild_ms",
     "ms",
     "the host's top-level rebuild for the frame (wall clock)",
     false,
     false,
     [](Row f) { return nlohmann::json(f.host_rebuild_seconds * 1e3); },
     {Printed::kAlways, "rebuild ms", "%.2f"},
     nullptr,
     false,
     true},
};

bool in_rows(const RowColumn& c, bool cycle, bool host_times) {
  return (cycle || !c.cycle_only) && (host_times || !c.host);
}

std::vector<ReportStat> row_stats(const SequenceFrame& f, bool cycle, bool host_times = false) {
  std::vector<ReportStat> out;
  for (const RowColumn& c : kRowColumns)
    if (in_rows(c, cycle, host_times)) out.push_back({c.name, c.unit, c.desc, c.value(f)});
  return out;
}

// Frames 1..N-1: frame 0's upload is the initial load, its trees the first build.
std::uint64_t sum_after_first(Run r, std::uint64_t SequenceFrame::*m) {
  std::uint64_t s = 0;
  for (std::size_t k = 1; k < r.frames.size(); ++k)
    s += r.frames[k].*m;
  return s;
}
std::uint64_t max_after_first(Run r, std::uint64_t SequenceFrame::*m) {
  std::uint64_t s = 0;
  for (std::size_t k = 1; k < r.frames.size(); ++k)
    s = std::max(s, r.frames[k].*m);
  return s;
}
std::size_t uploads(Run r) {
  return r.frames.empty() ? 0 : r.frames.size() - 1;
}
double mean_after_first(Run r, std::uint64_t SequenceFrame::*m) {
  return r.frames.size() > 1
             ? static_cast<double>(sum_after_first(r, m)) / static_cast<double>(r.frames.size() - 1)
             : 0.0;
}

int frames_delayed(Run r) {
  int n = 0;
  for (std::size_t k = 1; k < r.frames.size(); ++k)
    n += r.frames[k].stall_cycles > 0 ? 1 : 0;
  return n;
}

// One statistic of a sequence's summary, declared once: its key, unit, description and value,
// and its cell in the bus sweep's table (a sequence per row).
struct SummaryColumn {
  const char* name;
  const char* unit;
  const char* desc;
  bool cycle_only;
  nlohmann::json (*value)(const SequenceResult&);
  const char* head = nullptr;  // the bus sweep table's header (nullptr: not printed)
  const char* format = "%.0f";
  std::string (*text)(const SequenceResult&) = nullptr;  // printed in place of the value
};

constexpr SummaryColumn kSummaryColumns[] = {
    {"upload_bytes_total", "bytes", "bytes uploaded after frame 0", false,
     [](Run r) { return nlohmann::json(sum_after_first(r, &SequenceFrame::upload_bytes)); }},
    {"upload_bytes_mean", "bytes", "bytes uploaded per frame after frame 0", false,
     [](Run r) { return nlohmann::json(mean_after_first(r, &SequenceFrame::upload_bytes)); }},
    {"upload_bytes_max", "bytes", "largest upload after frame 0", false,
     [](Run r) { return nlohmann::json(max_after_first(r, &SequenceFrame::upload_bytes)); }},
    {"top_level_rebuilds", "trees", "top-level trees rebuilt after frame 0", false,
     [](Run r) { return nlohmann::json(sum_after_first(r, &SequenceFrame::top_level_builds)); }},
    {"bottom_level_rebuilds", "trees", "bottom-level trees rebuilt after frame 0", false,
     [](Run r) { return nlohmann::json(sum_after_first(r, &SequenceFrame::bottom_level_builds)); }},
    {"bottom_level_trees", "trees", "bottom-level trees built for frame 0", false,
     [](Run r) {
       return nlohmann::json(r.frames.empty() ? 0 : r.frames.front().bottom_level_builds);
     }},
    {"cycles", "cycles", "the sequence from frame 0's start to the last frame's end", true,
     [](Run r) { return nlohmann::json(r.total_cycles()); }},
    {"fps", "frames/s", "frames per second with the uploads", true,
     [](Run r) { return nlohmann::json(r.fps()); }, "sequence fps", "%.2f"},
    {"render_fps", "frames/s", "frames per second rendering alone", true,
     [](Run r) { return nlohmann::json(r.render_fps()); }, "render fps", "%.2f"},
    {"uploads_hidden", "uploads", "uploads done within the previous frame", true,
     [](Run r) { return nlohmann::json(r.hidden_uploads()); }, "uploads hidden", "",
     [](Run r) {
       return std::to_string(r.hidden_uploads()) + " of " + std::to_string(uploads(r));
     }},
    {"uploads_in_gaps", "uploads", "uploads that waited for a frame's end", true,
     [](Run r) { return nlohmann::json(r.gaps()); }},
    {"uploads", "uploads", "uploads after frame 0", true,
     [](Run r) { return nlohmann::json(uploads(r)); }},
    {"break_even_mb_s", "MB/s", "the lowest bus bandwidth every upload fits behind", true,
     [](Run r) { return nlohmann::json(r.break_even_mb_s()); }},
    {"frames_delayed", "frames", "frames that started after the previous frame's end", true,
     [](Run r) { return nlohmann::json(frames_delayed(r)); }, "frames delayed"},
    {"stall_cycles_max", "cycles", "the longest wait of a frame for its upload", true,
     [](Run r) { return nlohmann::json(max_after_first(r, &SequenceFrame::stall_cycles)); },
     "max stall cyc"},
    {"upload_cycles_mean", "cycles",
     "the uploads' cycles from the previous frame's start, per frame after frame 0", true,
     [](Run r) { return nlohmann::json(mean_after_first(r, &SequenceFrame::upload_cycles)); },
     "mean upload cyc"},
};

std::vector<ReportStat> summary_stats(const SequenceResult& r) {
  std::vector<ReportStat> out;
  for (const SummaryColumn& c : kSummaryColumns)
    if (r.cycle || !c.cycle_only) out.push_back({c.name, c.unit, c.desc, c.value(r)});
  return out;
}

std::string csv_cell(const RowColumn& c, const nlohmann::json& v) {
  char buf[40];
  if (std::string_view(c.name) == "digest")
    std::snprintf(buf, sizeof buf, "%016" PRIx64, v.get<std::uint64_t>());
  else if (v.is_boolean())
    return v.get<bool>() ? "1" : "0";
  else if (v.is_number_float())
    std::snprintf(buf, sizeof buf, "%.17g", v.get<double>());
  else
    return v.dump();
  return buf;
}

std::string printf_cell(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// Rows of cells (the first: the headers) right-aligned in columns two spaces apart.
std::string aligned(const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> width;
  for (const auto& row : rows)
    for (std::size_t i = 0; i < row.size(); ++i) {
      if (width.size() <= i) width.push_back(0);
      width[i] = std::max(width[i], row[i].size());
    }
  std::string s;
  for (const auto& row : rows) {
    for (std::size_t i = 0; i < row.size(); ++i)
      s += (i == 0 ? "" : "  ") + std::string(width[i] - row[i].size(), ' ') + row[i];
    s += "\n";
  }
  return s;
}

bool printed(const RowColumn& c, bool cycle) {
  return c.cell.printed == Printed::kAlways || (cycle && c.cell.printed == Printed::kCycle) ||
         (!cycle && c.cell.printed == Printed::kFunctional);
}

std::string row_cell(const RowColumn& c, Row f) {
  if (c.upload && f.index == 0) return "-";
  if (c.word != nullptr) return c.word(f);
  return printf_cell(c.cell.format, num(c.value(f)));
}

// The sequence: scene, model, frames, the scene's instances and the initial load.
std::string table_header(Run r) {
  std::string s;
  char buf[400];
  std::snprintf(
      buf, sizeof buf, "frames: %s, model %s, %dx%d, %zu frames %g s apart, %s\n", r.scene.c_str(),
      r.model.c_str(), r.width, r.height, r.frames.size(), r.dt,
      r.frame_gap ? "one top-level copy (uploads in frame gaps)" : "two top-level copies");
  s += buf;
  std::snprintf(buf, sizeof buf,
                "  %" PRIu64 " objects, %" PRIu64 " instances (%" PRIu64
                " dynamic); a top-level copy %.1f KB; initial load %.2f MB",
                r.objects, r.instances, r.dynamic_instances,
                static_cast<double>(r.top_copy_bytes) / 1024.0,
                static_cast<double>(r.initial_load_bytes) / 1048576.0);
  s += buf;
  if (r.cycle) {
    std::snprintf(buf, sizeof buf, ", %" PRIu64 " cycles = %.1f ms over the %g MB/s host bus",
                  r.initial_load_cycles,
                  static_cast<double>(r.initial_load_cycles) / (r.clock_mhz * 1e3), r.bus_mb_s);
    s += buf;
  }
  return s + "\n";
}

std::string table_summary(Run r) {
  std::string s;
  char buf[400];
  const nlohmann::json sum = nest(summary_stats(r));
  std::snprintf(buf, sizeof buf,
                "summary: uploads %.0f B per frame on average, at most %" PRIu64
                " B; top-level rebuilds %" PRIu64 ", bottom-level rebuilds %" PRIu64 " (%" PRIu64
                " bottom-level trees built for frame 0, reused since)\n",
                sum["upload_bytes_mean"].get<double>(),
                sum["upload_bytes_max"].get<std::uint64_t>(),
                sum["top_level_rebuilds"].get<std::uint64_t>(),
                sum["bottom_level_rebuilds"].get<std::uint64_t>(),
                sum["bottom_level_trees"].get<std::uint64_t>());
  s += buf;
  if (r.cycle && !r.frames.empty()) {
    std::snprintf(buf, sizeof buf,
                  "  %" PRIu64
                  " cycles = %.2f fps at %g MHz with the uploads (%.2f fps rendering "
                  "alone); uploads hidden behind the previous frame: %d of %zu (%d in frame "
                  "gaps); the others would fit down to %.3g MB/s\n",
                  sum["cycles"].get<std::uint64_t>(), sum["fps"].get<double>(), r.clock_mhz,
                  sum["render_fps"].get<double>(), sum["uploads_hidden"].get<int>(),
                  sum["uploads"].get<std::size_t>(), sum["uploads_in_gaps"].get<int>(),
                  sum["break_even_mb_s"].get<double>());
    s += buf;
  }
  return s;
}

const SummaryColumn& summary_column(std::string_view name) {
  for (const SummaryColumn& c : kSummaryColumns)
    if (name == c.name) return c;
  throw std::logic_error("no summary statistic " + std::string(name));
}

}  // namespace

nlohmann::json sequence_json(const SequenceResult& r, bool host_times) {
  nlohmann::json j;
  j["scene"] = r.scene;
  j["model"] = r.model;
  j["resolution"] = {{"width", r.width}, {"height", r.height}};
  j["frames"] = r.frames.size();
  j["dt"] = r.dt;
  j["top_level"] = r.frame_gap ? "one copy (every upload in a frame gap)" : "two copies";
  j["instances"] = r.instances;
  j["dynamic_instances"] = r.dynamic_instances;
  j["objects"] = r.objects;
  j["initial_load"] = {{"bytes", r.initial_load_bytes}};
  j["top_level_copy_bytes"] = r.top_copy_bytes;
  if (r.cycle) {
    j["clock_mhz"] = r.clock_mhz;
    j["hostbus_mb_s"] = r.bus_mb_s;
    j["initial_load"]["cycles"] = r.initial_load_cycles;
  }
  nlohmann::json rows = nlohmann::json::array();
  for (const SequenceFrame& f : r.frames)
    rows.push_back(nest(row_stats(f, r.cycle, host_times)));
  j["per_frame"] = rows;
  j["summary"] = nest(summary_stats(r));
  return j;
}

std::string sequence_csv(const SequenceResult& r) {
  std::string s;
  for (const RowColumn& c : kRowColumns) {
    if (!c.in_csv || (c.cycle_only && !r.cycle)) continue;
    std::string name = c.name;
    std::ranges::replace(name, '.', '_');
    s += (s.empty() ? "" : ",") + name;
  }
  s += "\n";
  for (const SequenceFrame& f : r.frames) {
    std::string line;
    for (const RowColumn& c : kRowColumns) {
      if (!c.in_csv || (c.cycle_only && !r.cycle)) continue;
      line += (line.empty() ? "" : ",") + csv_cell(c, c.value(f));
    }
    s += line + "\n";
  }
  return s;
}

std::string sequence_table(const SequenceResult& r) {
  std::vector<std::vector<std::string>> cells(1);
  for (const RowColumn& c : kRowColumns)
    if (printed(c, r.cycle)) cells[0].push_back(c.cell.head);
  for (const SequenceFrame& f : r.frames) {
    cells.emplace_back();
    for (const RowColumn& c : kRowColumns)
      if (printed(c, r.cycle)) cells.back().push_back(row_cell(c, f));
  }
  return table_header(r) + aligned(cells) + table_summary(r);
}

std::string bus_sweep_table(const std::vector<SequenceResult>& points) {
  // The bandwidth, then the summary statistics that tell where the uploads stop fitting.
  constexpr const char* kColumns[] = {
      "uploads_hidden", "frames_delayed", "stall_cycles_max", "upload_cycles_mean", "fps",
      "render_fps"};
  std::vector<std::vector<std::string>> cells = {{"bus MB/s"}};
  for (const char* name : kColumns)
    cells[0].push_back(summary_column(name).head);
  for (const SequenceResult& p : points) {
    cells.push_back({printf_cell("%.4g", p.bus_mb_s)});
    for (const char* name : kColumns) {
      const SummaryColumn& c = summary_column(name);
      cells.back().push_back(c.text ? c.text(p) : printf_cell(c.format, num(c.value(p))));
    }
  }
  std::string s = aligned(cells);
  if (!points.empty())
    s += "(uploads fit behind rendering down to about " +
         std::to_string(points.front().break_even_mb_s()) +
         " MB/s by bytes over render time, without bank contention)\n";
  return s;
}

nlohmann::json bus_sweep_json(const std::vector<SequenceResult>& points) {
  nlohmann::json j = nlohmann::json::array();
  for (const SequenceResult& p : points) {
    nlohmann::json e = sequence_json(p);
    e["hostbus_mb_s"] = p.bus_mb_s;
    j.push_back(e);
  }
  return j;
}

nlohmann::json sequence_host_json(const SequenceResult& r) {
  nlohmann::json frames = nlohmann::json::array();
  double rebuild_max = 0.0;
  for (const SequenceFrame& f : r.frames) {
    frames.push_back({{"frame", f.index},
                      {"rebuild_seconds", f.host_rebuild_seconds},
                      {"seconds", f.host_seconds}});
    if (f.index > 0) rebuild_max = std::max(rebuild_max, f.host_rebuild_seconds);
  }
  return {{"per_frame", frames}, {"top_level_rebuild_seconds_max", rebuild_max}};
}

nlohmann::json sequence_configuration_json(double time, const RenderSettings& s, bool cycle) {
  nlohmann::json c = {
      {"time", time}, {"shadows", s.shadows}, {"depth", s.depth}, {"bank_mb", s.bank_mb}};
  if (cycle) {
    const units::CycleParams p = resolve_cycle_params(s.cycle);
    c["cycle"] = parameters_json(&p, nullptr);
  }
  host::ImageParams trees;
  for (const std::string& kv : s.cycle.set)
    if (host::is_tree_setting(kv)) host::apply_tree_setting(trees, kv);
  c["trees"] = parameters_json(nullptr, &trees);
  return c;
}

std::vector<StatLine> sequence_stat_lines(const SequenceResult& r) {
  std::vector<StatLine> lines = stat_lines(summary_stats(r), "sequence.");
  for (const SequenceFrame& f : r.frames)
    for (StatLine& l : stat_lines(row_stats(f, r.cycle), "frame" + std::to_string(f.index) + "."))
      lines.push_back(std::move(l));
  return lines;
}

// ---- sweeps -----------------------------------------------------------------------------------

namespace {

// A sweep point's cost, declared once: its name (JSON key under "cost", CSV column, stats.txt
// "cost.NAME"), unit, description and value, from the cost model of the point's configuration
// (units/cost.h, docs/cost.md); the table's header and cell format.
struct CostStatDecl {
  const char* name;
  const char* unit;
  const char* desc;
  const char* head;
  const char* format;
  double (*value)(const units::ConfigurationCost&);
};

using Cost = const units::ConfigurationCost&;
constexpr CostStatDecl kCostStats[] = {
    {"fp_units", "units", "floating-point units of the chip (add, mul, div, cmp, sqrt)", "FP",
     "%5.0f", [](Cost c) { return double(c.fp_total.total()); }},
    {"memory_kb", "KB", "internal memory of the chip, dual-ported bits counted twice", "mem KB",
     "%8.2f", [](Cost c) { return c.memory_kb_total(); }},
    {"luts", "LUTs",
     "Virtex-II LUT estimate: the FP operators' LUTs (measured per operator, docs/cost.md)", "LUTs",
     "%7.0f", [](Cost c) { return double(c.area_total.luts); }},
    {"block_rams", "block RAMs",
     "18-Kbit Virtex-II block RAMs the memories need at least (registers excluded)", "BRAM",
     "%5.0f", [](Cost c) { return double(c.area_total.block_rams); }},
};

}  // namespace

std::vector<std::string> sweep_cost_names() {
  std::vector<std::string> names;
  for (const CostStatDecl& d : kCostStats)
    names.emplace_back(d.name);
  return names;
}

nlohmann::json sweep_cost_json(const units::CostParams& params) {
  const units::ConfigurationCost c = units::configuration_cost(params);
  nlohmann::json j = nlohmann::json::object();
  for (const CostStatDecl& d : kCostStats)
    j[d.name] = d.value(c);
  return j;
}

std::vector<StatLine> sweep_point_stat_lines(const SweepPoint& p, bool pareto) {
  std::vector<StatLine> lines = cycle_stat_lines(p.cycle);
  for (const CostStatDecl& d : kCostStats)
    lines.push_back({std::string("cost.") + d.name, num(json_at(p.cost, d.name)), d.desc, d.unit});
  if (pareto)
    lines.push_back({"cost.pareto", p.pareto ? 1.0 : 0.0,
                     "on the Pareto front: no other point has a higher frame rate at no more "
                     "cost, or a lower cost at no less frame rate",
                     "flag"});
  return lines;
}

nlohmann::json sweep_points_json(const SweepResult& sweep) {
  nlohmann::json a = nlohmann::json::array();
  for (const SweepPoint& p : sweep.points)
    a.push_back(
        {{"index", p.index}, {"settings", p.settings}, {"cycle", p.cycle}, {"cost", p.cost}});
  return a;
}

std::vector<SweepPoint> sweep_points_from_json(const nlohmann::json& j) {
  std::vector<SweepPoint> points;
  for (const nlohmann::json& e : j) {
    SweepPoint p;
    p.index = e.at("index").get<std::size_t>();
    p.settings = e.at("settings").get<std::vector<std::string>>();
    p.cycle = e.at("cycle");
    p.cost = e.at("cost");
    points.push_back(std::move(p));
  }
  return points;
}

namespace {

// The point's value of each axis, in axis order ("threads=4" -> "4").
std::vector<std::string> point_values(const SweepPoint& p) {
  std::vector<std::string> v;
  for (const std::string& kv : p.settings) {
    v.push_back(kv.substr(kv.find('=') + 1));
  }
  return v;
}

// A column of the sweep's table and CSV: a statistic of the point's frame report (by its name in
// cycle_stats' declarations) over a divisor, the point's speed-up over the first (no stat), one of
// the point's cost statistics (kCostStats) or, with --pareto, whether it is on the front.
enum class ColumnSource { kCycle, kSpeedup, kCost, kPareto };
struct SweepColumn {
  std::string name;    // CSV header
  std::string head;    // table header
  const char* format;  // printf format of the table cell
  ColumnSource source;
  const char* stat;
  double divisor;
};

struct CycleColumn {
  const char* name;
  const char* head;
  const char* format;
  const char* stat;  // nullptr: the speed-up
  double divisor;
};
constexpr CycleColumn kCycleColumns[] = {
    {"cycles", "cycles", "%10.0f", "cycles", 1.0},
    {"fps", "fps", "%8.1f", "fps", 1.0},
    {"mrays_per_s", "Mrays/s", "%8.2f", "rays_per_s", 1e6},
    {"speedup", "speed-up", "%8.2f", nullptr, 1.0},
    {"usage_traversal", "trav%", "%6.0f", "usage.traversal", 1.0},
    {"usage_list", "list%", "%6.0f", "usage.list", 1.0},
    {"usage_transformation", "xfrm%", "%6.0f", "usage.transformation", 1.0},
    {"usage_intersection", "int%", "%6.0f", "usage.intersection", 1.0},
    {"cache_hit_traversal", "hit-trav%", "%10.1f", "cache_hit.traversal", 1.0},
    {"cache_hit_list", "hit-list%", "%10.1f", "cache_hit.list", 1.0},
    {"cache_hit_transformation", "hit-xfrm%", "%10.1f", "cache_hit.transformation", 1.0},
    {"bandwidth_mb_s_total", "MB/s", "%7.0f", "bandwidth_mb_s.total", 1.0},
    {"cycles_per_packet", "cyc/pkt", "%8.1f", "cycles_per_packet", 1.0},
    {"simd_efficiency", "SIMD", "%6.2f", "simd_efficiency", 1.0},
};

std::vector<SweepColumn> sweep_columns(const SweepResult& sweep) {
  std::vector<SweepColumn> cols;
  for (const CycleColumn& c : kCycleColumns)
    cols.push_back({c.name, c.head, c.format,
                    c.stat == nullptr ? ColumnSource::kSpeedup : ColumnSource::kCycle, c.stat,
                    c.divisor});
  for (const CostStatDecl& d : kCostStats)
    cols.push_back({d.name, d.head, d.format, ColumnSource::kCost, d.name, 1.0});
  if (!sweep.pareto_cost.empty())
    cols.push_back(
        {"pareto_" + sweep.pareto_cost, "front", "%5.0f", ColumnSource::kPareto, nullptr, 1.0});
  return cols;
}

double column_value(const SweepColumn& c, const SweepPoint& p) {
  switch (c.source) {
    case ColumnSource::kSpeedup:
      return p.speedup;
    case ColumnSource::kPareto:
      return p.pareto ? 1.0 : 0.0;
    case ColumnSource::kCost:
      return json_at(p.cost, c.stat).get<double>();
    case ColumnSource::kCycle:
      break;
  }
  return json_at(p.cycle, c.stat).get<double>() / c.divisor;
}

// A table cell: the column's format, the front's members as '*'.
std::string table_cell(const SweepColumn& c, const SweepPoint& p) {
  char buf[64];
  if (c.source == ColumnSource::kPareto) {
    char probe[64];
    const int width = std::snprintf(probe, sizeof probe, c.format, 0.0);
    std::snprintf(buf, sizeof buf, "%*s", width, p.pareto ? "*" : "");
  } else {
    std::snprintf(buf, sizeof buf, c.format, column_value(c, p));
  }
  return buf;
}

}  // namespace

std::string sweep_table(const SweepResult& sweep) {
  const std::vector<SweepColumn> columns = sweep_columns(sweep);
  std::string s;
  char buf[64];
  for (const SweepAxis& a : sweep.axes) {
    std::snprintf(buf, sizeof buf, "%*s ", static_cast<int>(std::max<std::size_t>(a.key.size(), 6)),
                  a.key.c_str());
    s += buf;
  }
  for (const SweepColumn& c : columns) {
    char probe[64];
    const int width = std::snprintf(probe, sizeof probe, c.format, 0.0);
    std::snprintf(buf, sizeof buf, " %*s", width, c.head.c_str());
    s += buf;
  }
  s += "\n";
  for (const SweepPoint& p : sweep.points) {
    const std::vector<std::string> v = point_values(p);
    for (std::size_t a = 0; a < v.size(); ++a) {
      const int width = static_cast<int>(std::max<std::size_t>(sweep.axes[a].key.size(), 6));
      std::snprintf(buf, sizeof buf, "%*s ", width, v[a].c_str());
      s += buf;
    }
    for (const SweepColumn& c : columns)
      s += ' ' + table_cell(c, p);
    s += "\n";
  }
  return s;
}

std::string sweep_csv(const SweepResult& sweep) {
  const std::vector<SweepColumn> columns = sweep_columns(sweep);
  const bool shard = sweep.shards > 1;
  std::string s = shard ? "point,points," : "";
  for (const SweepAxis& a : sweep.axes) {
    s += a.key + ",";
  }
  for (const SweepColumn& c : columns) {
    s += c.name + (&c == &columns.back() ? "\n" : ",");
  }
  char buf[64];
  for (const SweepPoint& p : sweep.points) {
    if (shard) s += std::to_string(p.index) + "," + std::to_string(sweep.total_points) + ",";
    for (const std::string& v : point_values(p)) {
      s += v + ",";
    }
    for (const SweepColumn& c : columns) {
      std::snprintf(buf, sizeof buf, "%.17g", column_value(c, p));
      s += std::string(buf) + (&c == &columns.back() ? "\n" : ",");
    }
  }
  return s;
}

std::string sweep_pareto_text(const SweepResult& sweep) {
  if (sweep.pareto_cost.empty()) return "";
  std::vector<const SweepPoint*> front;
  for (const SweepPoint& p : sweep.points)
    if (p.pareto) front.push_back(&p);
  // Cheapest first; at equal cost (a tie in both) in sweep order.
  std::ranges::stable_sort(front, {}, [&](const SweepPoint* p) {
    return json_at(p->cost, sweep.pareto_cost).get<double>();
  });
  const CostStatDecl* decl = nullptr;
  for (const CostStatDecl& d : kCostStats)
    if (sweep.pareto_cost == d.name) decl = &d;
  std::string s = "Pareto front (frame rate against " + sweep.pareto_cost + ", " + decl->unit +
                  "): " + std::to_string(front.size()) + " of " +
                  std::to_string(sweep.points.size()) +
                  " points; no other point has a higher frame rate at no more cost, or a lower "
                  "cost at no less frame rate\n";
  char buf[96];
  for (const SweepPoint* p : front) {
    std::snprintf(buf, sizeof buf, "  %12.2f %s  %10.1f fps  ",
                  json_at(p->cost, sweep.pareto_cost).get<double>(), sweep.pareto_cost.c_str(),
                  json_at(p->cycle, "fps").get<double>());
    s += buf + join_words(p->settings) + "\n";
  }
  return s;
}

nlohmann::json sweep_json(const SweepResult& sweep, const SweepOptions& opts) {
  nlohmann::json j;
  j["scene"] = opts.scene;
  j["resolution"] = opts.res;
  j["preset"] = opts.preset;
  j["set"] = opts.set;
  nlohmann::json vary = nlohmann::json::object();
  for (const SweepAxis& a : sweep.axes) {
    vary[a.key] = a.values;
  }
  j["vary"] = vary;
  j["model"] = opts.model;
  j["functional_model"] = sweep.functional_model;
  j["bit_identical_to_functional_model"] = true;  // run_sweep_points throws otherwise
  j["functional_rays"] = sweep.functional_rays;
  if (sweep.shards > 1) {
    j["shard"] = std::to_string(sweep.shard + 1) + "/" + std::to_string(sweep.shards);
    j["total_points"] = sweep.total_points;
  }
  for (const CostStatDecl& d : kCostStats)
    j["cost_stats"][d.name] = {{"unit", d.unit}, {"desc", d.desc}};
  nlohmann::json points = nlohmann::json::array();
  nlohmann::json front = nlohmann::json::array();
  for (const SweepPoint& p : sweep.points) {
    nlohmann::json e;
    if (sweep.shards > 1) e["index"] = p.index;
    const std::vector<std::string> v = point_values(p);
    for (std::size_t a = 0; a < v.size(); ++a) {
      e["values"][sweep.axes[a].key] = v[a];
    }
    e["speedup"] = p.speedup;
    e["cost"] = p.cost;
    if (!sweep.pareto_cost.empty()) e["pareto"] = p.pareto;
    if (p.pareto) front.push_back(p.index);
    e["report"] = p.cycle;
    points.push_back(std::move(e));
  }
  j["points"] = points;
  if (!sweep.pareto_cost.empty())
    j["pareto"] = {{"cost", sweep.pareto_cost}, {"performance", "fps"}, {"points", front}};
  return j;
}

nlohmann::json sweep_rank_message(const std::string& error, const SweepResult& sweep) {
  nlohmann::json mine;
  if (!error.empty()) {
    mine["error"] = error;
  } else {
    mine["points"] = sweep_points_json(sweep);
  }
  return mine;
}

// --out-dir for a sweep: the CSV, the report without host timing (host.json has it), each point's
// resolved configuration (config.json), each point's statistics as one block (stats.txt) and the
// command line.
void write_sweep_folder(const SweepOptions& opts, const SweepResult& sweep,
                        const RenderSettings& rs, int jobs, int ranks) {
  nlohmann::json report = sweep_json(sweep, opts);
  nlohmann::json host;
  host["jobs"] = jobs;
  host["mpi_ranks"] = ranks;
  nlohmann::json config;
  config["scene"] = opts.scene;
  config["model"] = opts.model;
  config["resolution"] = opts.res;
  config["time"] = rs.time;
  config["shadows"] = rs.shadows;
  config["depth"] = rs.depth;
  config["bank_mb"] = rs.bank_mb;
  config["preset"] = opts.preset;
  config["set"] = opts.set;
  for (const SweepAxis& a : sweep.axes)
    config["vary"].push_back({{"key", a.key}, {"values", a.values}});
  if (sweep.shards > 1) config["shard"] = report["shard"];
  std::vector<std::pair<std::string, std::vector<StatLine>>> blocks;
  for (std::size_t i = 0; i < sweep.points.size(); ++i) {
    nlohmann::json& point = report["points"][i];
    host["points"].push_back(
        {{"values", point["values"]}, {"host", take_cycle_host(point["report"])}});
    config["points"].push_back(
        {{"values", point["values"]}, {"configuration", point["report"]["configuration"]}});
    blocks.push_back({"point " + std::to_string(sweep.points[i].index + 1) + " of " +
                          std::to_string(sweep.total_points) + ": " +
                          join_words(sweep.points[i].settings),
                      sweep_point_stat_lines(sweep.points[i], !sweep.pareto_cost.empty())});
  }
  write_run_folder({opts.out_dir,
                    std::move(report),
                    std::move(config),
                    std::move(host),
                    stats_text_blocks(blocks),
                    opts.argv,
                    {{"sweep.csv", sweep_csv(sweep)}}});
}

// ---- precision ------------------------------------------------------------------------------

namespace {

// One format's row of the precision report.
nlohmann::json precision_row_json(const PrecisionRow& r) {
  nlohmann::json row;
  row["mantissa"] = r.mantissa;
  row["format"] = ff::format_name(ff::Format{7, r.mantissa});
  row["same_triangle_pct"] = r.same_triangle_pct;
  row["psnr_db"] = std::isfinite(r.psnr_db) ? nlohmann::json(r.psnr_db) : nlohmann::json();
  row["t_rel_err_median"] = r.t_rel_err_median ? nlohmann::json(*r.t_rel_err_median) : nullptr;
  row["t_rel_err_max"] = r.t_rel_err_max ? nlohmann::json(*r.t_rel_err_max) : nullptr;
  row["mismatches"] = {{"hit_vs_miss", r.mismatches.hit_vs_miss},
                       {"edge_tie", r.mismatches.edge_tie},
                       {"grazing", r.mismatches.grazing},
                       {"other", r.mismatches.other}};
  return row;
}

// One format's statistics (stats.txt), named eM.NAME.
void precision_row_stats(const PrecisionRow& r, std::vector<StatLine>& stats) {
  const std::string m = "e7m" + std::to_string(r.mantissa) + ".";
  const std::string of = " of Float<7," + std::to_string(r.mantissa) + "> against float";
  stats.push_back({m + "same_triangle_pct", r.same_triangle_pct,
                   "% of pixels hitting the same triangle" + of, "%"});
  // Identical images have no finite PSNR; stats.txt carries the number, so infinity is left
  // out rather than printed as a value no parser agrees on.
  if (std::isfinite(r.psnr_db))
    stats.push_back({m + "psnr_db", r.psnr_db, "image PSNR" + of, "dB"});
  if (r.t_rel_err_median)
    stats.push_back({m + "t_rel_err_median", *r.t_rel_err_median,
                     "median relative hit-distance error" + of, "ratio"});
  if (r.t_rel_err_max)
    stats.push_back({m + "t_rel_err_max", *r.t_rel_err_max,
                     "largest relative hit-distance error" + of, "ratio"});
  stats.push_back({m + "mismatches.hit_vs_miss", static_cast<double>(r.mismatches.hit_vs_miss),
                   "pixels where one hits and the other misses", "pixels"});
  stats.push_back({m + "mismatches.edge_tie", static_cast<double>(r.mismatches.edge_tie),
                   "different triangles, hit on a shared edge", "pixels"});
  stats.push_back({m + "mismatches.grazing", static_cast<double>(r.mismatches.grazing),
                   "different triangles, grazing ray", "pixels"});
  stats.push_back({m + "mismatches.other", static_cast<double>(r.mismatches.other),
                   "different triangles, other cause", "pixels"});
}

}  // namespace

void write_precision_report(const std::string& json, const std::string& out_dir,
                            const std::string& scene, const RenderSettings& settings, int lo,
                            int hi, const std::vector<PrecisionRow>& rows,
                            const std::vector<std::string>& argv) {
  const bool in_dir = !out_dir.empty();
  nlohmann::json j;
  j["scene"] = scene;
  j["resolution"] = {{"width", settings.res.width}, {"height", settings.res.height}};
  j["reference"] = "float";
  nlohmann::json host;  // --out-dir: the frames' wall-clock seconds, apart from the results
  std::vector<StatLine> stats;
  for (const PrecisionRow& r : rows) {
    nlohmann::json row = precision_row_json(r);
    if (in_dir) {
      host["rows"].push_back({{"mantissa", r.mantissa}, {"seconds", r.seconds}});
    } else {
      row["seconds"] = r.seconds;
    }
    j["rows"].push_back(row);
    precision_row_stats(r, stats);
  }
  if (!in_dir) {
    write_text_file(json, j.dump(2) + "\n");
    return;
  }
  j["outputs"] = {{"plot", "precision.png"}, {"report", "report.json"},  {"stats", "stats.txt"},
                  {"config", "config.json"}, {"command", "command.txt"}, {"host", "host.json"}};
  // The study's whole configuration: the frame, the formats, and the tree keys every format's
  // image is built with (at their defaults: the study has no --set).
  nlohmann::json config;
  config["scene"] = scene;
  config["resolution"] = j["resolution"];
  config["bank_mb"] = settings.bank_mb;
  config["mantissa"] = {{"from", lo}, {"to", hi}};
  config["exponent_bits"] = 7;
  config["reference"] = "float";
  config["shadows"] = settings.shadows;
  config["depth"] = settings.depth;
  const host::ImageParams trees;
  config["trees"] = parameters_json(nullptr, &trees);
  write_run_folder({out_dir, j, std::move(config), std::move(host), stats_text(stats), argv, {}});
}

// ---- the paper's tables ---------------------------------------------------------------------

namespace {

// A figure's model value over the paper's (0 where the paper has none).
double paper_ratio(const PaperFigure& f) {
  return f.paper == 0.0 ? 0.0 : f.model / f.paper;
}

double stat(const nlohmann::json& cycle, const char* name) {
  return json_at(cycle, name).get<double>();
}

// The paper's cycles per 4-ray packet and Mrays/s at its fps and resolution (90 MHz).
void add_rate_figures(std::vector<PaperFigure>& v, const nlohmann::json& cycle, double fps,
                      int width, int height) {
  const double rays = fps * width * height;
  v.push_back({"cycles_per_packet", stat(cycle, "cycles_per_packet"),
               rays > 0.0 ? 90e6 / (rays / 4.0) : 0.0});
  v.push_back({"mrays_per_s", stat(cycle, "rays_per_s") / 1e6, rays / 1e6});
}

std::vector<PaperFigure> table4_figures(const nlohmann::json& cycle, double fps,
                                        const std::string& paper) {
  const Table4Row none{"", 0, {0, 0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  const auto row =
      std::ranges::find_if(paper_table4(), [&](const Table4Row& r) { return paper == r.scene; });
  const Table4Row& p = row != paper_table4().end() ? *row : none;
  const nlohmann::json& fb = json_at(cycle, "bandwidth_mb_s.frame_buffer");
  std::vector<PaperFigure> v = {
      {"fps", fps, p.fps},
      {"usage_traversal", stat(cycle, "usage.traversal"), p.usage[0]},
      {"usage_list", stat(cycle, "usage.list"), p.usage[1]},
      {"usage_transformation", stat(cycle, "usage.transformation"), p.usage[2]},
      {"usage_intersection", stat(cycle, "usage.intersection"), p.usage[3]},
      {"hit_traversal", stat(cycle, "cache_hit.traversal"), p.hit[0]},
      {"hit_list", stat(cycle, "cache_hit.list"), p.hit[1]},
      {"hit_transformation", stat(cycle, "cache_hit.transformation"), p.hit[2]},
      {"mb_s_dynrtc", stat(cycle, "bandwidth_mb_s.dynrtc"), p.bw[0]},
      // The paper's shading bandwidth includes the frame buffer (docs/fidelity.md).
      {"mb_s_shading",
       stat(cycle, "bandwidth_mb_s.shading") + (fb.is_number() ? fb.get<double>() : 0.0), p.bw[1]},
      {"mb_s_total", stat(cycle, "bandwidth_mb_s.total"), p.bw[2]},
  };
  add_rate_figures(v, cycle, p.fps, 1024, 768);
  // Shading and frame-buffer bytes per pixel: the paper's from its shading MB/s over its frame
  // rate at 1024x768 (Scene6: 19.0).
  const double paper_bpp = p.fps > 0 ? p.bw[1] * 1048576.0 / (p.fps * 1024.0 * 768.0) : 0.0;
  const nlohmann::json& bpp = json_at(cycle, "rgs.shading_bytes_per_pixel");
  v.push_back({"shading_bytes_per_pixel", bpp.is_number() ? bpp.get<double>() : 0.0, paper_bpp});
  return v;
}

std::vector<PaperFigure> table3_figures(const nlohmann::json& cycle, double fps,
                                        const std::string& paper) {
  const Table3Row* r = paper_table3_row(paper);
  const double paper_fps = r ? r->saarcor_fps : 0.0;
  std::vector<PaperFigure> v = {{"fps", fps, paper_fps}};
  add_rate_figures(v, cycle, paper_fps, 512, 384);
  return v;
}

}  // namespace

std::vector<PaperFigure> paper_figures(int table, const std::string& paper,
                                       const nlohmann::json& cycle, int width, int height) {
  // A frame at 1/scale of the table's resolution: its fps as the paper's frame would have it
  // (cycles per packet and rays/s do not depend on the resolution but through the image's
  // content).
  const int pw = table == 3 ? 512 : 1024, ph = table == 3 ? 384 : 768;
  const double fps = stat(cycle, "fps") * (width * height) / (pw * ph);
  return table == 3 ? table3_figures(cycle, fps, paper) : table4_figures(cycle, fps, paper);
}

nlohmann::json paper_entry_json(int table, const std::string& paper, const std::string& scene,
                                bool reference, int width, int height,
                                const std::vector<std::string>& settings,
                                const nlohmann::json& cycle) {
  nlohmann::json e;
  e["table"] = table;
  e["paper_scene"] = paper;
  e["scene"] = scene;
  e["kind"] = reference ? "reference" : "stand-in";
  e["resolution"] = std::to_string(width) + "x" + std::to_string(height);
  e["paper_resolution"] = table == 3 ? "512x384" : "1024x768";
  nlohmann::json fj = nlohmann::json::object();
  for (const PaperFigure& g : paper_figures(table, paper, cycle, width, height))
    fj[g.key] = {{"model", g.model}, {"paper", g.paper}, {"ratio", paper_ratio(g)}};
  e["figures"] = fj;
  e["configuration"] = settings;
  e["report"] = cycle;
  return e;
}

nlohmann::json paper_tables_json(int scale, const std::vector<std::string>& set,
                                 std::vector<nlohmann::json>& per_scene) {
  nlohmann::json entries = nlohmann::json::array();
  for (nlohmann::json& scene_entries : per_scene)
    for (nlohmann::json& e : scene_entries)
      entries.push_back(std::move(e));
  nlohmann::json j;
  j["scale"] = scale;
  j["configuration"] = set;  // each entry lists its own, the paper's filter included
  j["entries"] = entries;
  return j;
}

nlohmann::json thread_curve_json(const std::vector<int>& counts,
                                 const std::vector<nlohmann::json>& reports,
                                 const std::string& resolution) {
  nlohmann::json rows = nlohmann::json::array();
  double first = 0.0, last = 0.0;
  for (std::size_t i = 0; i < counts.size(); ++i) {
    const int t = counts[i];
    const nlohmann::json& report = reports[i];
    const double fps = report["fps"].get<double>();
    if (t == 1) first = fps;
    // The paper: nearly linear up to 32 threads, about +10 % from 32 to 64.
    const double paper_step = t == 1 ? 1.0 : t <= 32 ? 2.0 : 1.10;
    const double step = t == 1 ? 1.0 : fps / last;
    rows.push_back({{"threads", t},
                    {"fps", fps},
                    {"speedup", fps / first},
                    {"step", step},
                    {"paper_step", paper_step},
                    {"ratio", step / paper_step},
                    {"usage", report["usage"]}});
    last = fps;
  }
  return {{"scene", "builtin:room"}, {"resolution", resolution}, {"rows", rows}};
}

// ---- scene and compare ------------------------------------------------------------------------

namespace {

nlohmann::json tree_json(const host::KdTreeStats& s) {
  return {{"nodes", s.nodes},
          {"leaves", s.leaves},
          {"empty_leaves", s.empty_leaves},
          {"empty_chain_links", s.empty_chain_links},
          {"mergeable_chain_links", s.mergeable_chain_links},
          {"depth", s.depth},
          {"items_per_leaf", s.items_per_leaf},
          {"sah_cost", s.sah_cost},
          {"expected_traversal_steps", s.expected_traversal_steps},
          {"expected_leaf_visits", s.expected_leaf_visits},
          {"expected_item_tests", s.expected_item_tests},
          {"build_seconds", s.build_seconds}};
}

// A bottom tree's entry adds the busiest-unit objective's record (the top level keeps the plain
// SAH: host/tree_objective.h).
nlohmann::json bottom_tree_json(const host::KdTreeStats& s) {
  nlohmann::json j = tree_json(s);
  j["traversal_cost"] = s.chosen_traversal_cost;
  j["expected_unit_cycles"] = {{"traversal", s.expected_traversal_cycles},
                               {"list", s.expected_list_cycles},
                               {"transformation", s.expected_transformation_cycles},
                               {"intersection", s.expected_intersection_cycles}};
  return j;
}

// Every bottom tree (per object) and their sums.
nlohmann::json bottom_json(const SceneTrees& t, const host::Scene& scene) {
  host::KdTreeStats sum;
  std::uint64_t triangles = 0;
  double leaf_items = 0.0;
  std::uint64_t nonempty = 0;
  nlohmann::json per_object = nlohmann::json::array();
  for (const auto& [o, s] : t.bottom) {
    sum.nodes += s.nodes;
    sum.leaves += s.leaves;
    sum.empty_leaves += s.empty_leaves;
    sum.empty_chain_links += s.empty_chain_links;
    sum.mergeable_chain_links += s.mergeable_chain_links;
    sum.depth = std::max(sum.depth, s.depth);
    sum.build_seconds += s.build_seconds;
    leaf_items += s.items_per_leaf * (s.leaves - s.empty_leaves);
    nonempty += s.leaves - s.empty_leaves;
    nlohmann::json j = bottom_tree_json(s);
    j["object"] = o;
    j["name"] = scene.objects[o].name;
    j["triangles"] = scene.objects[o].triangles.size();
    j["nodes_per_triangle"] =
        static_cast<double>(s.nodes) / std::max<double>(1.0, scene.objects[o].triangles.size());
    triangles += scene.objects[o].triangles.size();
    per_object.push_back(j);
  }
  return {{"trees", t.bottom.size()},
          {"nodes", sum.nodes},
          {"leaves", sum.leaves},
          {"empty_leaves", sum.empty_leaves},
          {"empty_chain_links", sum.empty_chain_links},
          {"mergeable_chain_links", sum.mergeable_chain_links},
          {"max_depth", sum.depth},
          {"nodes_per_triangle",
           static_cast<double>(sum.nodes) / std::max<double>(1.0, static_cast<double>(triangles))},
          {"items_per_leaf", nonempty ? leaf_items / static_cast<double>(nonempty) : 0.0},
          {"build_seconds", sum.build_seconds},
          {"objects", per_object}};
}

// What the scene holds: counts, cameras, animation, the loader's warnings.
nlohmann::json scene_counts_json(const host::Scene& scene) {
  nlohmann::json j;
  j["time"] = scene.time;
  j["triangles"] = scene.instanced_triangles();
  j["unique_triangles"] = scene.unique_triangles();
  j["objects"] = scene.objects.size();
  j["instances"] = scene.instances.size();
  j["dynamic_instances"] = dynamic_instances(scene);
  j["materials"] = scene.materials.size();
  j["textures"] = scene.textures.size();
  j["lights"] = scene.lights.size();
  j["light_defaulted"] = scene.light_defaulted;
  j["cameras"] = scene.cameras.size();
  j["camera_names"] = nlohmann::json::array();
  for (const host::Camera& c : scene.cameras)
    j["camera_names"].push_back(c.name);
  j["animation_seconds"] = scene.animation_seconds;
  j["dropped_triangles"] = scene.dropped_triangles();
  j["dropped_triangles_instanced"] = scene.instanced_dropped_triangles();
  j["skipped_primitives"] = scene.skipped_primitives;
  j["warnings"] = scene.warnings;
  return j;
}

}  // namespace

nlohmann::json scene_report_json(const SceneOptions& options, const host::Scene& scene,
                                 double load_seconds, const SceneImage& img) {
  nlohmann::json j = scene_counts_json(scene);
  j["scene"] = options.scene;
  j["load_seconds"] = load_seconds;
  j["kdtree"] = {{"top", tree_json(img.trees.top)}, {"bottom", bottom_json(img.trees, scene)}};
  if (img.built) {
    j["bytes_per_bank"] = img.built->stats.bytes_per_bank;
    j["bank_bytes"] = static_cast<std::uint64_t>(img.params.bank_words) * 4u;
    j["image_seconds"] = img.seconds;
    j["image_error"] = nullptr;
  } else {
    j["bytes_per_bank"] = nullptr;
    j["image_error"] = img.error;
  }
  if (!options.export_path.empty()) j["exported"] = options.export_path;
  return j;
}

nlohmann::json compare_report_json(const CompareResult& r) {
  // JSON has no infinity: an infinite or absent figure is null (docs/compare.md).
  auto finite = [](const std::optional<double>& v) -> nlohmann::json {
    if (!v || !std::isfinite(*v)) return nullptr;
    return *v;
  };
  nlohmann::json j;
  j["kind"] = r.hit_records ? "hit_records" : "images";
  j["width"] = r.width;
  j["height"] = r.height;
  j["pixels"] = r.pixels;
  j["bit_identical"] = r.bit_identical;
  if (r.hit_records) {
    j["same_triangle_pct"] = r.same_triangle_pct;
    j["t_compared_pixels"] = r.t_compared;
    j["mismatches"] = {{"hit_vs_miss", r.mismatches.hit_vs_miss},
                       {"hit_vs_miss_near_edge", r.mismatches.hit_vs_miss_near_edge},
                       {"edge_tie", r.mismatches.edge_tie},
                       {"grazing", r.mismatches.grazing},
                       {"other", r.mismatches.other},
                       {"total", r.mismatches.total()}};
  } else {
    j["same_triangle_pct"] = nullptr;
    j["mismatches"] = {{"differing_pixels", r.differing_pixels}};
  }
  j["t_rel_err_max"] = finite(r.t_rel_err_max);
  j["t_rel_err_median"] = finite(r.t_rel_err_median);
  j["psnr_db"] = finite(r.psnr_db);
  j["max_channel_diff"] = finite(r.max_channel_diff);
  if (!r.hit_records) j["max_channel_diff_unit"] = r.eight_bit ? "8-bit levels" : "float";
  return j;
}

// ---- the run folder ----------------------------------------------------------------------------

std::string command_line_text(const std::vector<std::string>& argv) {
  std::string s;
  for (const std::string& w : argv) {
    if (!s.empty()) s += ' ';
    bool safe = !w.empty();
    for (char c : w)
      safe = safe && shell_safe(c);
    if (safe) {
      s += w;
      continue;
    }
    s += '\'';
    for (char c : w)
      s += c == '\'' ? std::string("'\\''") : std::string(1, c);
    s += '\'';
  }
  return s + "\n";
}

void check_out_dir(const std::string& dir) {
  if (dir.empty()) throw std::runtime_error("bad --out-dir '': expected a folder name");
  std::error_code ec;
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec))
    throw std::runtime_error("bad --out-dir '" + dir + "': a file of that name exists");
}

std::string run_file(const std::string& dir, const std::string& name) {
  return (std::filesystem::path(dir) / name).string();
}

nlohmann::json take_cycle_host(nlohmann::json& cycle) {
  nlohmann::json host = cycle.contains("host") ? cycle["host"] : nlohmann::json::object();
  cycle.erase("host");
  return host;
}

void write_run_folder(const RunFolder& f) {
  for (const auto& [name, text] : f.tables)
    write_text_file(run_file(f.dir, name), text);
  write_text_file(run_file(f.dir, "report.json"), f.report.dump(2) + "\n");
  write_text_file(run_file(f.dir, "stats.txt"), f.stats);
  write_text_file(run_file(f.dir, "config.json"), f.config.dump(2) + "\n");
  write_text_file(run_file(f.dir, "command.txt"), command_line_text(f.argv));
  write_text_file(run_file(f.dir, "host.json"), f.host.dump(2) + "\n");
}

void list_run_folder(const RunFolder& f,
                     std::vector<std::pair<std::string, std::string>>& outputs) {
  for (const char* key : {"report", "stats", "config", "command", "host"}) {
    const std::string_view k = key;
    const char* file = k == "report"    ? "report.json"
                       : k == "stats"   ? "stats.txt"
                       : k == "config"  ? "config.json"
                       : k == "command" ? "command.txt"
                                        : "host.json";
    outputs.push_back({key, run_file(f.dir, file)});
  }
}

// ---- render ------------------------------------------------------------------------------------

std::string describe_format(ff::Format f) {
  return "Float<" + std::to_string(f.exp_bits) + "," + std::to_string(f.man_bits) + "> (" +
         ff::format_name(f) + ")";
}

nlohmann::json parameters_json(const units::CycleParams* cycle, const host::ImageParams* trees) {
  nlohmann::json j = nlohmann::json::object();
  const auto add = [&j](const std::vector<hw::ParamInfo>& keys) {
    for (const hw::ParamInfo& k : keys)
      j[k.name] = {{"value", k.value}, {"unit", k.unit}, {"help", k.help}};
  };
  if (cycle != nullptr) {
    add(units::describe(*cycle));
    j["depth.traversal"] = cycle->traversal_depth();
    j["depth.list"] = cycle->list_depth();
    j["depth.transformation"] = cycle->transformation_depth();
    j["depth.intersection"] = cycle->intersection_depth();
  }
  if (trees != nullptr) add(host::describe_tree_settings(*trees));
  return j;
}

namespace {

// The frame, the image and the scene as render's report configures them.
nlohmann::json render_configuration(const PreparedScene& prep, const RenderSettings& settings) {
  const auto& st = prep.built.stats;
  return {{"time", settings.time},
          {"shadows", settings.shadows},
          {"depth", settings.depth},
          {"image_format", describe_format(prep.built.params.format)},
          {"bank_words", prep.built.params.bank_words},
          {"bank_mb", settings.bank_mb},
          {"instances", prep.scene.instances.size()},
          {"objects", prep.scene.objects.size()},
          {"triangles_unique", prep.scene.unique_triangles()},
          {"triangles_instanced", prep.scene.instanced_triangles()},
          {"triangles_dropped", st.dropped_triangles},
          {"scene_bytes", st.scene_bytes()},
          {"light_defaulted", prep.scene.light_defaulted},
          {"load_seconds", prep.load_seconds},
          {"build_seconds", prep.build_seconds}};
}

}  // namespace

nlohmann::json render_report_json(const std::string& scene, const std::string& model,
                                  const FrameResult& frame, const PreparedScene& prep,
                                  const RenderSettings& settings) {
  nlohmann::json j;
  j["scene"] = scene;
  j["model"] = model;
  j["resolution"] = {{"width", settings.res.width}, {"height", settings.res.height}};
  j["seconds"] = frame.seconds;
  j["rays"] = frame.rays;
  j["rays_per_second"] = frame.seconds > 0 ? static_cast<double>(frame.rays) / frame.seconds : 0;
  j["counters"] = frame.counters;
  j["configuration"] = render_configuration(prep, settings);
  if (!frame.cycle.is_null()) {  // the cycle model's figures at the top, its parameters inside
    nlohmann::json c = frame.cycle;
    j["configuration"]["cycle"] = c["configuration"];
    c.erase("configuration");
    j.update(c);
  } else {  // the other models read the same trees: their keys are configuration too
    j["configuration"]["trees"] = parameters_json(nullptr, &prep.built.params);
  }
  return j;
}

void write_render_report(const std::string& path, nlohmann::json report,
                         std::vector<std::pair<std::string, std::string>>& outputs) {
  nlohmann::json out;
  for (const auto& [k, v] : outputs)
    out[k] = v;
  report["outputs"] = out;
  write_text_file(path, report.dump(2) + "\n");
  outputs.push_back({"report", path});
}

void write_render_folder(const std::string& dir, nlohmann::json report, const FrameResult& frame,
                         const std::vector<std::string>& argv,
                         std::vector<std::pair<std::string, std::string>>& outputs) {
  RunFolder f;
  f.dir = dir;
  f.argv = argv;
  f.host["seconds"] = report["seconds"];
  f.host["rays_per_second"] = report["rays_per_second"];
  f.host["load_seconds"] = report["configuration"]["load_seconds"];
  f.host["build_seconds"] = report["configuration"]["build_seconds"];
  report.erase("seconds");
  report.erase("rays_per_second");
  report["configuration"].erase("load_seconds");
  report["configuration"].erase("build_seconds");
  if (report.contains("host")) f.host["cycle_model"] = take_cycle_host(report);
  list_run_folder(f, outputs);
  nlohmann::json names;
  for (const auto& [k, v] : outputs)
    names[k] = std::filesystem::path(v).filename().string();
  report["outputs"] = names;
  f.config = report["configuration"];
  f.config["scene"] = report["scene"];
  f.config["model"] = report["model"];
  f.config["resolution"] = report["resolution"];
  std::vector<StatLine> stats;
  if (!frame.cycle.is_null()) {
    stats = cycle_stat_lines(frame.cycle);
  } else {
    stats.push_back({"rays", static_cast<double>(frame.rays), "rays traced, all kinds", "rays"});
    for (StatLine& l : stat_lines(frame.counter_stats))
      stats.push_back(std::move(l));
  }
  f.stats = stats_text(stats);
  f.report = std::move(report);
  write_run_folder(f);
}

// ---- cost ------------------------------------------------------------------------------------

namespace {

nlohmann::json fp_json(const units::FpUnits& f, std::int64_t bits, const units::AreaEstimate& a) {
  return {{"add", f.add},
          {"mul", f.mul},
          {"div", f.div},
          {"cmp", f.cmp},
          {"sqrt", f.sqrt},
          {"memory_bits", bits},
          {"memory_kb", static_cast<double>(bits) / 8192.0},
          {"luts", a.luts},
          {"mult18x18", a.mult18x18},
          {"block_rams", a.block_rams}};
}

nlohmann::json unit_json(const units::UnitCost& u) {
  nlohmann::json j = fp_json(u.fp, u.memory_bits(), u.area);
  j["name"] = u.name;
  j["memory"] = nlohmann::json::array();
  j["memory_by_kind"] = nlohmann::json::object();
  for (const auto& m : u.memory)
    j["memory_by_kind"][m.kind] = j["memory_by_kind"].value(m.kind, std::int64_t{0}) + m.bits();
  for (const auto& m : u.memory)
    j["memory"].push_back({{"what", m.what},
                           {"kind", m.kind},
                           {"bits_each", m.bits_each},
                           {"count", m.count},
                           {"ports", m.ports},
                           {"bits", m.bits()}});
  return j;
}

nlohmann::json table2_json(const units::ConfigurationCost& c) {
  nlohmann::json j;
  auto row = [&](const std::string& key, const units::FpUnits& f, double kb) {
    const auto& p = units::paper_table2_row(key);
    const double model[] = {double(f.add), double(f.mul), double(f.div), double(f.cmp), kb};
    const double paper[] = {double(p.add), double(p.mul), double(p.div), double(p.cmp),
                            p.memory_kb};
    const char* keys[] = {"add", "mul", "div", "cmp", "memory_kb"};
    for (int i = 0; i < 5; ++i)
      j[key][keys[i]] = {{"model", model[i]},
                         {"paper", paper[i]},
                         {"ratio", paper[i] == 0.0 ? 0.0 : model[i] / paper[i]}};
  };
  for (const units::UnitCost& u : c.units)
    row(u.key, u.fp, u.memory_kb());
  row("total", c.fp_per_pipeline, static_cast<double>(c.memory_bits_per_pipeline) / 8192.0);
  return j;
}

}  // namespace

nlohmann::json cost_report_json(const units::CostParams& params, bool table2) {
  const units::ConfigurationCost c = units::configuration_cost(params);
  nlohmann::json j;
  for (const units::UnitCost& u : c.units)
    j["units"][u.key] = unit_json(u);
  j["total"] = fp_json(c.fp_total, c.memory_bits_total, c.area_total);
  j["total"]["per_pipeline"] =
      fp_json(c.fp_per_pipeline, c.memory_bits_per_pipeline, c.area_per_pipeline);
  for (const units::OperatorArea& o : units::operator_areas())
    j["operator_area"][o.op] = {{"luts", o.luts}, {"mult18x18", o.mult18x18}, {"source", o.source}};
  j["pipelines"] = c.pipelines;
  j["flops"] = c.flops;
  j["lights"] = params.lights;
  for (const auto& i : units::describe(params.cycle))
    j["configuration"][i.name] = i.value;
  const units::Table1 t1 = units::table1(params);
  for (const auto& r : t1.ratios)
    j["table1"][r.key] = {{"without_traversal", r.without_traversal},
                          {"full", r.full},
                          {"paper_without_traversal", r.paper_without_traversal},
                          {"paper_full", r.paper_full}};
  for (const auto& d : t1.designs)
    j["table1"]["designs"][d.key] = {{"name", d.name},
                                     {"parts", d.parts},
                                     {"without_traversal", d.without_traversal.total()},
                                     {"full", d.full.total()}};
  if (table2) j["table2"] = table2_json(c);
  return j;
}

}  // namespace saarcor
