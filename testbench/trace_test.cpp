// The traces of docs/traces.md on real scenes: the cycle model's request trace agrees with the
// functional model's packet by packet (same requests, same order, same values) over scenes and
// configurations, in every program mode, and an altered value is caught; tracing moves no figure;
// the Kanata log obeys the format's grammar and times a cache-hit node step exactly; the command
// line writes both files, prints the pixel's requests with their cycles, and refuses misuse with
// one error line.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "testbench/chip.h"
#include "testbench/dynrtc_testing.h"
#include "testbench/render_cmd.h"
#include "testbench/testing.h"
#include "units/functional_model.h"
#include "units/request_trace.h"
#include "units/run_trace.h"

namespace saarcor {
namespace {

using test_support::error_of;
using units::TraceLine;

constexpr int kW = units::testing::kSanitized ? 16 : 32;
constexpr int kH = units::testing::kSanitized ? 12 : 24;

std::vector<TraceLine> parse_all(const std::string& text) {
  std::vector<TraceLine> out;
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, units::kTraceHeader);
  while (std::getline(in, line))
    out.push_back(units::parse_trace_line(line));
  return out;
}

// The comparison key (docs/traces.md): a request is (primary packet, position in the packet's
// sequence); the functional trace is in packet order, the cycle trace in issue order with the
// packets interleaved over threads. Returns "" when every packet has the same requests with the
// same values in the same order in both, else the first difference.
std::string compare_traces(const std::vector<TraceLine>& functional,
                           const std::vector<TraceLine>& cycle) {
  std::map<int, std::vector<const TraceLine*>> a, b;
  for (const TraceLine& l : functional)
    a[l.packet].push_back(&l);
  for (const TraceLine& l : cycle)
    b[l.packet].push_back(&l);
  if (a.size() != b.size())
    return std::to_string(a.size()) + " packets vs " + std::to_string(b.size());
  for (const auto& [packet, fa] : a) {
    const auto& fb = b[packet];
    for (std::size_t i = 0; i < fa.size() || i < fb.size(); ++i) {
      const std::string where =
          "packet " + std::to_string(packet) + " request " + std::to_string(i);
      if (i >= fa.size() || i >= fb.size()) return where + ": missing in one trace";
      if (fa[i]->seq != i || fb[i]->seq != i) return where + ": out of order";
      if (!units::same_request(*fa[i], *fb[i]))
        return where + ":\n  " + format_trace_line(*fa[i]) + "\n  " + format_trace_line(*fb[i]);
    }
  }
  return "";
}

struct Traced {
  std::string trace, konata;
  CycleFrame frame;
};

Traced run_traced_cycle(const memif::MemoryImage& image, const std::vector<std::string>& set,
                        const units::FunctionalParams& shading, units::ProgramMode mode,
                        bool konata = false) {
  units::CycleParams p = units::prototype_params();
  for (const std::string& kv : set)
    units::apply_cycle_setting(p, kv);
  CycleRunOptions o;
  o.shading = shading;
  o.programs = mode;
  std::ostringstream trace, log;
  o.trace.trace = &trace;
  if (konata) o.trace.konata = &log;
  Traced t;
  t.frame = run_cycle(image, p, o);
  t.trace = trace.str();
  t.konata = log.str();
  return t;
}

std::string functional_trace(const memif::MemoryImage& image, units::FunctionalParams fp,
                             const std::vector<std::string>& set) {
  units::CycleParams p = units::prototype_params();
  for (const std::string& kv : set)
    units::apply_cycle_setting(p, kv);
  std::ostringstream out;
  units::run_functional<ff::fp24>(image, units::functional_params(p, fp), {}, nullptr, &out);
  return out.str();
}

struct SceneCase {
  const char* spec;
  bool shadows_and_secondary;
};

// Three scenes (the room; the dynamic room's 16 instanced movers; the room with shadow,
// reflection and transparency rays) x three configurations x the program modes.
TEST(RequestTrace, CycleAndFunctionalTracesAgreePacketByPacket) {
  const SceneCase scenes[] = {
      {"builtin:room", false}, {"builtin:dynamic", false}, {"builtin:room", true}};
  const std::vector<std::vector<std::string>> configs = {
      {},
      {"pipelines=3", "threads=4", "packet=16", "cache.traversal.items=8"},
      {"pipelines=2", "threads=8", "packet=1"}};
  const units::ProgramMode modes[] = {units::ProgramMode::kAhead, units::ProgramMode::kPacketFirst,
                                      units::ProgramMode::kPerStep};
  for (const SceneCase& sc : scenes) {
    // The sanitizer build's smaller frame misses the room's reflective and transparent
    // surfaces: the secondary-ray case keeps 32x24 there too.
    const bool secondary = sc.shadows_and_secondary;
    const host::BuiltImage built =
        units::testing::build(sc.spec, secondary ? 32 : kW, secondary ? 24 : kH);
    units::FunctionalParams shading;
    shading.shadows = shading.secondary = sc.shadows_and_secondary;
    shading.max_depth = sc.shadows_and_secondary ? 2 : -1;
    for (std::size_t c = 0; c < configs.size(); ++c) {
      const std::vector<TraceLine> f =
          parse_all(functional_trace(built.image, shading, configs[c]));
      ASSERT_FALSE(f.empty());
      const units::ProgramMode mode = modes[c];
      const std::vector<TraceLine> y =
          parse_all(run_traced_cycle(built.image, configs[c], shading, mode).trace);
      const std::string what = std::string(sc.spec) + (sc.shadows_and_secondary ? " +rays" : "") +
                               ", config " + std::to_string(c) + ", " +
                               units::program_mode_name(mode);
      EXPECT_EQ(compare_traces(f, y), "") << what;
      EXPECT_EQ(f.size(), y.size()) << what;
      // The cycle columns are there and rise; the functional ones are absent.
      for (std::size_t i = 1; i < y.size(); ++i)
        ASSERT_LE(y[i - 1].cycle, y[i].cycle) << what;
      EXPECT_EQ(f.front().cycle, units::kNoCycle);
      EXPECT_EQ(f.front().thread, -1);
      // What the scenes exercise: instances, shadow and secondary rays, transactions of each unit.
      std::map<std::string, int> seen;
      for (const TraceLine& l : f) {
        ++seen[units::phase_name(l.phase)];
        ++seen[units::ray_kind_name(l.kind)];
        if (l.txn.find("->") != std::string::npos) ++seen["txn"];
      }
      EXPECT_GT(seen["traverse"], 0) << what;
      EXPECT_GT(seen["intersect"], 0) << what;
      EXPECT_GT(seen["txn"], 0) << what;
      if (std::string(sc.spec) == "builtin:dynamic") {
        EXPECT_GT(seen["transform_object"], 0) << what;
      }
      if (sc.shadows_and_secondary) {
        EXPECT_GT(seen["shadow"], 0) << what;
        EXPECT_GT(seen["reflection"] + seen["transparency"], 0) << what;
      }
    }
  }
}

// The comparison can fail: one hex digit of one transaction, a dropped request, two requests
// swapped are each reported with the packet and request they concern.
TEST(RequestTrace, ComparisonCatchesAnAlteredValueAMissingAndASwappedRequest) {
  const host::BuiltImage built = units::testing::build("builtin:room", 16, 12);
  const units::FunctionalParams shading;
  const std::vector<TraceLine> f = parse_all(functional_trace(built.image, shading, {}));
  std::vector<TraceLine> y =
      parse_all(run_traced_cycle(built.image, {}, shading, units::ProgramMode::kAhead).trace);
  ASSERT_EQ(compare_traces(f, y), "");
  // The first intersection with a transaction: its t's last hex digit changed.
  std::size_t k = 0;
  while (k < y.size() && !(y[k].phase == units::Phase::kIntersect && !y[k].txn.empty()))
    ++k;
  ASSERT_LT(k, y.size());
  std::vector<TraceLine> altered = y;
  const std::size_t arrow = altered[k].txn.find("->");
  char& digit = altered[k].txn[arrow + 7];  // "->" then 6 digits of t: its last digit
  digit = digit == '0' ? '1' : '0';
  const std::string why = compare_traces(f, altered);
  EXPECT_NE(why.find("packet " + std::to_string(y[k].packet) + " request " +
                     std::to_string(y[k].seq) + ":"),
            std::string::npos)
      << why;
  std::vector<TraceLine> dropped = y;
  dropped.erase(dropped.begin() + static_cast<std::ptrdiff_t>(k));
  EXPECT_NE(compare_traces(f, dropped), "");
  std::vector<TraceLine> swapped = f;
  std::swap(swapped[3], swapped[4]);  // packet 0's requests 3 and 4
  EXPECT_EQ(compare_traces(swapped, y), "packet 0 request 3: out of order");
}

// Tracing is an observer: the same cycles, unit figures, caches and pixels as an untraced run.
TEST(RequestTrace, TracingMovesNoFigure) {
  const host::BuiltImage built = units::testing::build("builtin:dynamic", kW, kH);
  const units::FunctionalParams shading;
  for (const units::ProgramMode mode : {units::ProgramMode::kAhead, units::ProgramMode::kPerStep}) {
    CycleRunOptions plain;
    plain.programs = mode;
    const CycleFrame a = run_cycle(built.image, units::prototype_params(), plain);
    const Traced b = run_traced_cycle(built.image, {}, shading, mode, true);
    EXPECT_EQ(a.cycles, b.frame.cycles);
    EXPECT_EQ(a.issue_cycles, b.frame.issue_cycles);
    EXPECT_EQ(a.stall_cycles, b.frame.stall_cycles);
    EXPECT_EQ(a.requests, b.frame.requests);
    EXPECT_EQ(a.stats_json, b.frame.stats_json);
    EXPECT_EQ(a.frame.rgb, b.frame.frame.rgb);
    // A line per request every unit (the RGS's too) served.
    EXPECT_EQ(a.frame.units.requests, parse_all(b.trace).size());
  }
}

// ---- the Kanata log ---------------------------------------------------------------------------

struct KonataInsn {
  std::string label;
  std::vector<std::pair<std::string, std::pair<std::uint64_t, std::uint64_t>>> stages;
  std::uint64_t retired = 0;
};

std::vector<std::string> split_tabs(const std::string& line) {
  std::vector<std::string> f;
  std::size_t b = 0;
  for (;;) {
    const std::size_t e = line.find('\t', b);
    f.push_back(line.substr(b, e - b));
    if (e == std::string::npos) return f;
    b = e + 1;
  }
}

bool is_number(const std::string& s) {
  return !s.empty() && s.find_first_not_of("0123456789") == std::string::npos;
}

// The grammar of Kanata 0004 (docs/traces.md): the header; C= once, then C with a positive delta
// (cycles rise); I before any other command of its id, ids in sequence; L with type 0 or 1; S and
// E in pairs per lane and stage, E never before its S; R once, after every stage ended; every id
// retired. Returns the instructions, or fails the test with the line.
std::vector<KonataInsn> validate_konata(const std::string& text) {
  std::vector<KonataInsn> insns;
  std::vector<bool> retired;
  std::map<std::pair<std::size_t, std::string>, std::uint64_t> open;  // (id, lane+stage) -> start
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "Kanata\t0004");
  std::uint64_t cycle = 0;
  bool have_cycle = false;
  int n = 1;
  while (std::getline(in, line)) {
    ++n;
    const std::vector<std::string> f = split_tabs(line);
    const std::string& c = f[0];
    const auto fail = [&](const std::string& why) {
      ADD_FAILURE() << "Kanata line " << n << " '" << line << "': " << why;
      return std::vector<KonataInsn>{};
    };
    const std::size_t fields = c == "C=" || c == "C" ? 2 : 4;
    if (f.size() != fields) return fail("expected " + std::to_string(fields) + " fields");
    for (std::size_t i = 1; i < f.size(); ++i)
      if (!is_number(f[i]) && !(c == "L" && i == 3) && !(i == 3 && (c == "S" || c == "E")))
        return fail("field " + std::to_string(i) + " is not a number");
    if (c == "C=") {
      if (have_cycle) return fail("a second C=");
      cycle = std::stoull(f[1]);
      have_cycle = true;
      continue;
    }
    if (!have_cycle) return fail("a command before C=");
    if (c == "C") {
      if (std::stoull(f[1]) == 0) return fail("C 0: cycles must rise");
      cycle += std::stoull(f[1]);
      continue;
    }
    const std::size_t id = std::stoull(f[1]);
    if (c == "I") {
      if (id != insns.size()) return fail("ids must be sequential");
      insns.emplace_back();
      retired.push_back(false);
      continue;
    }
    if (id >= insns.size()) return fail("id used before its I");
    if (retired[id]) return fail("id used after its R");
    KonataInsn& k = insns[id];
    if (c == "L") {
      if (f[2] != "0" && f[2] != "1") return fail("L type is 0 or 1");
      if (f[2] == "0") k.label = f[3];
    } else if (c == "S") {
      if (!open.emplace(std::make_pair(id, f[2] + "/" + f[3]), cycle).second)
        return fail("stage started twice");
    } else if (c == "E") {
      const auto it = open.find({id, f[2] + "/" + f[3]});
      if (it == open.end()) return fail("E without S");
      k.stages.push_back({f[3], {it->second, cycle}});
      open.erase(it);
    } else if (c == "R") {
      if (f[3] != "0" && f[3] != "1") return fail("R type is 0 or 1");
      for (const auto& [key, start] : open)
        if (key.first == id) return fail("R with a stage open");
      retired[id] = true;
      k.retired = cycle;
    } else {
      return fail("unknown command");
    }
  }
  for (std::size_t i = 0; i < retired.size(); ++i)
    EXPECT_TRUE(retired[i]) << "id " << i << " never retired";
  return insns;
}

