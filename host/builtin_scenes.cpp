// Built-in procedural scenes, stand-ins for the paper's benchmarks (paper section 5, Table 3;
// decision D42): the same triangle and object counts, generated deterministically (own
// generator, fixed seeds, no hash-map iteration) so a scene name always gives the same bytes.
#include "host/builtin_scenes.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <glm/gtc/matrix_transform.hpp>
#include <stdexcept>

namespace saarcor::host {

namespace {

constexpr double kPi = 3.14159265358979323846;

// SplitMix64: tiny, fast and identical on every platform (std distributions are not).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : s_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0); }
  double range(double lo, double hi) { return lo + (hi - lo) * uniform(); }

 private:
  std::uint64_t s_;
};

void basis(const glm::dvec3& axis, glm::dvec3& e1, glm::dvec3& e2) {
  const glm::dvec3 a = glm::normalize(axis);
  const glm::dvec3 helper = std::abs(a.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
  e1 = glm::normalize(glm::cross(helper, a));
  e2 = glm::cross(a, e1);
}

class MeshBuilder {
 public:
  explicit MeshBuilder(std::string name) { obj_.name = std::move(name); }

  std::uint32_t vertex(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec2& uv) {
    obj_.positions.emplace_back(p);
    const double len = glm::length(n);
    obj_.normals.emplace_back(len > 0.0 ? n / len : glm::dvec3(0, 1, 0));
    obj_.texcoords.emplace_back(uv);
    return static_cast<std::uint32_t>(obj_.positions.size() - 1);
  }
  void tri(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t mat) {
    obj_.triangles.emplace_back(a, b, c);
    obj_.material.push_back(mat);
  }
  // A grid over a parametric surface f(s, t), s, t in [0, 1]: 2 * nu * nv triangles.
  void surface(const std::function<glm::dvec3(double, double)>& f, int nu, int nv,
               std::uint32_t mat, glm::dvec2 uv_repeat = {1.0, 1.0}) {
    const auto base = static_cast<std::uint32_t>(obj_.positions.size());
    const double h = 1e-4;
    for (int j = 0; j <= nv; ++j) {
      for (int i = 0; i <= nu; ++i) {
        const double s = static_cast<double>(i) / nu;
        const double t = static_cast<double>(j) / nv;
        const glm::dvec3 ds = f(std::min(s + h, 1.0), t) - f(std::max(s - h, 0.0), t);
        const glm::dvec3 dt = f(s, std::min(t + h, 1.0)) - f(s, std::max(t - h, 0.0));
        vertex(f(s, t), glm::cross(ds, dt), glm::dvec2(s * uv_repeat.x, t * uv_repeat.y));
      }
    }
    const auto row = static_cast<std::uint32_t>(nu + 1);
    for (int j = 0; j < nv; ++j) {
      for (int i = 0; i < nu; ++i) {
        const std::uint32_t v00 =
            base + static_cast<std::uint32_t>(j) * row + static_cast<std::uint32_t>(i);
        const std::uint32_t v10 = v00 + 1;
        const std::uint32_t v01 = v00 + row;
        const std::uint32_t v11 = v01 + 1;
        tri(v00, v10, v11, mat);
        tri(v00, v11, v01, mat);
      }
    }
  }
  // A planar grid from origin spanned by u and v (normal u x v): 2 * nu * nv triangles.
  void grid(const glm::dvec3& origin, const glm::dvec3& u, const glm::dvec3& v, int nu, int nv,
            std::uint32_t mat, glm::dvec2 uv_repeat = {1.0, 1.0}) {
    surface([&](double s, double t) { return origin + u * s + v * t; }, nu, nv, mat, uv_repeat);
  }
  // An axis-aligned box with outward faces: 12 triangles.
  void box(const glm::dvec3& lo, const glm::dvec3& hi, std::uint32_t mat) {
    const glm::dvec3 d = hi - lo;
    const glm::dvec3 x(d.x, 0, 0), y(0, d.y, 0), z(0, 0, d.z);
    grid(lo, x, z, 1, 1, mat);      // bottom (-y)
    grid(lo + y, z, x, 1, 1, mat);  // top (+y)
    grid(lo, y, x, 1, 1, mat);      // front (-z)
    grid(lo + z, x, y, 1, 1, mat);  // back (+z)
    grid(lo, z, y, 1, 1, mat);      // left (-x)
    grid(lo + x, y, z, 1, 1, mat);  // right (+x)
  }
  // A tube along a curve c(t) with radius r(t): 2 * n * rings triangles (no caps).
  void tube(const std::function<glm::dvec3(double)>& c, const std::function<double(double)>& r,
            const glm::dvec3& axis, int n, int rings, std::uint32_t mat) {
    glm::dvec3 e1, e2;
    basis(axis, e1, e2);
    surface(
        [&](double s, double t) {
          const double a = 2.0 * kPi * s;
          return c(t) + (e1 * std::cos(a) + e2 * std::sin(a)) * r(t);
        },
        n, rings, mat);
  }
  // A closed cylinder: 2n side + 2n cap triangles = 4n.
  void cylinder(const glm::dvec3& base, const glm::dvec3& axis, double radius, int n,
                std::uint32_t mat) {
    tube([&](double t) { return base + axis * t; }, [&](double) { return radius; }, axis, n, 1,
         mat);
    disc(base, -axis, radius, n, mat);
    disc(base + axis, axis, radius, n, mat);
  }
  // A fan of n triangles around centre + normal-facing rim.
  void disc(const glm::dvec3& centre, const glm::dvec3& normal, double radius, int n,
            std::uint32_t mat, const glm::dvec3& apex_offset = glm::dvec3(0.0)) {
    glm::dvec3 e1, e2;
    basis(normal, e1, e2);
    const std::uint32_t c = vertex(centre + apex_offset, normal, {0.5, 0.5});
    std::vector<std::uint32_t> rim;
    for (int i = 0; i < n; ++i) {
      const double a = 2.0 * kPi * i / n;
      const glm::dvec3 d = e1 * std::cos(a) + e2 * std::sin(a);
      rim.push_back(
          vertex(centre + d * radius, normal, {0.5 + 0.5 * std::cos(a), 0.5 + 0.5 * std::sin(a)}));
    }
    for (int i = 0; i < n; ++i)
      tri(c, rim[static_cast<std::size_t>(i)], rim[static_cast<std::size_t>((i + 1) % n)], mat);
  }
  // A cone: n side + n base triangles.
  void cone(const glm::dvec3& base, const glm::dvec3& axis, double radius, int n,
            std::uint32_t mat) {
    disc(base, axis, radius, n, mat, axis);
    disc(base, -axis, radius, n, mat);
  }
  // A UV sphere: 2 * slices * (stacks - 1) triangles (the pole rows are single triangles).
  void sphere(const glm::dvec3& centre, const glm::dvec3& radii, int slices, int stacks,
              std::uint32_t mat) {
    const auto base = static_cast<std::uint32_t>(obj_.positions.size());
    for (int j = 0; j <= stacks; ++j) {
      const double phi = kPi * j / stacks;
      for (int i = 0; i <= slices; ++i) {
        const double th = 2.0 * kPi * i / slices;
        const glm::dvec3 d(std::sin(phi) * std::cos(th), std::cos(phi),
                           std::sin(phi) * std::sin(th));
        vertex(centre + d * radii, d / radii,
               {static_cast<double>(i) / slices, static_cast<double>(j) / stacks});
      }
    }
    const auto row = static_cast<std::uint32_t>(slices + 1);
    for (int j = 0; j < stacks; ++j) {
      for (int i = 0; i < slices; ++i) {
        const std::uint32_t v00 =
            base + static_cast<std::uint32_t>(j) * row + static_cast<std::uint32_t>(i);
        const std::uint32_t v10 = v00 + 1, v01 = v00 + row, v11 = v01 + 1;
        if (j != 0) tri(v00, v10, v11, mat);
        if (j != stacks - 1) tri(v00, v11, v01, mat);
      }
    }
  }
  std::size_t triangles() const { return obj_.triangles.size(); }
  Object finish() {
    mark_degenerate_triangles(obj_);
    return std::move(obj_);
  }

 private:
  Object obj_;
};

std::uint32_t add_material(Scene& s, const std::string& name, glm::vec3 color, float metallic,
                           float roughness, int texture = -1) {
  Material m;
  m.name = name;
  m.base_color = glm::vec4(color, 1.0f);
  m.metallic = metallic;
  m.roughness = roughness;
  m.texture = texture;
  derive_fixed_function_terms(m, false);
  s.materials.push_back(m);
  return static_cast<std::uint32_t>(s.materials.size() - 1);
}

std::uint32_t rgba(double r, double g, double b) {
  const auto c = [](double v) {
    return static_cast<std::uint32_t>(std::clamp(v, 0.0, 1.0) * 255.0 + 0.5);
  };
  return c(r) | (c(g) << 8) | (c(b) << 16) | (255u << 24);
}

int add_texture(Scene& s, const std::string& name, int size,
                const std::function<glm::dvec3(int, int)>& texel) {
  Texture t;
  t.name = name;
  t.width = size;
  t.height = size;
  t.rgba.resize(static_cast<std::size_t>(size) * static_cast<std::size_t>(size));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const glm::dvec3 c = texel(x, y);
      t.rgba[static_cast<std::size_t>(y * size + x)] = rgba(c.x, c.y, c.z);
    }
  s.textures.push_back(std::move(t));
  return static_cast<int>(s.textures.size() - 1);
}

// One root node per instance (id = node index = instance index).
void add_instance(Scene& s, std::uint32_t object, const glm::dmat4& m, const std::string& name) {
  Node node;
  node.name = name;
  node.object = static_cast<int>(object);
  node.use_trs = false;
  node.matrix = m;
  const int index = static_cast<int>(s.nodes.size());
  s.nodes.push_back(node);
  s.roots.push_back(index);
  Instance inst;
  inst.object = object;
  inst.object_to_world = m;
  inst.id = static_cast<std::uint32_t>(index);
  s.instances.push_back(inst);
}

std::uint32_t add_object(Scene& s, MeshBuilder& b) {
  s.objects.push_back(b.finish());
  return static_cast<std::uint32_t>(s.objects.size() - 1);
}

Camera look_at(const glm::dvec3& eye, const glm::dvec3& target, const std::string& name) {
  Camera c;
  c.name = name;
  c.position = glm::vec3(eye);
  const glm::dvec3 f = glm::normalize(target - eye);
  const glm::dvec3 up0(0, 1, 0);
  c.forward = glm::vec3(f);
  c.up = glm::vec3(glm::normalize(up0 - f * glm::dot(up0, f)));
  c.yfov = static_cast<float>(kPi / 4.0);
  return c;
}

Light light_at(const glm::dvec3& p, const glm::dvec3& color) {
  Light l;
  l.position = glm::vec3(p);
  l.color = glm::vec3(color);
  return l;
}

// Value noise on an integer lattice, smoothly interpolated; deterministic for a given seed.
double lattice(int x, int y, std::uint64_t seed) {
  std::uint64_t h =
      seed ^ (static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) * 0x9E3779B97F4A7C15ull) ^
      (static_cast<std::uint64_t>(static_cast<std::uint32_t>(y)) * 0xC2B2AE3D27D4EB4Full);
  Rng r(h);
  return r.uniform();
}

