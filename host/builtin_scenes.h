// Built-in procedural scenes, deterministic stand-ins for the paper's benchmark scenes (paper
// section 5, Table 3; decision D42: matched in triangle and object counts). docs/scenes.md lists
// what each contains.
#pragma once

#include <string>
#include <vector>

#include "host/scene.h"

namespace saarcor::host {

// Names accepted by make_builtin_scene(), in a fixed order.
std::vector<std::string> builtin_scene_names();

// Builds `builtin:NAME` (name without the prefix). Every instance is a root node (id = node index
// = instance index); cameras and lights have fixed world positions. Throws std::runtime_error for
// an unknown name, listing the known ones.
Scene make_builtin_scene(const std::string& name);

}  // namespace saarcor::host