// One thread, so nothing contends: the second traversing packet's root step (the root left in
// the node cache by the first) has the stages of units/unit_timing_test.cpp's cache hit. Path
// latency 1 (queue), one cycle sending the node request (fetch), the rest of the hit latency
// (wait), ready one cycle before issue, one issue step, the rest of the depth in the pipeline,
// delivered when it ends.
TEST(KonataLog, ObeysTheGrammarAndTimesACacheHitNodeStepExactly) {
  const host::BuiltImage built = units::testing::build("builtin:cube", 8, 8);
  const Traced t =
      run_traced_cycle(built.image, {"threads=1"}, {}, units::ProgramMode::kAhead, true);
  const std::vector<KonataInsn> insns = validate_konata(t.konata);
  ASSERT_FALSE(insns.empty());
  EXPECT_EQ(insns.size(), t.frame.frame.units.requests);  // one record per request
  const units::CycleParams p = units::prototype_params();
  const int hit = 2, path = 1, ready_to_issue = 1, steps = 1;  // cache.hit_latency's default
  const int depth = p.lat_add + p.lat_div + p.lat_cmp;         // the traversal unit's
  // The first packet that traverses fetches the root (a miss); the next packet's root step hits.
  const KonataInsn* node = nullptr;
  std::string first_packet, root;
  for (const KonataInsn& k : insns) {
    const std::size_t at = k.label.find(" traversal traverse ");
    if (at == std::string::npos) continue;
    const std::string packet = k.label.substr(0, k.label.find('.'));
    const std::string item = k.label.substr(at + 20);
    if (first_packet.empty()) {
      first_packet = packet;
      root = item;
    } else if (packet != first_packet && item == root) {
      node = &k;
      break;
    }
  }
  ASSERT_NE(node, nullptr);
  const std::vector<std::pair<std::string, std::uint64_t>> expected = {
      {"queue", path},           {"fetch", 1},     {"wait", hit - 1},
      {"ready", ready_to_issue}, {"issue", steps}, {"pipe", depth - 1}};
  ASSERT_EQ(node->stages.size(), expected.size()) << node->label;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(node->stages[i].first, expected[i].first) << node->label;
    EXPECT_EQ(node->stages[i].second.second - node->stages[i].second.first, expected[i].second)
        << node->label << " stage " << expected[i].first;
    if (i > 0) {
      EXPECT_EQ(node->stages[i].second.first, node->stages[i - 1].second.second);
    }
  }
  // Accepted to delivered: hit + ready-to-issue + (steps - 1) + depth, as the unit timing test.
  const std::uint64_t accepted = node->stages[1].second.first;
  EXPECT_EQ(node->retired - accepted, static_cast<std::uint64_t>(hit + ready_to_issue + depth));
}