double value_noise(double x, double y, std::uint64_t seed) {
  const double fx = std::floor(x), fy = std::floor(y);
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  const double tx = x - fx, ty = y - fy;
  const double sx = tx * tx * (3 - 2 * tx), sy = ty * ty * (3 - 2 * ty);
  const double a = lattice(ix, iy, seed), b = lattice(ix + 1, iy, seed);
  const double c = lattice(ix, iy + 1, seed), d = lattice(ix + 1, iy + 1, seed);
  return (a + (b - a) * sx) + ((c + (d - c) * sx) - (a + (b - a) * sx)) * sy;
}

// ---- builtin:triangle, builtin:cube -------------------------------------------------------------

Scene make_triangle() {
  Scene s;
  const std::uint32_t mat = add_material(s, "white", {0.9f, 0.9f, 0.9f}, 0.0f, 1.0f);
  MeshBuilder b("triangle");
  const std::uint32_t v0 = b.vertex({-1, -1, 0}, {0, 0, 1}, {0, 0});
  const std::uint32_t v1 = b.vertex({1, -1, 0}, {0, 0, 1}, {1, 0});
  const std::uint32_t v2 = b.vertex({0, 1, 0}, {0, 0, 1}, {0.5, 1});
  b.tri(v0, v1, v2, mat);
  add_instance(s, add_object(s, b), glm::dmat4(1.0), "triangle");
  s.cameras.push_back(look_at({0, 0, 3}, {0, 0, 0}, "front"));
  s.lights.push_back(light_at({0, 1, 3}, {1, 1, 1}));
  return s;
}

