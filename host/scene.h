// The host's scene: objects (one per glTF mesh, in the mesh's own space), instances of them with
// world transforms, materials, textures, lights and cameras (docs/memory-image.md and
// docs/shading.md; paper section 2: objects that move under one affine transformation, instanced
// into a top level). This is host data; the hardware never sees it, only the memory image built
// from it. Loading, defaults and the built-in scenes are described in docs/scenes.md.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <string>
#include <vector>

#include "host/kdtree.h"

namespace saarcor::host {

struct Texture {
  std::string name;  // file name or "embedded:N"
  int width = 0;
  int height = 0;
  // RGBA8 (R in bits 0-7, G 8-15, B 16-23, A 24-31), row-major, row 0 at the top (texture v = 0),
  // values as stored in the file (sRGB-encoded for glTF base colour textures).
  std::vector<std::uint32_t> rgba;
};

struct Material {
  std::string name;
  glm::vec4 base_color{1.0f};  // linear RGBA factor
  int texture = -1;            // index into Scene::textures, -1 = none
  float metallic = 0.0f;
  float roughness = 1.0f;
  // The fixed-function shader's terms, derived from metallic/roughness by
  // derive_fixed_function_terms() (docs/scenes.md, "Materials").
  glm::vec3 specular{0.0f};
  float shininess = 1.0f;
  float reflectivity = 0.0f;
  float transparency = 0.0f;
  // Glass: glTF KHR_materials_transmission's transmissionFactor (an input, like metallic) and
  // KHR_materials_ior's index of refraction of the material's inside (outside: 1, vacuum). The
  // shader's refraction weight is derived from them (docs/shading.md section 7).
  float transmission = 0.0f;
  float ior = 1.5f;
  float refraction = 0.0f;
};

// One object: a triangle mesh in its own coordinate space with its own bottom-level kd-tree.
// Triangle i is (indices[i].x, .y, .z): A, B, C of the paper's unit-triangle transform.
// Degenerate triangles keep their slot (so triangle ids stay the mesh's own numbering) and are
// marked; they get no matrix and are never put in a kd-tree list.
struct Object {
  std::string name;
  std::vector<glm::vec3> positions;
  std::vector<glm::vec2> texcoords;  // per vertex; empty when the mesh has none
  std::vector<glm::vec3> normals;    // per vertex, unit; empty when the mesh has none
  std::vector<glm::uvec3> triangles;
  std::vector<std::uint32_t> material;   // per triangle: index into Scene::materials
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
  int node = -1;          // Scene::nodes index that places it, -1 = fixed world position
};

struct Camera {
  glm::vec3 position{0.0f, 0.0f, 5.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};  // unit
  glm::vec3 up{0.0f, 1.0f, 0.0f};        // unit, orthogonal to forward
  float yfov = 0.785398163f;             // vertical field of view, radians
  std::string name;
  int node = -1;  // Scene::nodes index that places it, -1 = fixed world position
};

// A node of the hierarchy. Built-in scenes use one root node per instance.
struct Node {
  std::string name;
  int parent = -1;
  std::vector<int> children;
  int object = -1;  // Scene::objects index (glTF mesh), -1 = none
  int camera = -1;  // index of the camera this node places, or -1
  int light = -1;   // index of the light this node places, or -1
  // The local transform: `matrix` when use_trs is false, else T * R * S. Animations override the
  // T, R and S parts of a TRS node.
  bool use_trs = true;
  glm::dmat4 matrix{1.0};
  glm::dvec3 translation{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  // w, x, y, z
  glm::dvec3 scale{1.0};
  bool animated = false;  // it or an ancestor is the target of an animation channel
};

enum class AnimPath { kTranslation, kRotation, kScale };
enum class AnimInterpolation { kLinear, kStep, kCubicSpline };

// One animation channel with its sampler. values holds one vec4 per key (xyz for translation and
// scale, xyzw quaternion for rotation); a CUBICSPLINE sampler keeps only the middle value of each
// (in-tangent, value, out-tangent) triple and is interpolated linearly (docs/scenes.md).
struct AnimChannel {
  int node = 0;
  AnimPath path = AnimPath::kTranslation;
  AnimInterpolation interpolation = AnimInterpolation::kLinear;
  std::vector<double> times;  // ascending, seconds
  std::vector<glm::dvec4> values;
};

struct Scene {
  std::string source;  // the spec it was loaded from
  std::vector<Object> objects;
  std::vector<Instance> instances;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<Light> lights;
  std::vector<Camera> cameras;  // perspective cameras of the default scene, traversal order
  std::vector<Node> nodes;
  std::vector<int> roots;  // root nodes of the default scene
  std::vector<AnimChannel> animations;
  double animation_seconds = 0.0;        // end time of the longest channel, 0 = static
  double time = 0.0;                     // the time the transforms were last evaluated at
  bool light_defaulted = false;          // lights holds only the default light (the file has none)
  std::uint64_t skipped_primitives = 0;  // non-triangle primitives skipped
  std::vector<std::string> warnings;     // one line each, no duplicates

  // Triangle slots (degenerate ones included): stored once per object, and after instancing.
  std::uint64_t unique_triangles() const;
  std::uint64_t instanced_triangles() const;
  // Degenerate triangles (no inverse T_delta): stored once per object, and after instancing.
  std::uint64_t dropped_triangles() const;
  std::uint64_t instanced_dropped_triangles() const;

  // Re-evaluates every animated node at time t (seconds, clamped to [0, animation_seconds]) and
  // updates the world transforms of instances, cameras and lights placed by nodes.
  void set_time(double t);

  void warn(const std::string& line);  // appends unless already present
};

// Loads `spec`: a glTF file (.gltf or .glb) or `builtin:NAME`. Throws std::runtime_error with one
// line naming the problem. The result is evaluated at time 0 and has at least one light.
Scene load_scene(const std::string& spec);

// World-space bounds of every instance (object bounds' corners transformed; conservative).
Aabb world_bounds(const Scene& scene);
// The framing used when a scene has no camera: looking along -Z at the centre of the world
// bounds, from the distance where the bounding sphere fits the 45-degree vertical field of view.
Camera default_camera(const Scene& scene);
// The camera a render uses: the scene's first camera, else default_camera().
Camera scene_camera(const Scene& scene);
// The light used when a scene has none: white, at the default camera's position plus half the
// bounding-sphere radius up (+Y).
Light default_light(const Scene& scene);
// Adds default_light() when scene.lights is empty and records it in light_defaulted.
void ensure_light(Scene& scene);

// Marks degenerate triangles of `object` (fills object.degenerate): zero or relatively tiny area,
// |(B-A) x (C-A)| <= kDegenerateRelativeArea * (longest edge)^2 in binary64, or a T_delta^-1 that
// does not invert to finite values in binary64.
inline constexpr double kDegenerateRelativeArea = 1e-12;
void mark_degenerate_triangles(Object& object);

// The documented metallic/roughness -> specular/shininess/reflectivity mapping.
void derive_fixed_function_terms(Material& material, bool alpha_blend);

// The node's local transform with the T, R, S parts as currently set.
glm::dmat4 node_local_matrix(const Node& node);

}  // namespace saarcor::host