// ---- the command line ---------------------------------------------------------------------------

std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

TEST(TraceCommand, RenderWritesTheTraceAndTheKanataLogOfAWindow) {
  const std::filesystem::path d = test_support::scratch_dir("trace_cmd");
  const std::string cycle_trace = (d / "cycle.trace").string();
  const std::string fp24_trace = (d / "fp24.trace").string();
  const std::string konata = (d / "run.kanata").string();
  RenderOptions o;
  o.scene = "builtin:room";
  o.res = "16x12";
  o.out = (d / "img").string();
  o.model = "cycle";
  o.trace.file = cycle_trace;
  o.trace.konata = konata;
  o.trace.konata_threads = "0-3";
  o.trace.from = 100;
  o.trace.to = 400;
  o.trace.window_given = true;
  ASSERT_EQ(run_render(o), 0);
  const std::vector<TraceLine> lines = parse_all(slurp(cycle_trace));
  ASSERT_FALSE(lines.empty());
  for (const TraceLine& l : lines) {
    EXPECT_GE(l.cycle, 100u);
    EXPECT_LE(l.cycle, 400u);
  }
  const std::vector<KonataInsn> insns = validate_konata(slurp(konata));
  ASSERT_FALSE(insns.empty());
  for (const KonataInsn& k : insns)
    EXPECT_GE(k.stages.front().second.first, 100u);
  // The same lines as the fp24 model's for every request inside the window.
  RenderOptions f = o;
  f.model = "fp24";
  f.trace = {};
  f.trace.file = fp24_trace;
  ASSERT_EQ(run_render(f), 0);
  std::map<std::pair<int, std::uint32_t>, TraceLine> by_key;
  for (const TraceLine& l : parse_all(slurp(fp24_trace)))
    by_key[{l.packet, l.seq}] = l;
  for (const TraceLine& l : lines)
    EXPECT_TRUE(units::same_request(by_key.at({l.packet, l.seq}), l)) << format_trace_line(l);
}