Scene make_cube() {
  Scene s;
  const int tex = add_texture(s, "checker", 16, [](int x, int y) {
    return ((x / 4 + y / 4) % 2) ? glm::dvec3(0.9, 0.9, 0.9) : glm::dvec3(0.2, 0.3, 0.8);
  });
  const std::uint32_t mat = add_material(s, "checker", {1, 1, 1}, 0.0f, 0.6f, tex);
  MeshBuilder b("cube");
  b.box({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}, mat);
  add_instance(s, add_object(s, b), glm::rotate(glm::dmat4(1.0), 0.5, glm::dvec3(0.3, 1.0, 0.1)),
               "cube");
  s.cameras.push_back(look_at({1.2, 1.0, 2.5}, {0, 0, 0}, "front"));
  s.lights.push_back(light_at({2, 3, 3}, {1, 1, 1}));
  return s;
}

// The inside of a box-shaped room spanning [-w, w] x [0, h] x [-w, w]: the floor as cells x cells
// textured quads, the ceiling and the four walls one quad each (builtin:room, builtin:glass).
struct RoomShell {
  double w, h;
  int floor_cells;
  glm::dvec2 floor_uv;
  std::uint32_t floor, ceiling, back, walls;
  glm::dvec2 back_uv{1.0, 1.0};
};

void add_room_shell(MeshBuilder& b, const RoomShell& r) {
  const double w = r.w, h = r.h;
  const int n = r.floor_cells;
  b.grid({-w, 0, w}, {2 * w, 0, 0}, {0, 0, -2 * w}, n, n, r.floor, r.floor_uv);  // 2 n^2
  b.grid({-w, h, -w}, {2 * w, 0, 0}, {0, 0, 2 * w}, 1, 1, r.ceiling);            // 2
  b.grid({-w, 0, -w}, {2 * w, 0, 0}, {0, h, 0}, 1, 1, r.back, r.back_uv);        // back, 2
  b.grid({w, 0, w}, {-2 * w, 0, 0}, {0, h, 0}, 1, 1, r.walls);                   // front, 2
  b.grid({-w, 0, w}, {0, 0, -2 * w}, {0, h, 0}, 1, 1, r.walls);                  // left, 2
  b.grid({w, 0, -w}, {0, 0, 2 * w}, {0, h, 0}, 1, 1, r.walls);                   // right, 2
}

// ---- builtin:room (Scene6: "a simple room with table and chairs", 806 triangles, 1 object) -----

Scene make_room() {
  Scene s;
  const int checker = add_texture(s, "floor_checker", 64, [](int x, int y) {
    const bool dark = ((x / 8) + (y / 8)) % 2 == 1;
    const double grain = 0.04 * std::sin(0.7 * x + 0.3 * y);
    return dark ? glm::dvec3(0.25 + grain, 0.18 + grain, 0.12)
                : glm::dvec3(0.85 + grain, 0.80 + grain, 0.70);
  });
  const std::uint32_t floor_m = add_material(s, "floor", {1, 1, 1}, 0.0f, 0.5f, checker);
  const std::uint32_t wall_m = add_material(s, "wall", {0.85f, 0.80f, 0.65f}, 0.0f, 1.0f);
  const std::uint32_t ceil_m = add_material(s, "ceiling", {0.95f, 0.95f, 0.95f}, 0.0f, 1.0f);
  const std::uint32_t wood_m = add_material(s, "table_wood", {0.45f, 0.28f, 0.12f}, 0.0f, 0.4f);
  const std::uint32_t chair_m = add_material(s, "chair", {0.60f, 0.10f, 0.08f}, 0.0f, 0.7f);
  const std::uint32_t vase_m = add_material(s, "vase", {0.15f, 0.30f, 0.75f}, 0.3f, 0.15f);

  MeshBuilder b("room");
  add_room_shell(b, {3.0, 3.0, 12, {6, 6}, floor_m, ceil_m, wall_m, wall_m});  // 288 + 10
  // Table: top and four legs (60).
  const glm::dvec3 tc(0, 0, -0.5);
  b.box(tc + glm::dvec3(-0.8, 0.72, -0.45), tc + glm::dvec3(0.8, 0.78, 0.45), wood_m);
  for (int i = 0; i < 4; ++i) {
    const double x = (i & 1) ? 0.7 : -0.7, z = (i & 2) ? 0.35 : -0.35;
    b.box(tc + glm::dvec3(x - 0.04, 0, z - 0.04), tc + glm::dvec3(x + 0.04, 0.72, z + 0.04),
          wood_m);
  }
  // Four chairs: seat, four legs, back (4 x 72 = 288).
  for (int c = 0; c < 4; ++c) {
    const double side = (c & 1) ? 1.0 : -1.0;
    const glm::dvec3 cc =
        tc + glm::dvec3((c & 2) ? 0.4 * side : 1.15 * side, 0, (c & 2) ? 0.75 * side : 0.0);
    const bool along_x = (c & 2) == 0;  // chairs at the ends face along x
    b.box(cc + glm::dvec3(-0.22, 0.42, -0.22), cc + glm::dvec3(0.22, 0.46, 0.22), chair_m);
    for (int i = 0; i < 4; ++i) {
      const double x = (i & 1) ? 0.18 : -0.18, z = (i & 2) ? 0.18 : -0.18;
      b.box(cc + glm::dvec3(x - 0.025, 0, z - 0.025), cc + glm::dvec3(x + 0.025, 0.42, z + 0.025),
            chair_m);
    }
    if (along_x) {
      const double x = 0.2 * side;
      b.box(cc + glm::dvec3(x - 0.02, 0.46, -0.22), cc + glm::dvec3(x + 0.02, 0.95, 0.22), chair_m);
    } else {
      const double z = 0.2 * side;
      b.box(cc + glm::dvec3(-0.22, 0.46, z - 0.02), cc + glm::dvec3(0.22, 0.95, z + 0.02), chair_m);
    }
  }
  // A vase on the table (160).
  b.cylinder(tc + glm::dvec3(0.2, 0.78, 0.0), {0, 0.3, 0}, 0.08, 40, vase_m);
  add_instance(s, add_object(s, b), glm::dmat4(1.0), "room");
  s.cameras.push_back(look_at({0.4, 1.6, 2.8}, {0, 0.7, -0.5}, "door"));
  s.lights.push_back(light_at({0, 2.8, 0}, {0.9, 0.9, 0.85}));
  s.lights.push_back(light_at({2.2, 2.5, 2.2}, {0.4, 0.4, 0.45}));
  return s;
}

