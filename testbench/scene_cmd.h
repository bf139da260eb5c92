// `saarcor scene SCENE [--time T] [--json] [--export FILE] [--bank-mb MB]`: what a scene holds
// and what the host makes of it (counts, both kd-tree levels' statistics and build
// times, bytes per SRAM bank; docs/memory-image.md).
#pragma once

#include <string>
#include <vector>

namespace saarcor {

struct SceneOptions {
  std::string scene;             // glTF path or builtin:NAME
  double time = 0.0;             // seconds; animated transforms are evaluated here
  bool json = false;             // one JSON object on stdout instead of text
  std::string export_path;       // write the scene as glTF (.glb or .gltf) when set
  double bank_mb = 4.0;          // SRAM bank size for the memory image (the prototype: 4 MB)
  std::vector<std::string> set;  // kd.KEY=VALUE: the tree builder's keys (host/tree_settings.h)
};

// Prints the report on stdout; returns the exit status. Bad input throws std::runtime_error.
int run_scene(const SceneOptions& options);

}  // namespace saarcor
