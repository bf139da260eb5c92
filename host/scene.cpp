// Scene-wide operations: counts, animation sampling (set_time), the default camera and light, and
// the degenerate-triangle test shared by every loader (docs/memory-image.md: degenerate triangles
// are dropped by the host and counted; paper section 2: dynamic objects move under one affine
// transformation each, so only instance matrices change over time).
#include "host/scene.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <stdexcept>

#include "host/aff_loader.h"
#include "host/builtin_scenes.h"
#include "host/gltf_loader.h"

namespace saarcor::host {

std::uint32_t Object::dropped_triangles() const {
  return static_cast<std::uint32_t>(std::count(degenerate.begin(), degenerate.end(), 1));
}

std::uint64_t Scene::unique_triangles() const {
  std::uint64_t n = 0;
  for (const Object& o : objects)
    n += o.triangles.size();
  return n;
}

std::uint64_t Scene::instanced_triangles() const {
  std::uint64_t n = 0;
  for (const Instance& i : instances)
    n += objects.at(i.object).triangles.size();
  return n;
}

std::uint64_t Scene::dropped_triangles() const {
  std::uint64_t n = 0;
  for (const Object& o : objects)
    n += o.dropped_triangles();
  return n;
}

std::uint64_t Scene::instanced_dropped_triangles() const {
  std::vector<std::uint32_t> per_object(objects.size());
  for (std::size_t i = 0; i < objects.size(); ++i)
    per_object[i] = objects[i].dropped_triangles();
  std::uint64_t n = 0;
  for (const Instance& i : instances)
    n += per_object.at(i.object);
  return n;
}

void Scene::warn(const std::string& line) {
  if (std::find(warnings.begin(), warnings.end(), line) == warnings.end()) warnings.push_back(line);
}

glm::dmat4 node_local_matrix(const Node& node) {
  if (!node.use_trs) return node.matrix;
  const glm::dmat4 t = glm::translate(glm::dmat4(1.0), node.translation);
  const glm::dmat4 r = glm::mat4_cast(node.rotation);
  const glm::dmat4 s = glm::scale(glm::dmat4(1.0), node.scale);
  return t * r * s;
}

namespace {

// Index of the last key at or before t (times ascending, t inside [times.front(), times.back()]).
std::size_t key_before(const std::vector<double>& times, double t) {
  const auto it = std::upper_bound(times.begin(), times.end(), t);
  return it == times.begin() ? 0 : static_cast<std::size_t>(it - times.begin()) - 1;
}

glm::dvec4 sample(const AnimChannel& ch, double t) {
  const std::size_t n = ch.times.size();
  if (t <= ch.times.front()) return ch.values.front();
  if (t >= ch.times.back()) return ch.values[n - 1];
  const std::size_t k = key_before(ch.times, t);
  if (ch.interpolation == AnimInterpolation::kStep || k + 1 >= n) return ch.values[k];
  const double t0 = ch.times[k];
  const double t1 = ch.times[k + 1];
  const double s = t1 > t0 ? (t - t0) / (t1 - t0) : 0.0;
  const glm::dvec4& a = ch.values[k];
  const glm::dvec4& b = ch.values[k + 1];
  if (ch.path == AnimPath::kRotation) {
    // glTF: spherical linear interpolation of unit quaternions, the shorter way.
    glm::dquat qa(a.w, a.x, a.y, a.z);
    glm::dquat qb(b.w, b.x, b.y, b.z);
    qa = glm::normalize(qa);
    qb = glm::normalize(qb);
    const glm::dquat q = glm::normalize(glm::slerp(qa, qb, s));
    return {q.x, q.y, q.z, q.w};
  }
  return a + (b - a) * s;
}

}  // namespace

void Scene::set_time(double t) {
  time = std::clamp(t, 0.0, animation_seconds);
  for (const AnimChannel& ch : animations) {
    if (ch.times.empty()) continue;
    Node& node = nodes.at(static_cast<std::size_t>(ch.node));
    const glm::dvec4 v = sample(ch, time);
    switch (ch.path) {
      case AnimPath::kTranslation:
        node.translation = glm::dvec3(v);
        break;
      case AnimPath::kScale:
        node.scale = glm::dvec3(v);
        break;
      case AnimPath::kRotation:
        node.rotation = glm::dquat(v.w, v.x, v.y, v.z);
        break;
    }
  }
  // World matrices, parents before children (roots first, depth-first).
  std::vector<glm::dmat4> world(nodes.size(), glm::dmat4(1.0));
  std::vector<std::uint8_t> done(nodes.size(), 0);
  std::vector<std::pair<int, glm::dmat4>> stack;
  for (auto r = roots.rbegin(); r != roots.rend(); ++r)
    stack.emplace_back(*r, glm::dmat4(1.0));
  while (!stack.empty()) {
    const auto [n, parent] = stack.back();
    stack.pop_back();
    const auto un = static_cast<std::size_t>(n);
    if (done[un]) continue;  // a node reached twice (not a tree) keeps its first placement
    done[un] = 1;
    world[un] = parent * node_local_matrix(nodes[un]);
    const Node& node = nodes[un];
    for (auto c = node.children.rbegin(); c != node.children.rend(); ++c)
      stack.emplace_back(*c, world[un]);
  }
  for (Instance& inst : instances) {
    if (inst.id < nodes.size()) {
      inst.object_to_world = world[inst.id];
      inst.dynamic = nodes[inst.id].animated;
    }
  }
  for (Camera& cam : cameras) {
    if (cam.node < 0) continue;
    const glm::dmat4& m = world[static_cast<std::size_t>(cam.node)];
    cam.position = glm::vec3(glm::dvec3(m[3]));
    // glTF cameras look down their local -Z with +Y up.
    const glm::dvec3 f = -glm::dvec3(m[2]);
    const glm::dvec3 u = glm::dvec3(m[1]);
    const glm::dvec3 fn = glm::normalize(f);
    const glm::dvec3 un = glm::normalize(u - fn * glm::dot(u, fn));
    cam.forward = glm::vec3(fn);
    cam.up = glm::vec3(un);
  }
  for (Light& light : lights) {
    if (light.node >= 0)
      light.position = glm::vec3(glm::dvec3(world[static_cast<std::size_t>(light.node)][3]));
  }
}

Aabb world_bounds(const Scene& scene) {
  std::vector<Aabb> local(scene.objects.size());
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const Object& o = scene.objects[i];
    // Only vertices that triangles use: a mesh may carry unused vertices.
    for (const glm::uvec3& t : o.triangles)
      for (int k = 0; k < 3; ++k)
        local[i].grow(o.positions[t[k]]);
  }
  Aabb box;
  for (const Instance& inst : scene.instances) {
    const Aabb& b = local.at(inst.object);
    if (b.empty()) continue;
    for (int c = 0; c < 8; ++c) {
      const glm::dvec4 p((c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y,
                         (c & 4) ? b.hi.z : b.lo.z, 1.0);
      box.grow(glm::vec3(glm::dvec3(inst.object_to_world * p)));
    }
  }
  return box;
}

Camera default_camera(const Scene& scene) {
  Camera cam;
  cam.name = "default";
  const Aabb b = world_bounds(scene);
  glm::dvec3 centre(0.0);
  double radius = 1.0;
  if (!b.empty()) {
    centre = (glm::dvec3(b.lo) + glm::dvec3(b.hi)) * 0.5;
    radius = std::max(glm::length(glm::dvec3(b.hi) - glm::dvec3(b.lo)) * 0.5, 1e-6);
  }
  const double yfov = 0.785398163397448;  // 45 degrees, the paper's frustum
  const double distance = radius / std::sin(yfov * 0.5);
  cam.position = glm::vec3(centre + glm::dvec3(0.0, 0.0, distance));
  cam.forward = {0.0f, 0.0f, -1.0f};
  cam.up = {0.0f, 1.0f, 0.0f};
  cam.yfov = static_cast<float>(yfov);
  return cam;
}

Camera scene_camera(const Scene& scene) {
  return scene.cameras.empty() ? default_camera(scene) : scene.cameras.front();
}

Light default_light(const Scene& scene) {
  const Aabb b = world_bounds(scene);
  const double radius =
      b.empty() ? 1.0 : std::max(glm::length(glm::dvec3(b.hi) - glm::dvec3(b.lo)) * 0.5, 1e-6);
  Light light;
  light.position =
      default_camera(scene).position + glm::vec3(0.0f, static_cast<float>(radius * 0.5), 0.0f);
  light.color = glm::vec3(1.0f);
  return light;
}

void ensure_light(Scene& scene) {
  if (!scene.lights.empty()) return;
  scene.lights.push_back(default_light(scene));
  scene.light_defaulted = true;
}

void mark_degenerate_triangles(Object& object) {
  object.degenerate.assign(object.triangles.size(), 0);
  for (std::size_t i = 0; i < object.triangles.size(); ++i) {
    const glm::uvec3& t = object.triangles[i];
    const glm::dvec3 a(object.positions[t.x]);
    const glm::dvec3 b(object.positions[t.y]);
    const glm::dvec3 c(object.positions[t.z]);
    const glm::dvec3 cr = glm::cross(b - a, c - a);
    const double twice_area = glm::length(cr);
    const double longest =
        std::max({glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c)});
    bool bad = !(twice_area > kDegenerateRelativeArea * longest) || !(longest > 0.0);
    if (!bad) {
      // T_delta^-1 = [A-C, B-C, N] (docs/memory-image.md erratum): its determinant is
      // (A-C) x (B-C) . N; the inverse must come out finite in binary64.
      const glm::dvec3 n = cr / twice_area;
      const glm::dmat3 m(a - c, b - c, n);
      const double det = glm::determinant(m);
      const glm::dmat3 inv = glm::inverse(m);
      bad = !(std::abs(det) > 0.0) || !std::isfinite(det);
      for (int col = 0; col < 3 && !bad; ++col)
        for (int row = 0; row < 3 && !bad; ++row)
          bad = !std::isfinite(inv[col][row]);
    }
    object.degenerate[i] = bad ? 1 : 0;
  }
}