// ---- builtin:suncor (5,622 sunflowers of 33,288 triangles = 187,145,136) ----------------------

Object make_sunflower(std::uint32_t seed_m, std::uint32_t petal_m, std::uint32_t stem_m,
                      std::uint32_t leaf_m) {
  MeshBuilder b("sunflower");
  const glm::dvec3 head(0.0, 1.6, 0.06);
  const glm::dvec3 facing = glm::normalize(glm::dvec3(0.0, 0.3, 1.0));
  glm::dvec3 e1, e2;
  basis(facing, e1, e2);
  const double radius = 0.3;
  // Seeds on Fermat's spiral at the golden angle, each a four-sided pyramid: 7,506 x 4 = 30,024.
  const int seeds = 7506;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  const double half = 0.45 * radius * std::sqrt(kPi / seeds);
  for (int i = 0; i < seeds; ++i) {
    const double r = radius * std::sqrt((i + 0.5) / seeds);
    const double a = i * golden;
    const glm::dvec3 radial = e1 * std::cos(a) + e2 * std::sin(a);
    const glm::dvec3 tangent = -e1 * std::sin(a) + e2 * std::cos(a);
    const double dome = 0.04 * (1.0 - (r / radius) * (r / radius));
    const glm::dvec3 p = head + radial * r + facing * dome;
    const glm::dvec3 apex = p + facing * (0.006 + 0.004 * (1.0 - r / radius));
    std::uint32_t corner[4];
    for (int k = 0; k < 4; ++k) {
      const double sx = (k == 0 || k == 3) ? -1.0 : 1.0, sy = (k < 2) ? -1.0 : 1.0;
      const glm::dvec3 q = p + (radial * sx + tangent * sy) * half;
      corner[k] = b.vertex(q, facing + (q - p) * 50.0, {0.5 + 0.5 * sx, 0.5 + 0.5 * sy});
    }
    const std::uint32_t top = b.vertex(apex, facing, {0.5, 0.5});
    for (int k = 0; k < 4; ++k)
      b.tri(corner[k], corner[(k + 1) % 4], top, seed_m);
  }
  // Back of the head: a shallow cone (64).
  b.disc(head - facing * 0.005, -facing, radius * 1.05, 64, stem_m, -facing * 0.08);
  // 34 petals of 4 x 8 quads (2,176).
  for (int k = 0; k < 34; ++k) {
    const double a = 2.0 * kPi * k / 34 + (k % 2) * 0.05;
    const glm::dvec3 d = e1 * std::cos(a) + e2 * std::sin(a);
    const glm::dvec3 side = -e1 * std::sin(a) + e2 * std::cos(a);
    const double lift = (k % 2) ? 0.01 : -0.01;
    b.surface(
        [&](double s, double t) {
          const double width = 0.05 * std::sin(kPi * (0.15 + 0.85 * s));
          return head + d * (radius * 0.95 + 0.26 * s) + side * ((t - 0.5) * width) +
                 facing * (lift + 0.05 * s * s - 0.01 * (t - 0.5) * (t - 0.5));
        },
        8, 4, petal_m);
  }
  // The stem: a slightly bent tube of 16 x 24 quads (768).
  b.tube([&](double t) { return glm::dvec3(0.05 * std::sin(kPi * t), 1.6 * t, 0.02 * t); },
         [](double t) { return 0.025 - 0.008 * t; }, {0, 1, 0}, 16, 24, stem_m);
  // Two leaves of 8 x 8 quads (256).
  for (int k = 0; k < 2; ++k) {
    const double dir = k ? 1.0 : -1.0;
    const glm::dvec3 root(0.03 * dir, 0.6 + 0.25 * k, 0.01);
    b.surface(
        [&](double s, double t) {
          const double width = 0.09 * std::sin(kPi * s);
          return root + glm::dvec3(dir * 0.35 * s, 0.12 * s - 0.15 * s * s, (t - 0.5) * width) +
                 glm::dvec3(0, 0.03 * (t - 0.5) * (t - 0.5), 0);
        },
        8, 8, leaf_m);
  }
  return b.finish();
}

// SunCOR's field: 75 x 75 grid positions minus the last three, 5,622 sunflowers, each jittered,
// turned and scaled.
struct SunflowerPlace {
  double x, z, yaw, scale;
};
std::vector<SunflowerPlace> sunflower_places() {
  Rng rng(0x5C0Au);
  const int side = 75;
  const double spacing = 0.9;
  std::vector<SunflowerPlace> out;
  for (int i = 0; i < 5622; ++i) {
    const int gx = i % side, gz = i / side;
    SunflowerPlace f{};
    f.x = (gx - side / 2) * spacing + rng.range(-0.3, 0.3);
    f.z = -(gz * spacing) + rng.range(-0.3, 0.3);
    f.yaw = rng.range(-0.5, 0.5);
    f.scale = rng.range(0.8, 1.2);
    out.push_back(f);
  }
  return out;
}

Scene make_suncor() {
  Scene s;
  const std::uint32_t seed_m = add_material(s, "seeds", {0.25f, 0.15f, 0.06f}, 0.0f, 0.9f);
  const std::uint32_t petal_m = add_material(s, "petals", {0.95f, 0.75f, 0.05f}, 0.0f, 0.6f);
  const std::uint32_t stem_m = add_material(s, "stem", {0.20f, 0.45f, 0.12f}, 0.0f, 0.8f);
  const std::uint32_t leaf_m = add_material(s, "leaves", {0.15f, 0.55f, 0.10f}, 0.0f, 0.7f);
  s.objects.push_back(make_sunflower(seed_m, petal_m, stem_m, leaf_m));
  for (const SunflowerPlace& f : sunflower_places()) {
    glm::dmat4 m = glm::translate(glm::dmat4(1.0), {f.x, 0.0, f.z});
    m = glm::rotate(m, f.yaw, {0.0, 1.0, 0.0});
    m = glm::scale(m, glm::dvec3(f.scale));
    add_instance(s, 0, m, "sunflower" + std::to_string(s.instances.size()));
  }
  s.cameras.push_back(look_at({0.0, 3.5, 6.0}, {0.0, 0.5, -20.0}, "field"));
  // Two more views of the same field (`--set image.camera=1|2`), for measuring how much of a
  // frame's work is the view: "above" looks down into the field so that nearly every pixel hits
  // a sunflower (as the paper's 31 shading bytes per pixel suggest of its SunCOR frames, if its
  // misses read nothing), "heads" looks along the rows at head height (docs/fidelity.md).
  s.cameras.push_back(look_at({0.0, 8.0, 4.0}, {0.0, 0.0, -10.0}, "above"));
  s.cameras.push_back(look_at({0.0, 2.2, 4.0}, {0.0, 1.6, -6.0}, "heads"));
  s.lights.push_back(light_at({-30.0, 80.0, 40.0}, {1.0, 0.97, 0.9}));
  return s;
}

