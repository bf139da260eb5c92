// saarcor-rtl: runs a unit vector file (docs/unit-vectors.md, written by `saarcor vectors`)
// through the Verilated unit datapath (rtl/*.sv) and lists every vector whose RTL outputs differ
// from the file's (docs/rtl.md).
//
//   saarcor-rtl check FILE [--out OUT] [--max N]
//
// Exit status: 0 every vector matches, 2 some differ (or the RTL's latency is not the cycle
// model's unit depth), 1 usage error or malformed file.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <string>
#include <vector>

#include "rtl/rtl_units.h"
#include "rtl/vector_file.h"
#include "units/cycle_params.h"

namespace {

constexpr const char* kUsage =
    "usage: saarcor-rtl check FILE [--out OUT] [--max N]\n"
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

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() == 1 && (args[0] == "--help" || args[0] == "-h")) {
    std::fputs(kUsage, stdout);
    return 0;
  }
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
