// saarcor-rtl: runs a unit vector file (docs/unit-vectors.md, written by `saarcor vectors`)
// through the Verilated unit datapath (rtl/*.sv) and lists every vector whose RTL outputs differ
// from the file's (docs/rtl.md).
//
//   saarcor-rtl check FILE [--out OUT] [--max N]
//
//   saarcor-rtl lockstep SCENE [--units traversal,list,transformation,intersection,caches|dynrtc]
//                        [--res WxH]
//                        [--set KEY=VALUE ...] [--shadows] [--depth N] [--until CYCLE]
//                        [--wave FILE] [--bench]
//
// check: exit status 0 every vector matches, 2 some differ (or the RTL's latency is not the cycle
// model's unit depth), 1 usage error or malformed file. lockstep (rtl/lockstep.h): 0 no
// divergence, 2 a divergence (its screen printed, the RTL waveform around it written), 1 bad
// usage or a configuration no Verilated build has.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <string>
#include <vector>

#include "rtl/lockstep.h"
#include "rtl/rtl_units.h"
#include "rtl/vector_file.h"
#include "units/cycle_params.h"

namespace {

constexpr const char* kUsage =
    "usage: saarcor-rtl check FILE [--out OUT] [--max N]\n"
    "       saarcor-rtl lockstep SCENE [--units "
    "traversal,list,transformation,intersection,caches|dynrtc]\n"
    "                            [--res WxH] [--set KEY=VALUE ...] [--shadows] [--depth N]\n"
    "                            [--until CYCLE] [--wave FILE] [--bench] [--fault NAME]\n"
    "  lockstep: runs the cycle model and the Verilated units (traversal, list, transformation,\n"
    "  intersection; the caches node-cache, list-cache, row-cache, or caches for the three;\n"
    "  default traversal,list) side by side and compares every port event of each\n"
    "  in the same cycle; exit 2 at the first divergence (its screen, a VCD window of the RTL\n"
    "  around it and the replay command printed). --bench also times the cycle model alone on\n"
    "  the same frame.\n"
    "  Runs the unit vectors in FILE (saarcor vectors --out FILE) through the Verilated unit and\n"
    "  lists the vectors whose outputs differ from the file's (at most N, default 20).\n"
    "  --out OUT  also writes FILE with the RTL's outputs (saarcor vectors --check OUT checks it)\n"
    "  Exit status: 0 all match, 2 some differ, 1 bad usage or a malformed file.\n";

int depth_of(saarcor::units::VectorUnit unit) {
  const saarcor::units::CycleParams p = saarcor::units::prototype_params();
  switch (unit) {
    case saarcor::units::VectorUnit::kTraversal:
      return p.traversal_depth();
    case saarcor::units::VectorUnit::kTransformation:
      return p.transformation_depth();
    case saarcor::units::VectorUnit::kIntersection:
      return p.intersection_depth();
  }
  return -1;
}

std::string show(std::uint32_t v, bool flag) {
  char buf[16];
  std::snprintf(buf, sizeof buf, flag ? "%u" : "%06x", static_cast<unsigned>(v));
  return buf;
}

int check(const std::string& path, const std::string& out, std::size_t max_list) {
  using namespace saarcor;
  const rtl::VectorFile file = rtl::read_vector_file(path);
  std::vector<std::vector<std::uint32_t>> inputs;
  inputs.reserve(file.vectors.size());
  for (const auto& v : file.vectors)
    inputs.push_back(v.in);
  const rtl::RtlRun run = rtl::run_unit(file.unit, inputs);
  const auto& names = units::vector_outputs(file.unit);

  std::size_t differing = 0;
  std::vector<std::vector<std::uint32_t>> outputs;
  for (std::size_t k = 0; k < file.vectors.size(); ++k) {
    const auto& want = file.vectors[k].out;
    std::vector<std::uint32_t> got(run.outputs[k].begin(),
                                   run.outputs[k].begin() + static_cast<long>(want.size()));
    bool differs = false;
    for (std::size_t i = 0; i < want.size(); ++i) {
      if (got[i] == want[i]) continue;
      if (!differs && differing < max_list) {
        std::printf("line %zu: %s is %s in the RTL, the file has %s\n", file.vectors[k].line,
                    names[i].c_str(), show(got[i], units::vector_field_is_flag(names[i])).c_str(),
                    show(want[i], units::vector_field_is_flag(names[i])).c_str());
      }
      differs = true;
    }
    differing += differs ? 1 : 0;
    outputs.push_back(std::move(got));
  }
  if (differing > max_list) std::printf("... and %zu more\n", differing - max_list);

  const int depth = depth_of(file.unit);
  const bool latency_ok =
      run.latency_min == depth && run.latency_max == depth && run.stray_outputs == 0;
  std::printf(
      "saarcor-rtl check: %s unit, %zu vectors in %llu cycles, latency %d cycles (cycle model "
      "depth %d)%s, %zu differ\n",
      units::vector_unit_name(file.unit), file.vectors.size(),
      static_cast<unsigned long long>(run.cycles), run.latency_max, depth,
      latency_ok ? "" : " MISMATCH", differing);
  if (!out.empty()) {
    std::ofstream o(out, std::ios::binary);
    o << rtl::format_vector_file(file, outputs);
    if (!o) throw std::runtime_error("cannot write " + out);
  }
  return (differing == 0 && latency_ok) ? 0 : 2;
}

// Parses a decimal count; false for anything else.
bool parse_count(const std::string& s, std::uint64_t& out) {
  if (s.empty() || s.size() > 18 || s.find_first_not_of("0123456789") != std::string::npos)
    return false;
  out = std::stoull(s);
  return true;
}

using saarcor::rtl::LockstepOptions;

int fail(const std::string& m) {
  std::fprintf(stderr, "saarcor-rtl: error: %s\n", m.c_str());
  return 1;
}

std::vector<std::string> split_units(const std::string& u) {
  std::vector<std::string> units;
  for (std::size_t p = 0; p != std::string::npos;) {
    const std::size_t q = u.find(',', p);
    units.push_back(u.substr(p, q == std::string::npos ? q : q - p));
    p = q == std::string::npos ? q : q + 1;
  }
  return units;
}

// The options after SCENE into o; the error line's text, or "" when they all parse.
std::string parse_lockstep_args(const std::vector<std::string>& args, LockstepOptions& o) {
  for (std::size_t i = 2; i < args.size(); ++i) {
    const std::string& a = args[i];
    const bool has = i + 1 < args.size();
    std::uint64_t n = 0;
    if (a == "--shadows") {
      o.shadows = true;
    } else if (a == "--bench") {
      o.bench = true;
    } else if (!has) {
      return "unknown or incomplete argument '" + a + "'";
    } else if (a == "--units") {
      o.units = split_units(args[++i]);
    } else if (a == "--res") {
      const std::string r = args[++i];
      const std::size_t x = r.find('x');
      std::uint64_t w = 0, h = 0;
      if (x == std::string::npos || !parse_count(r.substr(0, x), w) ||
          !parse_count(r.substr(x + 1), h) || w == 0 || h == 0 || w > 8192 || h > 8192)
        return "--res '" + r + "' is not WxH";
      o.width = static_cast<int>(w);
      o.height = static_cast<int>(h);
    } else if (a == "--set") {
      o.set.push_back(args[++i]);
    } else if (a == "--depth") {
      if (!parse_count(args[++i], n) || n > 16) return "--depth '" + args[i] + "' is not 0..16";
      o.depth = static_cast<int>(n);
    } else if (a == "--until") {
      if (!parse_count(args[++i], n) || n == 0) return "--until '" + args[i] + "' is not a cycle";
      o.until = n;
    } else if (a == "--wave") {
      o.wave = args[++i];
    } else if (a == "--fault") {
      o.fault = args[++i];
    } else {
      return "unknown argument '" + a + "'";
    }
  }
  return "";
}

// A divergence: the same run again, traced around the cycle, then its screen, the waveform and
// the replay command.
int report_divergence(const LockstepOptions& o, const saarcor::rtl::LockstepResult& r) {
  LockstepOptions w = o;
  w.write_wave = true;
  w.wave_from = r.divergence.cycle > 64 ? r.divergence.cycle - 64 : 0;
  w.wave_to = r.divergence.cycle + 16;
  w.until = w.wave_to;
  (void)saarcor::rtl::run_lockstep(w);  // the same run again, traced around the cycle
  std::fputs(r.screen.c_str(), stdout);
  std::printf("  waveform: %s (RTL cycles %llu..%llu, 2 time units per cycle)\n",
              saarcor::rtl::wave_file(o, r.divergence.unit).c_str(),
              static_cast<unsigned long long>(w.wave_from),
              static_cast<unsigned long long>(w.wave_to));
  std::printf("  replay:   %s --until %llu --wave %s\n", saarcor::rtl::lockstep_command(o).c_str(),
              static_cast<unsigned long long>(r.divergence.cycle), w.wave.c_str());
  return 2;
}

void report_agreement(const LockstepOptions& o, const saarcor::rtl::LockstepResult& r) {
  if (o.until != 0 && r.cycles <= o.until + 1) {
    std::printf(
        "saarcor-rtl lockstep: stopped after cycle %llu (--until), no divergence up to it\n",
        static_cast<unsigned long long>(o.until));
    for (const saarcor::rtl::LockstepUnit& u : r.units)  // one waveform per RTL unit
      std::printf(
          "  waveform: %s (RTL cycles %llu..%llu)\n", saarcor::rtl::wave_file(o, u.unit).c_str(),
          static_cast<unsigned long long>(o.wave_from), static_cast<unsigned long long>(o.wave_to));
  }
  std::printf("saarcor-rtl lockstep: %s %dx%d: 0 divergences in %llu cycles\n", o.scene.c_str(),
              o.width, o.height, static_cast<unsigned long long>(r.model_cycles));
  using saarcor::units::BoundaryPort;
  using Ports = std::vector<BoundaryPort>;
  for (const saarcor::rtl::LockstepUnit& u : r.units) {
    const bool cache = u.unit.ends_with("-cache");
    const bool whole = u.unit == "dynrtc";  // its boundary in; every unit's and cache's compared
    std::printf("  %s %s(build %s): in:", u.unit.c_str(), cache || whole ? "" : "unit ",
                u.build.c_str());
    for (BoundaryPort p :
         whole ? Ports{BoundaryPort::kInput, BoundaryPort::kSideBand, BoundaryPort::kPortResponse,
                       BoundaryPort::kPortBlocked}
         : cache
             ? Ports{BoundaryPort::kCacheRequest, BoundaryPort::kMemTaken, BoundaryPort::kMemFill}
             : Ports{BoundaryPort::kInput, BoundaryPort::kSideBand, BoundaryPort::kCacheResponse,
                     BoundaryPort::kCacheBlocked})
      std::printf(" %s %llu", saarcor::units::boundary_port_name(p),
                  static_cast<unsigned long long>(u.event(p)));
    std::printf("; compared:");
    for (BoundaryPort p :
         whole   ? Ports{BoundaryPort::kCacheRequest, BoundaryPort::kOutput,
                       BoundaryPort::kCacheAccept, BoundaryPort::kCacheReply,
                       BoundaryPort::kMemRequest, BoundaryPort::kMemTaken, BoundaryPort::kMemFill}
         : cache ? Ports{BoundaryPort::kCacheAccept, BoundaryPort::kCacheReply,
                         BoundaryPort::kMemRequest}
                 : Ports{BoundaryPort::kCacheRequest, BoundaryPort::kOutput})
      std::printf(" %s %llu", saarcor::units::boundary_port_name(p),
                  static_cast<unsigned long long>(u.event(p)));
    std::printf("\n");
  }
  const double c = static_cast<double>(r.model_cycles);
  std::printf("  speed: RTL %.0f k cycles/s, co-simulation %.0f k cycles/s",
              r.rtl_seconds > 0 ? static_cast<double>(r.cycles) / r.rtl_seconds / 1e3 : 0.0,
              r.seconds > 0 ? c / r.seconds / 1e3 : 0.0);
  if (o.bench)
    std::printf(", cycle model alone %.0f k cycles/s",
                r.model_seconds > 0 ? c / r.model_seconds / 1e3 : 0.0);
  std::printf("\n");
}

int lockstep(const std::vector<std::string>& args) {
  LockstepOptions o;
  o.scene = args[1];
  const std::string error = parse_lockstep_args(args, o);
  if (!error.empty()) return fail(error);
  try {
    if (o.until != 0) {  // a replay: the waveform of the window before the cycle asked for
      o.write_wave = true;
      o.wave_from = o.until > 64 ? o.until - 64 : 0;
      o.wave_to = o.until;
    }
    const saarcor::rtl::LockstepResult r = saarcor::rtl::run_lockstep(o);
    if (r.diverged) return report_divergence(o, r);
    report_agreement(o, r);
    return 0;
  } catch (const std::exception& e) {
    return fail(e.what());
  }
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() == 1 && (args[0] == "--help" || args[0] == "-h")) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  if (args.size() >= 2 && args[0] == "lockstep") return lockstep(args);
  if (args.size() < 2 || args[0] != "check") {
    std::fputs(kUsage, stderr);
    return 1;
  }
  std::string out;
  std::size_t max_list = 20;
  for (std::size_t i = 2; i < args.size(); ++i) {
    if (args[i] == "--out" && i + 1 < args.size()) {
      out = args[++i];
    } else if (args[i] == "--max" && i + 1 < args.size()) {
      char* end = nullptr;
      const unsigned long long n = std::strtoull(args[++i].c_str(), &end, 10);
      if (*end != '\0' || args[i].empty()) {
        std::fprintf(stderr, "saarcor-rtl: error: --max '%s' is not a count\n", args[i].c_str());
        return 1;
      }
      max_list = static_cast<std::size_t>(n);
    } else {
      std::fprintf(stderr, "saarcor-rtl: error: unknown argument '%s'\n%s", args[i].c_str(),
                   kUsage);
      return 1;
    }
  }
  try {
    return check(args[1], out, max_list);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "saarcor-rtl: error: %s\n", e.what());
    return 1;
  }
}