// ---- builtin:suncor-wind (SunCOR's field with every instance moving) -------------------------

// The same field in the wind: a gust runs through it along +x, each sunflower sways about its
// base (a tilt of up to 0.12 rad about z, applied after its own yaw), one cycle every 4 s. Every
// one of the 5,622 instances moves every frame: the top level's worst case (paper section 2: the
// top-level index "must be rebuilt whenever any object moves").
Scene make_suncor_wind() {
  Scene s = make_suncor();
  const std::vector<SunflowerPlace> places = sunflower_places();
  const double period = 4.0;
  const int keys = 17;
  s.nodes.clear();
  s.roots.clear();
  s.instances.clear();
  s.animations.reserve(places.size());
  for (const SunflowerPlace& f : places) {
    Node node;
    node.name = "sunflower" + std::to_string(s.nodes.size());
    node.object = 0;
    node.use_trs = true;
    node.animated = true;
    node.translation = {f.x, 0.0, f.z};
    node.scale = glm::dvec3(f.scale);
    const int index = static_cast<int>(s.nodes.size());
    const glm::dquat yaw = glm::angleAxis(f.yaw, glm::dvec3(0.0, 1.0, 0.0));
    AnimChannel rot;
    rot.node = index;
    rot.path = AnimPath::kRotation;
    for (int k = 0; k < keys; ++k) {
      const double t = period * k / (keys - 1);
      const double tilt = 0.12 * std::sin(2.0 * kPi * t / period - 0.15 * f.x);
      const glm::dquat q = glm::angleAxis(tilt, glm::dvec3(0.0, 0.0, 1.0)) * yaw;
      rot.times.push_back(t);
      // binary32 keys, as a glTF file stores them: export and re-load are exact
      rot.values.emplace_back(glm::dvec4(glm::vec4(glm::dvec4(q.x, q.y, q.z, q.w))));
    }
    node.rotation = glm::dquat(rot.values[0].w, rot.values[0].x, rot.values[0].y, rot.values[0].z);
    s.nodes.push_back(node);
    s.roots.push_back(index);
    s.animations.push_back(std::move(rot));
    Instance inst;
    inst.object = 0;
    inst.id = static_cast<std::uint32_t>(index);
    inst.dynamic = true;
    s.instances.push_back(inst);
  }
  s.animation_seconds = period;
  return s;
}

// ---- builtin:terrain (264 objects, 10,469,866 triangles: a 1M-triangle heightfield + trees) ----

double terrain_height(double x, double z) {
  double h = 25.0 * std::sin(x * 0.004) * std::cos(z * 0.006) + 12.0 * std::sin((x + z) * 0.011);
  double amp = 18.0, freq = 1.0 / 120.0;
  for (int o = 0; o < 4; ++o) {
    h +=
        amp * (value_noise(x * freq, z * freq, 0x7E44A1Full + static_cast<std::uint64_t>(o)) - 0.5);
    amp *= 0.45;
    freq *= 2.1;
  }
  return h;
}

// A tree: trunk (16 x 8 quads = 256), 50 branches (6 x 2 quads = 24 each, 1,200) and `leaves`
// leaf quads (2 triangles each) in a crown whose shape depends on `kind`.
Object make_tree(int kind, int leaves, std::uint32_t bark_m, std::uint32_t leaf_m) {
  MeshBuilder b("tree" + std::to_string(kind));
  Rng rng(0x7EE0ull + static_cast<std::uint64_t>(kind));
  const double height = kind == 0 ? 14.0 : (kind == 1 ? 10.0 : 18.0);
  const double trunk_r = kind == 1 ? 0.35 : 0.3;
  b.tube([&](double t) { return glm::dvec3(0.0, height * t, 0.0); },
         [&](double t) { return trunk_r * (1.0 - 0.7 * t); }, {0, 1, 0}, 16, 8, bark_m);
  // Points inside the crown (rejection sampling within the crown's bounding box).
  const auto crown_point = [&]() {
    for (;;) {
      const double u = rng.range(-1, 1), v = rng.range(0, 1), w = rng.range(-1, 1);
      if (kind == 0) {  // conifer: a cone from 25% to 100% of the height
        const double r = 1.0 - v;
        if (u * u + w * w <= r * r) return glm::dvec3(u * 4.5, height * (0.25 + 0.75 * v), w * 4.5);
      } else if (kind == 1) {  // broadleaf: a sphere
        const double y = 2 * v - 1;
        if (u * u + y * y + w * w <= 1.0)
          return glm::dvec3(u * 5.0, height * 0.6 + y * 4.0, w * 5.0);
      } else {  // poplar: a tall ellipsoid
        const double y = 2 * v - 1;
        if (u * u + y * y + w * w <= 1.0)
          return glm::dvec3(u * 2.2, height * 0.6 + y * 7.0, w * 2.2);
      }
    }
  };
  for (int i = 0; i < 50; ++i) {
    const double y0 = height * rng.range(0.3, 0.9);
    const glm::dvec3 from(0.0, y0, 0.0);
    glm::dvec3 to = crown_point();
    to.y = std::max(to.y, y0 + 0.3);
    b.tube([&](double t) { return from + (to - from) * t; },
           [](double t) { return 0.08 * (1.0 - 0.6 * t); }, to - from, 6, 2, bark_m);
  }
  for (int i = 0; i < leaves; ++i) {
    const glm::dvec3 c = crown_point();
    const double a = rng.range(0, 2 * kPi), tilt = rng.range(-1.2, 1.2);
    const glm::dvec3 u = glm::dvec3(std::cos(a), 0.0, std::sin(a)) * 0.22;
    const glm::dvec3 v =
        glm::dvec3(-std::sin(a) * std::cos(tilt), std::sin(tilt), std::cos(a) * std::cos(tilt)) *
        0.3;
    b.grid(c - u * 0.5 - v * 0.5, u, v, 1, 1, leaf_m);
  }
  return b.finish();
}

