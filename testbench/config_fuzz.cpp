// libFuzzer harness of the configuration parser (docs/fuzzing.md): `--preset P --set KEY=VALUE
// ...` resolved the way `saarcor render --model cycle` resolves it (testbench/cycle_render.cpp
// resolve_cycle_params: the preset, then each setting in order, kd.* keys into the tree builder's
// parameters and the others into the cycle model's, then the cross-parameter checks). The input's
// first line is the preset name, every further line (NUL bytes end a line too: an argument cannot
// hold one) one KEY=VALUE.
//
// What follows a parse that succeeded is checked too: every resolved cycle key and kd.* key lies
// in its declared range (a power of two where it must be), and the kd.* keys build the trees of a
// small built-in scene (the cube; the room when any kd.* key is given). Bad input may only end in
// one std::runtime_error line (fuzz::documented_errors_only); anything else is a finding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "host/fuzz_support.h"
#include "host/image_builder.h"
#include "host/scene.h"
#include "host/tree_settings.h"
#include "units/cycle_params.h"

namespace {

using saarcor::fuzz::finding;

std::vector<std::string> lines_of(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> lines(1);
  for (std::size_t i = 0; i < size; ++i) {
    if (data[i] == '\n' || data[i] == 0) {  // a command-line argument holds no NUL
      lines.emplace_back();
    } else {
      lines.back() += static_cast<char>(data[i]);
    }
  }
  return lines;
}

template <class Info>
void check_range(const Info& i, bool pow2) {
  if (!(i.value >= i.min && i.value <= i.max))
    finding(i.name + " = " + std::to_string(i.value) + " resolved outside " +
            std::to_string(i.min) + ".." + std::to_string(i.max));
  if (pow2) {
    const auto n = static_cast<std::uint64_t>(i.value);
    if (n == 0 || (n & (n - 1)) != 0)
      finding(i.name + " = " + std::to_string(i.value) + " resolved to a non-power of two");
  }
}

void exercise(const std::vector<std::string>& lines) {
  using namespace saarcor;
  units::CycleParams p = units::cycle_preset(lines.front());
  host::ImageParams trees;
  trees.width = 8;
  trees.height = 8;
  bool kd = false;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    if (host::is_tree_setting(lines[i])) {
      host::apply_tree_setting(trees, lines[i]);
      kd = true;
    } else {
      units::apply_cycle_setting(p, lines[i]);
    }
  }
  units::check_cycle_params(p);
  for (const units::CycleParamInfo& i : units::describe(p))
    check_range(i, i.pow2);
  for (const host::TreeSettingInfo& i : host::describe_tree_settings(trees))
    if (i.name != "kd.max_depth" || i.value != -1.0) check_range(i, false);
  if (p.pipelines * p.threads > units::kMaxChipThreads)
    finding("pipelines x threads = " + std::to_string(p.pipelines * p.threads) + " accepted");
  static const host::Scene cube = host::load_scene("builtin:cube");
  static const host::Scene room = host::load_scene("builtin:room");
  const host::BuiltImage built = host::build_image(kd ? room : cube, trees);
  if (built.top.nodes.empty()) finding("a built image without a top-level tree");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::vector<std::string> lines = lines_of(data, size);
  // The messages quote the argument as given (allow_cr).
  saarcor::fuzz::documented_errors_only([&] { exercise(lines); }, true);
  return 0;
}