TEST(TraceCommand, PixelPrintsEveryRequestOfItsPacketWithItsCycle) {
  const test_support::CliRun r =
      test_support::run_saarcor("render builtin:room --model cycle --res 16x12 --pixel 5,3");
  ASSERT_EQ(r.status, 0) << r.err;
  const test_support::CliRun f =
      test_support::run_saarcor("render builtin:room --model fp24 --res 16x12 --pixel 5,3");
  ASSERT_EQ(f.status, 0) << f.err;
  // The functional printout's request lines, each with a cycle in front in the cycle printout.
  std::vector<std::string> want, got;
  std::istringstream fin(f.out), cin(r.out);
  for (std::string l; std::getline(fin, l);)
    if (l.starts_with("  ") && l.find("item=") != std::string::npos) want.push_back(l.substr(2));
  std::uint64_t last = 0;
  for (std::string l; std::getline(cin, l);) {
    if (!l.starts_with("  cycle=")) continue;
    const std::uint64_t c = std::stoull(l.substr(8));
    EXPECT_GE(c, last);
    last = c;
    got.push_back(l.substr(l.find("thread=") + 11));
  }
  ASSERT_FALSE(want.empty());
  ASSERT_EQ(got.size(), want.size()) << r.out;
  for (std::size_t i = 0; i < got.size(); ++i)
    EXPECT_EQ(got[i], want[i]);
  EXPECT_NE(r.out.find("pixel 5,3: "), std::string::npos);
}