Scene make_terrain() {
  Scene s;
  const int grass = add_texture(s, "grass", 64, [](int x, int y) {
    const double n =
        value_noise(x * 0.25, y * 0.25, 0x6A55ull) * 0.6 + value_noise(x, y, 0x6A56ull) * 0.4;
    return glm::dvec3(0.18 + 0.15 * n, 0.35 + 0.25 * n, 0.10 + 0.08 * n);
  });
  const std::uint32_t ground_m = add_material(s, "ground", {1, 1, 1}, 0.0f, 1.0f, grass);
  const std::uint32_t bark_m = add_material(s, "bark", {0.35f, 0.25f, 0.15f}, 0.0f, 1.0f);
  const std::uint32_t leaf_m = add_material(s, "foliage", {0.12f, 0.40f, 0.10f}, 0.0f, 0.8f);
  // 1000 x 500 cells of 2 m: 1,000,000 triangles.
  const int nx = 1000, nz = 500;
  const double cell = 2.0;
  // Heights once per grid vertex; normals from central differences of the grid itself.
  MeshBuilder ground("heightfield");
  std::vector<double> height(static_cast<std::size_t>((nx + 1) * (nz + 1)));
  const auto at = [&](int i, int j) -> double& {
    return height[static_cast<std::size_t>(j * (nx + 1) + i)];
  };
  for (int j = 0; j <= nz; ++j)
    for (int i = 0; i <= nx; ++i)
      at(i, j) = terrain_height((i - nx / 2) * cell, (j - nz / 2) * cell);
  for (int j = 0; j <= nz; ++j) {
    for (int i = 0; i <= nx; ++i) {
      const int i0 = std::max(i - 1, 0), i1 = std::min(i + 1, nx);
      const int j0 = std::max(j - 1, 0), j1 = std::min(j + 1, nz);
      const double dhdx = (at(i1, j) - at(i0, j)) / ((i1 - i0) * cell);
      const double dhdz = (at(i, j1) - at(i, j0)) / ((j1 - j0) * cell);
      // World z = -grid z, so the slope along world z flips sign.
      ground.vertex({(i - nx / 2) * cell, at(i, j), -(j - nz / 2) * cell}, {-dhdx, 1.0, dhdz},
                    {i / 8.0, j / 8.0});
    }
  }
  const auto row = static_cast<std::uint32_t>(nx + 1);
  for (int j = 0; j < nz; ++j) {
    for (int i = 0; i < nx; ++i) {
      const std::uint32_t v00 = static_cast<std::uint32_t>(j) * row + static_cast<std::uint32_t>(i);
      ground.tri(v00, v00 + 1, v00 + row + 1, ground_m);
      ground.tri(v00, v00 + row + 1, v00 + row, ground_m);
    }
  }
  s.objects.push_back(ground.finish());
  add_instance(s, 0, glm::dmat4(1.0), "heightfield");
  // Three tree kinds of 36,006 / 36,008 / 36,010 triangles, 169 + 44 + 50 = 263 instances:
  // 9,469,866 tree triangles, 10,469,866 in all (Table 3's Terrain).
  const int leaves[3] = {17275, 17276, 17277};
  const int count[3] = {169, 44, 50};
  for (int k = 0; k < 3; ++k)
    s.objects.push_back(make_tree(k, leaves[k], bark_m, leaf_m));
  Rng rng(0x7E22A1Eull);
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    for (int i = 0; i < count[k]; ++i, ++n) {
      // Groves in the half of the terrain the camera looks at.
      const double x = rng.range(-450.0, 450.0), z = rng.range(-350.0, 150.0);
      const double y = terrain_height(x, -z) - 0.3;
      glm::dmat4 m = glm::translate(glm::dmat4(1.0), {x, y, z});
      m = glm::rotate(m, rng.range(0, 2 * kPi), {0.0, 1.0, 0.0});
      m = glm::scale(m, glm::dvec3(rng.range(0.8, 1.25)));
      add_instance(s, static_cast<std::uint32_t>(1 + k), m, "tree" + std::to_string(n));
    }
  }
  const double cz = 330.0;
  s.cameras.push_back(
      look_at({0.0, terrain_height(0.0, -cz) + 45.0, cz}, {0.0, 0.0, -100.0}, "overlook"));
  s.lights.push_back(light_at({-400.0, 600.0, 500.0}, {1.0, 0.96, 0.88}));
  return s;
}

// ---- builtin:dynamic (Quake3-p: 17 objects, 52,790 triangles, 16 moving players/monsters) -----

Object make_player(std::uint32_t body_m, std::uint32_t skin_m) {
  MeshBuilder b("player");
  b.sphere({0, 1.65, 0}, glm::dvec3(0.14), 16, 9, skin_m);  // 256
  b.cylinder({0, 0.85, 0}, {0, 0.65, 0}, 0.2, 32, body_m);  // 128
  for (int i = 0; i < 4; ++i) {                             // 4 x 112
    const double side = (i & 1) ? 1.0 : -1.0;
    if (i < 2) {
      b.cylinder({0.1 * side, 0.0, 0}, {0, 0.85, 0}, 0.07, 28, body_m);  // legs
    } else {
      b.cylinder({0.27 * side, 0.85, 0}, {0, 0.6, 0}, 0.05, 28, skin_m);  // arms
    }
  }
  return b.finish();  // 832
}

Object make_monster(std::uint32_t hide_m, std::uint32_t horn_m) {
  MeshBuilder b("monster");
  b.sphere({0, 0.8, 0}, {0.6, 0.45, 0.8}, 24, 11, hide_m);  // 480
  for (int i = 0; i < 4; ++i) {                             // 4 x 64
    const double x = (i & 1) ? 0.35 : -0.35, z = (i & 2) ? 0.45 : -0.45;
    b.cylinder({x, 0.0, z}, {0, 0.55, 0}, 0.09, 16, hide_m);
  }
  for (int i = 0; i < 2; ++i) {  // 2 x 52
    const double x = i ? 0.2 : -0.2;
    b.cone({x, 1.15, 0.55}, {x * 0.8, 0.35, 0.15}, 0.07, 26, horn_m);
  }
  return b.finish();  // 840
}

