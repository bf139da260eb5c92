// One ray per packet through the image's kd-trees in binary32 (testbench/packet_cost.h).
#include "testbench/packet_cost.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fixedfloat/format.h"
#include "units/functional_model.h"
#include "units/shading.h"

namespace saarcor {

CostFeatures cost_features(const RayCost& c) {
  return {1.0,
          static_cast<double>(c.steps),
          static_cast<double>(c.tests),
          static_cast<double>(c.leaves),
          static_cast<double>(c.lists),
          static_cast<double>(c.transforms),
          c.box ? 1.0 : 0.0,
          static_cast<double>(c.shadow_rays),
          static_cast<double>(c.shadow_steps),
          static_cast<double>(c.shadow_tests),
          static_cast<double>(c.secondary_rays),
          static_cast<double>(c.secondary_steps),
          static_cast<double>(c.secondary_tests)};
}

CostPaths cost_paths(const memif::MemoryImage& image, const units::FunctionalParams& shading) {
  return {shading.shade && shading.shadows, shading.shade && shading.secondary,
          shading.max_depth < 0 ? image.registers().max_depth
                                : static_cast<std::uint32_t>(shading.max_depth)};
}

namespace {

using Row3 = std::array<std::array<float, 4>, 3>;
using Vec = std::array<float, 3>;

constexpr int kMaxDepth = 128;  // deferred far children of one level's path

// out_r = (m_r0*x + m_r1*y) + (m_r2*z + t_r), t_r = 0 for a direction (the transformation unit).
Vec transform(const Row3& m, const Vec& v, float w) {
  Vec r{};
  for (std::size_t i = 0; i < 3; ++i)
    r[i] = (m[i][0] * v[0] + m[i][1] * v[1]) + (m[i][2] * v[2] + m[i][3] * w);
  return r;
}

// Clips [t0, t1] to the box by slabs; a NaN (ray in a slab plane) leaves the interval.
void clip(const Vec& lo, const Vec& hi, const Vec& o, const Vec& d, float& t0, float& t1) {
  for (std::size_t a = 0; a < 3; ++a) {
    const float n = (lo[a] - o[a]) / d[a], f = (hi[a] - o[a]) / d[a];
    const bool neg = std::signbit(d[a]);
    if ((neg ? f : n) > t0) t0 = neg ? f : n;
    if ((neg ? n : f) < t1) t1 = neg ? n : f;
  }
}

}  // namespace

PacketCostModel::Ray PacketCostModel::make_ray(const Vec& o, const Vec& d) {
  Ray r{o, d, {}};
  for (std::size_t a = 0; a < 3; ++a)
    r.inv[a] = 1.0f / d[a];
  return r;
}

float PacketCostModel::decode(std::uint32_t bits) const {
  return static_cast<float>(ff::decode(bits, image_.format(), ff::Subnormals::kFlush));
}

PacketCostModel::PacketCostModel(const memif::MemoryImage& image) : image_(image) {
  const auto& r = image.registers();
  // Nodes are read when a ray first reaches them: a frame's rays visit a small part of a large
  // scene's trees.
  nodes_.assign(image.regions().count[static_cast<int>(memif::ItemType::kNode)], Node{});
  for (std::uint32_t i = 0; i < r.instance_count; ++i) {
    const std::uint32_t base = r.instance_row_base + memif::kInstanceRows * i;
    Instance in;
    for (std::uint32_t k = 0; k < 3; ++k) {
      const auto row = image.row(base + k);
      for (std::size_t j = 0; j < 4; ++j)
        in.world_to_object[k][j] = decode(row[j]);
    }
    const memif::InstanceHeader h = image.instance_header(i);
    in.root = h.root;
    in.triangle_rows = h.triangle_row_base;
    in.shading_base = h.shading_base;
    const auto lo = image.row(base + 4), hi = image.row(base + 5);
    for (std::size_t a = 0; a < 3; ++a) {
      in.lo[a] = decode(lo[a]);
      in.hi[a] = decode(hi[a]);
    }
    instances_.push_back(in);
  }
  const std::uint32_t rows = image.regions().count[static_cast<int>(memif::ItemType::kRow)];
  slots_.assign(rows, -1);
  for (std::size_t a = 0; a < 3; ++a) {
    scene_lo_[a] = decode(r.scene_min[a]);
    scene_hi_[a] = decode(r.scene_max[a]);
    cam_r_[a] = decode(r.cam_r[a]);
    cam_u_[a] = decode(r.cam_u[a]);
    cam_d_[a] = decode(r.cam_d[a]);
    cam_p_[a] = decode(r.cam_p[a]);
  }
  for (std::uint32_t l = 0; l < r.light_count; ++l) {
    Vec pos{};
    for (std::uint32_t k = 0; k < 3; ++k)
      pos[k] = decode(image.word(memif::kShadingBank, r.light_base + memif::kLightWords * l + k));
    lights_.push_back(pos);
  }
  epsilon_ = decode(r.epsilon);
}

void PacketCostModel::read_node(std::uint32_t index) const {
  Node& m = nodes_[index];
  const memif::KdNode n = image_.node(index);
  m.bits = n.leaf
               ? 3u
               : n.axis | (std::uint32_t{n.empty_left} << 2) | (std::uint32_t{n.empty_right} << 3);
  m.child = n.leaf ? n.first : n.child_pair;
  m.count = n.count;
  m.split = n.leaf ? 0.0f : decode(n.split);
}

const Row3& PacketCostModel::triangle(std::uint32_t first_row) const {
  std::int32_t& slot = slots_[first_row];
  if (slot < 0) {
    Row3 m{};
    for (std::uint32_t k = 0; k < 3; ++k) {
      const auto row = image_.row(first_row + k);
      for (std::size_t j = 0; j < 4; ++j)
        m[k][j] = decode(row[j]);
    }
    slot = static_cast<std::int32_t>(matrices_.size());
    matrices_.push_back(m);
  }
  return matrices_[static_cast<std::size_t>(slot)];
}

// Front-to-back kd traversal over [t0, t1], as the traversal unit decides: the far child only
// when the plane lies before the segment, the near only when beyond it, both otherwise; an empty
// child is never entered. visit(leaf, t_far) returns true to stop (a hit before the leaf's end).
template <class Visit>
void PacketCostModel::traverse(std::uint32_t root, const Ray& r, float t0, float t1, RayCost& c,
                               Visit&& visit) const {
  struct Entry {
    std::uint32_t node;
    float t0, t1;
  };
  Entry stack[kMaxDepth];
  int top = 0;
  std::uint32_t node = root;
  for (;;) {
    bool live = true;
    while (live && (this->node(node).bits & 3u) != 3u) {
      const Node& n = this->node(node);
      ++c.steps;
      const std::size_t axis = n.bits & 3u;
      const float d = (n.split - r.o[axis]) * r.inv[axis];
      const std::uint32_t flip = std::signbit(r.d[axis]) ? 1u : 0u;
      const std::uint32_t near = n.child + flip, far = n.child + 1u - flip;
      const bool near_live = ((n.bits >> (2u + flip)) & 1u) == 0;
      const bool far_live = ((n.bits >> (3u - flip)) & 1u) == 0;
      if (d < t0 || t1 < d) {
        node = d < t0 ? far : near;
        live = d < t0 ? far_live : near_live;
        continue;
      }
      const bool split = d == d;  // NaN: the ray lies in the plane, both over the segment
      if (far_live && top < kMaxDepth) stack[top++] = {far, split ? d : t0, t1};
      if (split) t1 = d;
      node = near;
      live = near_live;
    }
    if (live) {
      ++c.leaves;
      if (visit(this->node(node), t1)) return;
    }
    if (top == 0) return;
    --top;
    node = stack[top].node;
    t0 = stack[top].t0;
    t1 = stack[top].t1;
  }
}

bool PacketCostModel::trace_instance(std::uint32_t instance, const Ray& world, float& t_best,
                                     bool any_hit, RayCost& c, Hit* hit) const {
  const Instance& in = instances_[instance];
  ++c.transforms;
  const Ray r = make_ray(transform(in.world_to_object, world.o, 1.0f),
                         transform(in.world_to_object, world.d, 0.0f));
  float t0 = 0.0f, t1 = t_best;
  clip(in.lo, in.hi, r.o, r.d, t0, t1);
  if (!(t0 <= t1)) return false;
  bool ended = false;
  traverse(in.root, r, t0, t1, c, [&](const Node& leaf, float leaf_far) {
    for (std::uint32_t i = 0; i < leaf.count; ++i) {
      ++c.lists;
      ++c.tests;
      const std::uint32_t first =
          in.triangle_rows + memif::kTriangleRows * image_.list_entry(leaf.child + i);
      const Row3& m = triangle(first);
      const Vec o = transform(m, r.o, 1.0f), d = transform(m, r.d, 0.0f);
      const float t = -o[2] / d[2];
      if (!(t > 0.0f && t < t_best) || d[2] == 0.0f) continue;
      const float u = o[0] + t * d[0], v = o[1] + t * d[1];
      if (u >= 0.0f && v >= 0.0f && u + v <= 1.0f) {
        t_best = t;
        c.hit = true;
        if (hit != nullptr) *hit = {instance, first, t};
        if (any_hit) return ended = true;  // a shadow ray is done at its first hit (D15)
      }
    }
    return t_best < leaf_far;
  });
  return ended;
}

RayCost PacketCostModel::trace(const Vec& origin, const Vec& direction, float t_max, bool any_hit,
                               Hit* hit) const {
  RayCost c;
  const Ray r = make_ray(origin, direction);
  float t0 = 0.0f, t1 = t_max;
  clip(scene_lo_, scene_hi_, r.o, r.d, t0, t1);
  if (!(t0 <= t1) || nodes_.empty()) return c;
  c.box = true;
  float t_best = t_max;
  // The mailbox: an instance listed in several top-level leaves is entered once per ray (a ray
  // entering more instances than it holds may enter one twice: a cost, not a result).
  std::array<std::uint32_t, 64> seen{};
  std::size_t n_seen = 0;
  traverse(image_.registers().top_root, r, t0, t1, c, [&](const Node& leaf, float leaf_far) {
    for (std::uint32_t i = 0; i < leaf.count; ++i) {
      ++c.lists;
      const std::uint32_t inst = image_.list_entry(leaf.child + i);
      if (inst >= instances_.size() ||
          std::find(seen.begin(), seen.begin() + n_seen, inst) != seen.begin() + n_seen)
        continue;
      if (n_seen < seen.size()) seen[n_seen++] = inst;
      if (trace_instance(inst, r, t_best, any_hit, c, hit)) return true;
    }
    return t_best < leaf_far;
  });
  return c;
}

// The RGS's work on a hit (units/rgs_step.h): per light, the world normal (row 2 of the
// triangle's matrix through the instance's M^T) faced against the ray; the light lights the hit
// when the normal points towards it, and its shadow ray then runs from the light to the hit point
// over t < 1 - 1/512, ending at its first hit. Then the children, each with its weight
// (docs/shading.md section 7): reflection from t - e along D - 2 (D.n / n.n) n, transparency and
// refraction (here straight on: its bend changes little of the work) from t + e along D.
void PacketCostModel::shade(const Vec& o, const Vec& d, const Hit& hit, std::uint32_t weight,
                            std::uint32_t depth, const CostPaths& paths, RayCost& c) const {
  const Row3& m = triangle(hit.triangle_row);
  const Instance& in = instances_[hit.instance];
  const auto& w = in.world_to_object;
  Vec n{}, p{};
  float dn = 0, nn = 0;
  for (std::size_t j = 0; j < 3; ++j) {
    n[j] = w[0][j] * m[2][0] + w[1][j] * m[2][1] + w[2][j] * m[2][2];
    p[j] = o[j] + hit.t * d[j];
    dn += n[j] * d[j];
    nn += n[j] * n[j];
  }
  const std::size_t lights = paths.shadows ? lights_.size() : 0;
  for (std::size_t l = 0; l < lights; ++l) {
    const Vec& light = lights_[l];
    Vec s{};
    float lit = 0;
    for (std::size_t j = 0; j < 3; ++j) {
      s[j] = p[j] - light[j];
      lit += n[j] * s[j];
    }
    if (!(dn > 0 ? lit > 0 : lit < 0)) continue;  // the faced normal is -n when n . D > 0
    const RayCost r = trace(light, s, 1.0f - 1.0f / 512.0f, true);
    ++c.shadow_rays;
    c.shadow_steps += r.steps;
    c.shadow_tests += r.tests;
  }
  if (!paths.secondary || depth >= paths.max_depth) return;
  // The hit triangle's material, as the RGS reads it (units/shading.h).
  const std::uint32_t triangle_index = (hit.triangle_row - in.triangle_rows) / memif::kTriangleRows;
  const memif::MaterialRecord mat = units::read_material(
      image_, units::read_shading_record(image_, in.shading_base + triangle_index).material);
  const auto child = [&](std::uint32_t child_weight, float at, const Vec& direction) {
    if (child_weight == 0) return;
    Vec origin{};
    for (std::size_t j = 0; j < 3; ++j)
      origin[j] = o[j] + at * d[j];
    Hit h;
    const RayCost r = trace(origin, direction, std::numeric_limits<float>::infinity(), false, &h);
    ++c.secondary_rays;
    c.secondary_steps += r.steps;
    c.secondary_tests += r.tests;
    if (r.hit) shade(origin, direction, h, child_weight, depth + 1, paths, c);
  };
  Vec reflected = d;
  for (std::size_t j = 0; j < 3; ++j)
    reflected[j] = d[j] - 2.0f * dn / nn * n[j];
  child(units::mul8(weight, mat.reflectivity), hit.t - epsilon_, reflected);
  child(units::mul8(weight, mat.transparency), hit.t + epsilon_, d);
  child(units::mul8(weight, mat.refraction), hit.t + epsilon_, d);
}

RayCost PacketCostModel::trace_pixel(double x, double y, const CostPaths& paths) const {
  const auto px = static_cast<float>(x), py = static_cast<float>(y);
  Vec d{};
  for (std::size_t i = 0; i < 3; ++i)
    d[i] = (cam_r_[i] * px + cam_u_[i] * py) + cam_d_[i];
  Hit hit;
  RayCost c = trace(cam_p_, d, std::numeric_limits<float>::infinity(), false, &hit);
  if (c.hit && (paths.shadows || paths.secondary)) shade(cam_p_, d, hit, 255u, 0, paths, c);
  return c;
}

RayCost& operator+=(RayCost& a, const RayCost& b) {
  a.box = a.box || b.box;
  a.hit = a.hit || b.hit;
  a.steps += b.steps;
  a.leaves += b.leaves;
  a.lists += b.lists;
  a.transforms += b.transforms;
  a.tests += b.tests;
  a.shadow_rays += b.shadow_rays;
  a.shadow_steps += b.shadow_steps;
  a.shadow_tests += b.shadow_tests;
  a.secondary_rays += b.secondary_rays;
  a.secondary_steps += b.secondary_steps;
  a.secondary_tests += b.secondary_tests;
  return a;
}

std::vector<RayCost> packet_costs(const memif::MemoryImage& image, int packet,
                                  const CostPaths& paths) {
  const auto& r = image.registers();
  const int w = static_cast<int>(r.width), h = static_cast<int>(r.height);
  const units::PacketTiling t = units::packet_tiling(w, h, packet);
  const PacketCostModel model(image);
  // Packets of 16 rays or more: one ray per quadrant of the tile (a ray per 4 pixels at most,
  // as with 4-ray packets), since one ray of 16 predicts its packet less well.
  const int split = packet >= 16 ? 2 : 1;
  std::vector<RayCost> costs(static_cast<std::size_t>(t.count()));
  for (int i = 0; i < t.count(); ++i) {
    const int tx = (i % t.tiles_x) * t.tile_width, ty = (i / t.tiles_x) * t.tile_height;
    for (int q = 0; q < split * split; ++q) {
      // The part's centre, the part clipped to the image (the frame's last column and row).
      const int pw = t.tile_width / split, ph = t.tile_height / split;
      const int x0 = tx + (q % split) * pw, y0 = ty + (q / split) * ph;
      const int x1 = std::min(x0 + pw, w) - 1, y1 = std::min(y0 + ph, h) - 1;
      if (x1 < x0 || y1 < y0) continue;  // a quadrant outside the image
      costs[static_cast<std::size_t>(i)] +=
          model.trace_pixel(0.5 * (x0 + x1), 0.5 * (y0 + y1), paths);
    }
  }
  return costs;
}

}  // namespace saarcor
