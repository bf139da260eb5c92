// The host's scene: objects (one per glTF mesh, in the mesh's own space), instances of them with
// world transforms, materials, textures, lights and cameras (DESIGN.md sections 4 and 7; paper
// section 2: objects that move under one affine transformation, instanced into a top level).
// This is host data; the hardware never sees it, only the memory image built from it.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

namespace saarcor::host {

struct Texture {
  std::string name;  // file name or "embedded:N"
  int width = 0;
  int height = 0;
  std::vector<std::uint32_t> rgba;  // RGBA8, row-major, row 0 at the top (texture v = 0)
};

struct Material {
  std::string name;
  glm::vec4 base_color{1.0f};  // linear RGBA factor
  int texture = -1;            // index into Scene::textures, -1 = none
  float metallic = 0.0f;
  float roughness = 1.0f;
  // The fixed-function shader's terms, derived from metallic/roughness (docs/shading.md).
  glm::vec3 specular{0.0f};
  float shininess = 1.0f;
  float reflectivity = 0.0f;
  float transparency = 0.0f;
};

// One object: a triangle mesh in its own coordinate space with its own bottom-level kd-tree.
// Triangle i is (indices[i].x, .y, .z): A, B, C of the paper's unit-triangle transform.
// Degenerate triangles keep their slot (so triangle ids stay the mesh's own numbering) and are
// marked; they get no matrix and are never put in a kd-tree list.
struct Object {
  std::string name;
  std::vector<glm::vec3> positions;
  std::vector<glm::vec2> texcoords;  // per vertex; empty when the mesh has none
  std::vector<glm::uvec3> triangles;
  std::vector<std::uint32_t> material;  // per triangle: index into Scene::materials
  std::vector<std::uint8_t> degenerate;  // per triangle: 1 = dropped (no inverse T_delta)
  std::uint32_t dropped_triangles() const;
};

struct Instance {
  std::uint32_t object = 0;
  glm::dmat4 object_to_world{1.0};  // binary64: the host inverts it before rounding once
  std::uint32_t id = 0;             // glTF node index (built-in scenes: instance index)
  bool dynamic = false;             // its transform changes over time
};

struct Light {
  glm::vec3 position{0.0f};
  glm::vec3 color{1.0f};  // RGB intensity, 1 = full
};

struct Camera {
  glm::vec3 position{0.0f, 0.0f, 5.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};  // unit
  glm::vec3 up{0.0f, 1.0f, 0.0f};        // unit, orthogonal to forward
  float yfov = 0.785398163f;             // vertical field of view, radians
};

}  // namespace saarcor::host