Scene make_dynamic() {
  Scene s;
  const int crate_tex = add_texture(s, "crate", 64, [](int x, int y) {
    const bool frame = x < 6 || y < 6 || x > 57 || y > 57 || std::abs(x - y) < 4;
    const double g = 0.06 * std::sin(y * 0.9) + 0.03 * std::sin(x * 2.3);
    return frame ? glm::dvec3(0.35 + g, 0.22 + g, 0.10) : glm::dvec3(0.60 + g, 0.45 + g, 0.25);
  });
  const std::uint32_t floor_m = add_material(s, "floor", {0.45f, 0.45f, 0.48f}, 0.0f, 0.7f);
  const std::uint32_t wall_m = add_material(s, "wall", {0.55f, 0.50f, 0.42f}, 0.0f, 0.9f);
  const std::uint32_t pillar_m = add_material(s, "pillar", {0.70f, 0.68f, 0.62f}, 0.2f, 0.3f);
  const std::uint32_t crate_m = add_material(s, "crate", {1, 1, 1}, 0.0f, 0.8f, crate_tex);
  const std::uint32_t body_m = add_material(s, "armour", {0.20f, 0.30f, 0.60f}, 0.6f, 0.3f);
  const std::uint32_t skin_m = add_material(s, "skin", {0.85f, 0.65f, 0.50f}, 0.0f, 0.8f);
  const std::uint32_t hide_m = add_material(s, "hide", {0.35f, 0.50f, 0.20f}, 0.0f, 0.9f);
  const std::uint32_t horn_m = add_material(s, "horn", {0.90f, 0.88f, 0.80f}, 0.0f, 0.4f);

  // The level: 39,414 triangles (52,790 - 16 movers of 832 and 840).
  MeshBuilder level("arena");
  const double w = 20.0, h = 8.0;
  level.grid({-w, 0, w}, {2 * w, 0, 0}, {0, 0, -2 * w}, 80, 80, floor_m, {10, 10});  // 12,800
  level.grid({-w, h, -w}, {2 * w, 0, 0}, {0, 0, 2 * w}, 40, 40, wall_m);             // 3,200
  level.grid({-w, 0, -w}, {2 * w, 0, 0}, {0, h, 0}, 80, 16, wall_m);                 // 2,560
  level.grid({w, 0, w}, {-2 * w, 0, 0}, {0, h, 0}, 80, 16, wall_m);                  // 2,560
  level.grid({-w, 0, w}, {0, 0, -2 * w}, {0, h, 0}, 80, 16, wall_m);                 // 2,560
  level.grid({w, 0, -w}, {0, 0, 2 * w}, {0, h, 0}, 80, 16, wall_m);                  // 2,560
  for (int i = 0; i < 24; ++i) {  // 24 pillars of 32 x 8 quads: 12,288
    const double a = 2.0 * kPi * i / 24;
    const glm::dvec3 c(std::cos(a) * 15.0, 0.0, std::sin(a) * 15.0);
    level.tube([&](double t) { return c + glm::dvec3(0.0, h * t, 0.0); },
               [](double t) { return 0.6 - 0.15 * std::sin(kPi * t); }, {0, 1, 0}, 32, 8, pillar_m);
  }
  const std::size_t target = 39414;
  Rng rng(0xD1A4ull);
  int crate = 0;
  while (level.triangles() + 12 <= target) {  // stacks of crates along the walls
    const int stack = crate / 3, layer = crate % 3;
    const double along = -18.0 + (stack % 24) * 1.5;
    const int wall = (stack / 24) % 4;
    glm::dvec3 c = wall == 0   ? glm::dvec3(along, 0, -18.5)
                   : wall == 1 ? glm::dvec3(along, 0, 18.5)
                   : wall == 2 ? glm::dvec3(-18.5, 0, along)
                               : glm::dvec3(18.5, 0, along);
    c.y = layer * 1.0;
    c.x += rng.range(-0.08, 0.08);
    level.box(c - glm::dvec3(0.5, 0.0, 0.5), c + glm::dvec3(0.5, 1.0, 0.5), crate_m);
    ++crate;
  }
  const std::size_t rest = (target - level.triangles()) / 2;  // a banner strip for what is left
  if (rest > 0)
    level.grid({-4.0, 5.0, -w + 0.05}, {8.0, 0, 0}, {0, 1.5, 0}, static_cast<int>(rest), 1,
               pillar_m);
  s.objects.push_back(level.finish());
  s.objects.push_back(make_player(body_m, skin_m));
  s.objects.push_back(make_monster(hide_m, horn_m));
  add_instance(s, 0, glm::dmat4(1.0), "arena");

  // 16 movers on closed loops between the pillars; one lap takes 10 s.
  const double lap = 10.0;
  const int keys = 41;
  for (int i = 0; i < 16; ++i) {
    const std::uint32_t object = (i % 2) ? 2 : 1;
    Node node;
    node.name = (object == 1 ? "player" : "monster") + std::to_string(i / 2);
    node.object = static_cast<int>(object);
    node.use_trs = true;
    node.animated = true;
    const int index = static_cast<int>(s.nodes.size());
    const double r = 4.0 + 0.4 * i;
    const double dir = (i % 2) ? 1.0 : -1.0;
    const double phase = 2.0 * kPi * i / 16.0;
    const double wobble = 1.0 + 0.15 * (i % 3);
    AnimChannel tr, rot;
    tr.node = rot.node = index;
    tr.path = AnimPath::kTranslation;
    rot.path = AnimPath::kRotation;
    for (int k = 0; k < keys; ++k) {
      const double t = lap * k / (keys - 1);
      const double a = phase + dir * 2.0 * kPi * t / lap;
      const glm::dvec3 p(std::cos(a) * r * wobble, 0.0, std::sin(a) * r);
      const glm::dvec3 v(-std::sin(a) * r * wobble * dir, 0.0,
                         std::cos(a) * r * dir);  // velocity direction
      const double yaw = std::atan2(v.x, v.z);    // objects face +Z
      const glm::dquat q = glm::angleAxis(yaw, glm::dvec3(0.0, 1.0, 0.0));
      // Keys are binary32 values, as a glTF file stores them: export and re-load are exact.
      tr.times.push_back(t);
      tr.values.emplace_back(glm::dvec4(glm::vec4(glm::dvec4(p, 0.0))));
      rot.times.push_back(t);
      rot.values.emplace_back(glm::dvec4(glm::vec4(glm::dvec4(q.x, q.y, q.z, q.w))));
    }
    node.translation = glm::dvec3(tr.values[0]);
    node.rotation = glm::dquat(rot.values[0].w, rot.values[0].x, rot.values[0].y, rot.values[0].z);
    s.nodes.push_back(node);
    s.roots.push_back(index);
    s.animations.push_back(std::move(tr));
    s.animations.push_back(std::move(rot));
    Instance inst;
    inst.object = object;
    inst.id = static_cast<std::uint32_t>(index);
    inst.dynamic = true;
    s.instances.push_back(inst);
  }
  s.animation_seconds = lap;
  s.cameras.push_back(look_at({0.0, 6.0, 19.0}, {0.0, 1.0, 0.0}, "gallery"));
  s.lights.push_back(light_at({0.0, 7.5, 0.0}, {0.8, 0.8, 0.75}));
  s.lights.push_back(light_at({-12.0, 7.0, -12.0}, {0.5, 0.45, 0.4}));
  s.lights.push_back(light_at({12.0, 7.0, 12.0}, {0.4, 0.45, 0.5}));
  return s;
}