TEST(TraceCommand, MisuseIsOneErrorLine) {
  const std::filesystem::path d = test_support::scratch_dir("trace_bad");
  const std::string base = "render builtin:cube --res 8x8 --out " + (d / "x").string() + " ";
  using test_support::expect_one_line_error;
  using test_support::run_saarcor;
  expect_one_line_error(run_saarcor(base + "--model cycle --trace /nonexistent/dir/t.trace"),
                        "cannot write --trace '/nonexistent/dir/t.trace'");
  expect_one_line_error(run_saarcor(base + "--model cycle --konata /nonexistent/k.log"),
                        "cannot write --konata");
  expect_one_line_error(run_saarcor(base + "--model cycle --trace " + (d / "t").string() +
                                    " --trace-from 50 --trace-to 10"),
                        "bad --trace-to 10: before --trace-from 50");
  expect_one_line_error(run_saarcor(base + "--model float --trace " + (d / "t").string()),
                        "the float reference has none");
  expect_one_line_error(run_saarcor(base + "--model fp24 --konata " + (d / "k").string()),
                        "--konata needs --model cycle");
  expect_one_line_error(
      run_saarcor(base + "--model fp24 --trace " + (d / "t").string() + " --trace-to 5"),
      "apply to --model cycle");
  expect_one_line_error(run_saarcor(base + "--model cycle --trace-to 5"),
                        "limit --trace, --konata or --perfetto");
  expect_one_line_error(
      run_saarcor(base + "--model cycle --konata " + (d / "k").string() + " --konata-threads 0,64"),
      "bad --konata-threads '0,64': thread 64 does not exist (64 threads)");
  expect_one_line_error(
      run_saarcor(base + "--model cycle --konata " + (d / "k").string() + " --konata-threads 3-1"),
      "runs backwards");
  expect_one_line_error(
      run_saarcor(base + "--model cycle --pixel 1,1 --trace " + (d / "t").string()),
      "--pixel prints its packet's requests itself");
  // No trace file is left behind by a refused command.
  EXPECT_FALSE(std::filesystem::exists(d / "t"));
  EXPECT_FALSE(std::filesystem::exists(d / "k"));
  EXPECT_EQ(parse_thread_list("0,3,8-10", 16), (std::vector<std::uint32_t>{0, 3, 8, 9, 10}));
  EXPECT_EQ(error_of([] { parse_thread_list("1,,2", 16); }),
            "bad --konata-threads '1,,2': expected thread ids like 0,3,8-11");
}

}  // namespace
}  // namespace saarcor
