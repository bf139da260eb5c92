// glTF 2.0 import through tinygltf, textures through OpenImageIO (README.md "Layout": host/ is
// the one hardware-free library that reads files). Mapping rules are in docs/scenes.md.
#pragma once

#include <cstddef>
#include <string>

#include "host/scene.h"

namespace saarcor::host {

// Loads a .gltf (external or embedded buffers) or .glb file. Each mesh becomes one object (its
// triangle primitives concatenated in order), each node of the default scene that carries a mesh
// one instance (id = node index). The scene is evaluated at time 0; lights are not defaulted here
// (load_scene() does that). Throws std::runtime_error with one line naming the file and problem.
Scene load_gltf(const std::string& path);

// Decodes an encoded image (PNG, JPEG, ... whatever OpenImageIO reads) from memory into RGBA8.
// `name` is used in the error message.
Texture decode_image(const unsigned char* bytes, std::size_t size, const std::string& name);

}  // namespace saarcor::host