// ---- builtin:glass (refraction: a textured room, a glass sphere and a glass block) -------------

// Glass as a glTF asset would give it (KHR_materials_transmission, KHR_materials_ior): a smooth
// dielectric whose transmission factor becomes the refraction weight.
std::uint32_t add_glass(Scene& s, const std::string& name, glm::vec3 tint, float transmission,
                        float ior) {
  Material m;
  m.name = name;
  m.base_color = glm::vec4(tint, 1.0f);
  m.roughness = 0.05f;
  m.transmission = transmission;
  m.ior = ior;
  derive_fixed_function_terms(m, false);
  s.materials.push_back(m);
  return static_cast<std::uint32_t>(s.materials.size() - 1);
}

Scene make_glass() {
  Scene s;
  const int checker = add_texture(s, "floor_checker", 32, [](int x, int y) {
    return ((x / 4) + (y / 4)) % 2 ? glm::dvec3(0.20, 0.22, 0.30) : glm::dvec3(0.90, 0.88, 0.80);
  });
  const int stripes = add_texture(s, "wall_stripes", 32, [](int x, int) {
    return (x / 4) % 2 ? glm::dvec3(0.85, 0.30, 0.20) : glm::dvec3(0.95, 0.90, 0.70);
  });
  const std::uint32_t floor_m = add_material(s, "floor", {1, 1, 1}, 0.0f, 0.6f, checker);
  const std::uint32_t back_m = add_material(s, "back_wall", {1, 1, 1}, 0.0f, 1.0f, stripes);
  const std::uint32_t wall_m = add_material(s, "wall", {0.75f, 0.80f, 0.85f}, 0.0f, 1.0f);
  const std::uint32_t mirror_m = add_material(s, "mirror", {0.90f, 0.90f, 0.90f}, 1.0f, 0.05f);
  const std::uint32_t post_m = add_material(s, "post", {0.20f, 0.65f, 0.25f}, 0.0f, 0.5f);
  const std::uint32_t sphere_m = add_glass(s, "glass", {0.85f, 0.92f, 1.0f}, 0.9f, 1.5f);
  const std::uint32_t block_m = add_glass(s, "crystal", {1.0f, 0.95f, 0.85f}, 0.85f, 1.7f);

  MeshBuilder room("room");
  const double w = 2.0;
  add_room_shell(room, {w, 2.5, 4, {4, 4}, floor_m, wall_m, back_m, wall_m, {3, 1}});  // 32 + 10
  // A mirror before the back wall, behind the block (2).
  room.grid({0.4, 0.3, -w + 0.02}, {1.4, 0, 0}, {0, 1.5, 0}, 1, 1, mirror_m);
  // A green post behind the sphere, seen through it; its foot below the floor, so no face lies
  // in the floor's plane (40).
  room.cylinder({-0.9, -0.05, -1.3}, {0, 1.65, 0}, 0.12, 10, post_m);
  // The glass sphere (32 x 16: 960).
  room.sphere({-0.5, 0.55, -0.2}, {0.55, 0.55, 0.55}, 32, 16, sphere_m);
  add_instance(s, add_object(s, room), glm::dmat4(1.0), "room");
  // A glass block: its own object, placed by a rotation and a non-uniform scale (12).
  MeshBuilder block("block");
  block.box({-0.5, 0.0, -0.5}, {0.5, 1.0, 0.5}, block_m);
  // It stands a little above the floor: a face in the floor's plane would make the closest hit a
  // tie that fp24 and binary32 break differently.
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), glm::dvec3(0.75, 0.02, 0.1));
  m = glm::rotate(m, 0.6, glm::dvec3(0, 1, 0));
  m = glm::scale(m, glm::dvec3(0.5, 0.9, 0.35));
  add_instance(s, add_object(s, block), m, "block");
  s.cameras.push_back(look_at({0.3, 1.4, 1.9}, {0.0, 0.5, -0.5}, "front"));
  s.lights.push_back(light_at({0.0, 2.4, -0.6}, {0.95, 0.95, 0.9}));
  return s;
}

}  // namespace

std::vector<std::string> builtin_scene_names() {
  return {"triangle", "cube", "room", "suncor", "terrain", "dynamic", "glass", "suncor-wind"};
}

Scene make_builtin_scene(const std::string& name) {
  Scene s;
  if (name == "triangle") {
    s = make_triangle();
  } else if (name == "cube") {
    s = make_cube();
  } else if (name == "room") {
    s = make_room();
  } else if (name == "suncor") {
    s = make_suncor();
  } else if (name == "terrain") {
    s = make_terrain();
  } else if (name == "dynamic") {
    s = make_dynamic();
  } else if (name == "glass") {
    s = make_glass();
  } else if (name == "suncor-wind") {
    s = make_suncor_wind();
  } else {
    std::string known;
    for (const std::string& n : builtin_scene_names())
      known += (known.empty() ? "" : ", ") + n;
    throw std::runtime_error("unknown built-in scene 'builtin:" + name + "' (known: " + known +
                             ")");
  }
  s.source = "builtin:" + name;
  s.set_time(0.0);
  return s;
}

}  // namespace saarcor::host