void derive_fixed_function_terms(Material& m, bool alpha_blend) {
  const float rough = std::clamp(m.roughness, 0.0f, 1.0f);
  const float metal = std::clamp(m.metallic, 0.0f, 1.0f);
  const glm::vec3 base(m.base_color);
  // Dielectrics reflect about 4% at normal incidence, metals their base colour (the usual
  // Fresnel F0); rough surfaces spread it into a highlight too dim for a Phong lobe.
  const glm::vec3 f0 = glm::vec3(0.04f) * (1.0f - metal) + base * metal;
  m.specular = f0 * (1.0f - rough);
  // Blinn-Phong exponent matching a GGX lobe of alpha = roughness^2: n = 2 / alpha^2 - 2.
  const double alpha = std::max(static_cast<double>(rough) * rough, 1e-2);
  m.shininess = static_cast<float>(std::clamp(2.0 / (alpha * alpha) - 2.0, 1.0, 256.0));
  m.reflectivity = metal * (1.0f - rough);
  m.transparency = alpha_blend ? std::clamp(1.0f - m.base_color.a, 0.0f, 1.0f) : 0.0f;
  // Transmission is the dielectric's share (KHR_materials_transmission: metals do not transmit),
  // so reflectivity + refraction <= 1.
  m.refraction = std::clamp(m.transmission, 0.0f, 1.0f) * (1.0f - metal);
}

Scene load_scene(const std::string& spec) {
  Scene scene;
  const std::string prefix = "builtin:";
  if (spec.rfind(prefix, 0) == 0) {
    scene = make_builtin_scene(spec.substr(prefix.size()));
  } else if (spec.ends_with(".aff") || spec.ends_with(".AFF")) {
    scene = load_aff(spec);
  } else {
    scene = load_gltf(spec);
  }
  scene.source = spec;
  scene.set_time(0.0);
  ensure_light(scene);
  return scene;
}

}  // namespace saarcor::host
