// `saarcor scene SCENE [--time T] [--json] [--export FILE] [--bank-mb MB] [--write-image FILE]`:
// what a scene holds and what the host makes of it (counts, both kd-tree levels' statistics and
// build times, bytes per SRAM bank; docs/memory-image.md), and the memory image as a file for a
// reference outside the process (memif/image_file.h: the DPI-C library of rtl/dpi/ loads it).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "host/image_builder.h"
#include "host/kdtree.h"

namespace saarcor {

struct SceneOptions {
  std::string scene;             // glTF path or builtin:NAME
  double time = 0.0;             // seconds; animated transforms are evaluated here
  bool json = false;             // one JSON object on stdout instead of text
  std::string export_path;       // write the scene as glTF (.glb or .gltf) when set
  std::string image_path;        // write the memory image file (memif/image_file.h) when set
  double bank_mb = 4.0;          // SRAM bank size for the memory image (the prototype: 4 MB)
  std::vector<std::string> set;  // kd.KEY=VALUE: the tree builder's keys (host/tree_settings.h)
};

// The scene's trees: the top level and each stored object's (built with the memory image, or alone
// when the image does not fit its banks).
struct SceneTrees {
  host::KdTreeStats top;
  std::vector<std::pair<std::uint32_t, host::KdTreeStats>> bottom;  // (object, stats)
};

// The memory image, or when it does not fit its banks the reason and the trees built alone.
struct SceneImage {
  std::optional<host::BuiltImage> built;
  std::string error;
  host::ImageParams params;
  SceneTrees trees;
  double seconds = 0.0;
};

// Instances whose transform is animated.
std::uint64_t dynamic_instances(const host::Scene& scene);

// Prints the report on stdout (testbench/report.h scene_report_json; --json prints it as JSON);
// returns the exit status. Bad input throws std::runtime_error.
int run_scene(const SceneOptions& options);

}  // namespace saarcor
