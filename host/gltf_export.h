// Scene -> glTF 2.0 through tinygltf's writer, so other tools can open the built-in scenes
// (`saarcor scene builtin:NAME --export out.glb`). Mapping rules in docs/scenes.md.
#pragma once

#include <string>
#include <vector>

#include "host/scene.h"

namespace saarcor::host {

// Writes `scene` to `path`: binary glTF when the name ends in .glb, otherwise .gltf with its
// buffers and images embedded. Objects become meshes (one primitive per run of equal material, so
// triangle order and ids survive), instances nodes that share them, textures PNG images,
// animations one clip. The file is written under a temporary name and renamed, so a failure never
// leaves a partial file. Throws std::runtime_error with one line.
void export_gltf(const Scene& scene, const std::string& path);

// Encodes an RGBA8 texture as PNG in memory (OpenImageIO).
std::vector<unsigned char> encode_png(const Texture& texture);

}  // namespace saarcor::host
