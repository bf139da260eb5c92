// The float reference renderer (docs/compare.md, model 1; paper sections 2.1, 2.2.2, 3.1 and
// docs/cycle-model.md and docs/shading.md): two-level kd-tree traversal, world -> object transform,
// unit- triangle intersection, all in binary32 in the datapath op order. docs/float-reference.md.
#include "host/float_reference.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>

#include "host/image_builder.h"
#include "host/scene.h"
#include "memif/image_format.h"

namespace saarcor::host {

FloatTraceStats& FloatTraceStats::operator+=(const FloatTraceStats& o) {
  rays += o.rays;
  traversal_steps += o.traversal_steps;
  leaves += o.leaves;
  list_entries += o.list_entries;
  mailbox_skips += o.mailbox_skips;
  transformations += o.transformations;
  intersections += o.intersections;
  return *this;
}

namespace {

// The traversal stack of one level. A kd-tree path never holds more deferred far children than
// the tree is deep; FloatScene refuses trees deeper than this.
constexpr int kMaxDepth = 120;

struct StackEntry {
  std::uint32_t node;
  float t_near;
  float t_far;
};

// out_r = (m_r0*x + m_r1*y) + (m_r2*z + t_r): the transformation unit's adder tree (decision D5).
inline glm::vec3 transform_point(const Affine32& m, const glm::vec3& p) {
  glm::vec3 r;
  for (int i = 0; i < 3; ++i) {
    const auto& row = m.rows[static_cast<std::size_t>(i)];
    r[i] = (row[0] * p.x + row[1] * p.y) + (row[2] * p.z + row[3]);
  }
  return r;
}
// The direction step feeds a zero translation.
inline glm::vec3 transform_vector(const Affine32& m, const glm::vec3& d) {
  glm::vec3 r;
  for (int i = 0; i < 3; ++i) {
    const auto& row = m.rows[static_cast<std::size_t>(i)];
    r[i] = (row[0] * d.x + row[1] * d.y) + (row[2] * d.z + 0.0f);
  }
  return r;
}

// Clips [t_near, t_far] to the box with the traversal unit's operation d = (plane - O) / D. A NaN
// (ray inside a slab plane with D = 0) leaves the interval as it is.
inline void clip_to_box(const Aabb& box, const FloatRay& ray, float& t_near, float& t_far) {
  for (int a = 0; a < 3; ++a) {
    const float t0 = (box.lo[a] - ray.origin[a]) / ray.direction[a];
    const float t1 = (box.hi[a] - ray.origin[a]) / ray.direction[a];
    const float lo = std::signbit(ray.direction[a]) ? t1 : t0;
    const float hi = std::signbit(ray.direction[a]) ? t0 : t1;
    if (lo > t_near) t_near = lo;
    if (hi < t_far) t_far = hi;
  }
}

inline bool node_is_leaf(const FloatNode& n) {
  return (n.bits & 3u) == 3u;
}

}  // namespace

// The unit-triangle test without the upper bound: t, u, v and D'z of a valid candidate.
static inline bool unit_triangle_candidate(const Affine32& t_delta, const FloatRay& ray,
                                           float t_min, float t_best, float& t, float& u, float& v,
                                           float& cos) {
  const glm::vec3 o = transform_point(t_delta, ray.origin);
  const glm::vec3 d = transform_vector(t_delta, ray.direction);
  const float tt = -o.z / d.z;
  // t <= t_best keeps exact ties for the caller's tie rule; NaN fails every compare.
  if (!(tt > t_min && tt <= t_best && tt < std::numeric_limits<float>::infinity()) || d.z == 0.0f)
    return false;
  const float uu = o.x + tt * d.x;
  const float vv = o.y + tt * d.y;
  if (!(uu >= 0.0f && vv >= 0.0f && uu + vv <= 1.0f)) return false;
  t = tt;
  u = uu;
  v = vv;
  cos = d.z;
  return true;
}

bool intersect_unit_triangle(const Affine32& t_delta, const FloatRay& ray, float t_min,
                             float t_best, float& t, float& u, float& v, float& cos) {
  float tt, uu, vv, cc;
  if (!unit_triangle_candidate(t_delta, ray, t_min, t_best, tt, uu, vv, cc) || !(tt < t_best))
    return false;
  t = tt;
  u = uu;
  v = vv;
  cos = cc;
  return true;
}

// docs/shading.md section 3: nearer wins; at equal t the smaller (instance, triangle) wins. The
// initial bound t_max (no hit yet) is strict.
static inline bool replaces(const FloatHit& best, float t, std::uint32_t instance,
                            std::uint32_t triangle) {
  if (t < best.t) return true;
  return t == best.t && best.hit() &&
         (instance < best.instance || (instance == best.instance && triangle < best.triangle));
}

// ---- building ---------------------------------------------------------------------------------

std::uint32_t FloatScene::append_tree(const KdTree& tree, std::uint32_t item_offset) {
  if (tree.nodes.empty()) throw std::runtime_error("float reference: a kd-tree has no nodes");
  const auto base = static_cast<std::uint32_t>(nodes_.size());
  std::vector<std::uint32_t> depth(tree.nodes.size(), 0);
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    const KdTreeNode& n = tree.nodes[i];
    FloatNode f;
    if (n.leaf) {
      f.bits = 3u | (n.count << 2);
      f.payload = item_offset + n.first;
      if (std::uint64_t{n.first} + n.count > tree.items.size())
        throw std::runtime_error("float reference: a kd-tree leaf list runs past its items");
    } else {
      if (n.axis > 2 || std::uint64_t{n.child} + 1 >= tree.nodes.size() || n.child <= i)
        throw std::runtime_error("float reference: a kd-tree inner node is malformed");
      f.bits = n.axis | ((base + n.child) << 2);
      f.payload = std::bit_cast<std::uint32_t>(n.split);
      depth[n.child] = depth[n.child + 1] = depth[i] + 1;
      if (depth[i] + 1 >= static_cast<std::uint32_t>(kMaxDepth))
        throw std::runtime_error("float reference: a kd-tree is deeper than " +
                                 std::to_string(kMaxDepth) + " levels");
    }
    nodes_.push_back(f);
  }
  return base;
}

std::uint32_t FloatScene::add_object(const KdTree& tree,
                                     std::span<const std::optional<Affine64>> matrices) {
  FloatObject o;
  o.item_base = static_cast<std::uint32_t>(items_.size());
  o.matrix_base = static_cast<std::uint32_t>(triangles_.size());
  o.triangle_count = static_cast<std::uint32_t>(matrices.size());
  o.bounds = tree.bounds;
  o.root = append_tree(tree, o.item_base);
  for (std::uint32_t item : tree.items) {
    if (item >= matrices.size() || !matrices[item])
      throw std::runtime_error("float reference: a kd-tree lists triangle " + std::to_string(item) +
                               ", which has no matrix");
    items_.push_back(item);
  }
  for (const auto& m : matrices)
    triangles_.push_back(m ? to_float(*m) : Affine32{});
  objects_.push_back(o);
  return static_cast<std::uint32_t>(objects_.size() - 1);
}

std::uint32_t FloatScene::add_instance(std::uint32_t object, const Affine64& world_to_object,
                                       std::uint32_t id) {
  if (object >= objects_.size())
    throw std::runtime_error("float reference: instance of unknown object " +
                             std::to_string(object));
  instances_.push_back(FloatInstance{world_to_object, to_float(world_to_object), object, id});
  return static_cast<std::uint32_t>(instances_.size() - 1);
}

void FloatScene::set_top(const KdTree& tree) {
  const auto item_base = static_cast<std::uint32_t>(items_.size());
  for (std::uint32_t item : tree.items) {
    if (item >= instances_.size())
      throw std::runtime_error("float reference: the top-level tree lists instance " +
                               std::to_string(item) + ", which does not exist");
    items_.push_back(item);
  }
  top_root_ = append_tree(tree, item_base);
  top_bounds_ = tree.bounds;
  has_top_ = true;
}

// ---- traversal ----------------------------------------------------------------------------------

// Front-to-back kd traversal (Wald's formulation, docs/cycle-model.md): d = (split - O) / D per
// inner node; the near child is the one the direction's sign points away from; the far child is
// pushed with [d, t_far]. After a leaf, the ray ends when its closest hit lies within the leaf.
// Visit(leaf_node, t_near, t_far) processes one leaf and returns true to stop.
template <class Visit>
static void traverse(const FloatNode* nodes, std::uint32_t root, const FloatRay& ray, float t_near,
                     float t_far, FloatTraceStats& stats, Visit&& visit) {
  StackEntry stack[kMaxDepth];
  int top = 0;
  std::uint32_t node = root;
  for (;;) {
    FloatNode n = nodes[node];
    while (!node_is_leaf(n)) {
      ++stats.traversal_steps;
      const std::uint32_t axis = n.bits & 3u;
      const std::uint32_t child = n.bits >> 2;
      const float split = std::bit_cast<float>(n.payload);
      const float dir = ray.direction[static_cast<int>(axis)];
      const float d = (split - ray.origin[static_cast<int>(axis)]) / dir;
      const std::uint32_t flip = std::signbit(dir) ? 1u : 0u;
      const std::uint32_t near_child = child + flip;
      const std::uint32_t far_child = child + (1u - flip);
      // As the traversal unit decides (units/datapath.h traversal_lane): far side only when the
      // plane lies before the segment, near side only when beyond it, otherwise both. Equality
      // visits both: a child can be a slab thinner than the rounding of d (a flat triangle's
      // box), whose interval [d, d] holds the hit. NaN (the ray lies in the plane) visits both
      // over the whole segment.
      if (d < t_near) {
        node = far_child;
      } else if (t_far < d) {
        node = near_child;
      } else if (d == d) {
        stack[top++] = StackEntry{far_child, d, t_far};
        node = near_child;
        t_far = d;
      } else {
        stack[top++] = StackEntry{far_child, t_near, t_far};
        node = near_child;
      }
      n = nodes[node];
    }
    ++stats.leaves;
    if (visit(n, t_far)) return;
    if (top == 0) return;
    --top;
    node = stack[top].node;
    t_near = stack[top].t_near;
    t_far = stack[top].t_far;
  }
}

template <bool kAnyHit>
void FloatScene::trace_object(std::uint32_t instance, const FloatRay& world, float t_min,
                              FloatHit& hit, FloatTraceStats& stats) const {
  const FloatInstance& inst = instances_[instance];
  const FloatObject& obj = objects_[inst.object];
  ++stats.transformations;
  const FloatRay ray =
      step_ == InstanceStep::kBinary64
          ? FloatRay{glm::vec3(inst.world_to_object.apply_point(glm::dvec3(world.origin))),
                     glm::vec3(inst.world_to_object.apply_vector(glm::dvec3(world.direction)))}
          : FloatRay{transform_point(inst.world_to_object32, world.origin),
                     transform_vector(inst.world_to_object32, world.direction)};
  // decision D29: the object's tree is traversed over the ray's whole [t_min, t_best], clipped to
  // the object's box, not to the top-level leaf.
  float t_near = t_min;
  float t_far = hit.t;
  clip_to_box(obj.bounds, ray, t_near, t_far);
  if (!(t_near <= t_far)) return;
  const Affine32* matrices = triangles_.data() + obj.matrix_base;
  traverse(nodes_.data(), obj.root, ray, t_near, t_far, stats,
           [&](const FloatNode& leaf, float leaf_far) {
             const std::uint32_t count = leaf.bits >> 2;
             const std::uint32_t* list = items_.data() + leaf.payload;
             for (std::uint32_t i = 0; i < count; ++i) {
               ++stats.list_entries;
               ++stats.intersections;
               const std::uint32_t tri = list[i];
               float t, u, v, c;
               if (unit_triangle_candidate(matrices[tri], ray, t_min, hit.t, t, u, v, c) &&
                   replaces(hit, t, instance, tri)) {
                 hit = FloatHit{t, u, v, c, instance, tri};
                 if constexpr (kAnyHit) return true;
               }
             }
             // Strict: a hit exactly at the leaf's end may still lose a tie to a later leaf.
             return hit.t < leaf_far;
           });
}

FloatHit FloatScene::trace(const FloatRay& ray, float t_min, float t_max, bool any_hit,
                           FloatTraceStats* stats_out) const {
  FloatTraceStats stats;
  stats.rays = 1;
  FloatHit hit;
  hit.t = t_max;
  if (!has_top_) throw std::runtime_error("float reference: the scene has no top-level tree");
  float t_near = t_min;
  float t_far = t_max;
  clip_to_box(top_bounds_, ray, t_near, t_far);
  if (t_near <= t_far) {
    // The mailbox (paper section 3.1): an instance listed in several top-level leaves is
    // traversed once per ray. A ray visits few instances, so a short list suffices.
    std::uint32_t mailbox[64];
    std::uint32_t mailbox_size = 0;
    std::vector<std::uint32_t> mailbox_overflow;
    traverse(nodes_.data(), top_root_, ray, t_near, t_far, stats,
             [&](const FloatNode& leaf, float leaf_far) {
               const std::uint32_t count = leaf.bits >> 2;
               const std::uint32_t* list = items_.data() + leaf.payload;
               for (std::uint32_t i = 0; i < count; ++i) {
                 ++stats.list_entries;
                 const std::uint32_t inst = list[i];
                 const bool seen =
                     std::find(mailbox, mailbox + mailbox_size, inst) != mailbox + mailbox_size ||
                     std::find(mailbox_overflow.begin(), mailbox_overflow.end(), inst) !=
                         mailbox_overflow.end();
                 if (seen) {
                   ++stats.mailbox_skips;
                   continue;
                 }
                 if (mailbox_size < 64)
                   mailbox[mailbox_size++] = inst;
                 else
                   mailbox_overflow.push_back(inst);
                 if (any_hit) {
                   trace_object<true>(inst, ray, t_min, hit, stats);
                   if (hit.hit()) return true;
                 } else {
                   trace_object<false>(inst, ray, t_min, hit, stats);
                 }
               }
               return hit.t < leaf_far;
             });
  }
  if (!hit.hit()) hit.t = std::numeric_limits<float>::infinity();
  if (stats_out) *stats_out += stats;
  return hit;
}

FloatHit trace_float(const FloatScene& scene, const FloatRay& ray, float t_min, float t_max) {
  return scene.trace(ray, t_min, t_max);
}

FloatRay primary_ray(const PrimaryBasis32& c, int x, int y) {
  const float px = static_cast<float>(x);
  const float py = static_cast<float>(y);
  FloatRay r;
  // Origin step of R' = ((0,0,0), ...): (Cr*0 + Cu*0) + (Cd*0 + Cp) = Cp.
  r.origin = c.cp;
  for (int i = 0; i < 3; ++i)
    r.direction[i] = (c.cr[i] * px + c.cu[i] * py) + (c.cd[i] + 0.0f);
  return r;
}

std::vector<FloatRay> primary_rays(const PrimaryBasis32& camera, int width, int height) {
  std::vector<FloatRay> rays;
  rays.reserve(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      rays.push_back(primary_ray(camera, x, y));
  return rays;
}

// ---- the image's view ---------------------------------------------------------------------------

FloatScene::FloatScene(const BuiltImage& image, InstanceStep step) : step_(step) {
  for (const ObjectInfo& o : image.objects) {
    if (o.stored && !o.tree.nodes.empty()) {
      add_object(o.tree, o.t_delta);
    } else {
      // Not in the image (no instance uses it, or nothing of it survived): an empty leaf.
      KdTree empty;
      empty.nodes.push_back(KdTreeNode{true, 0, 0.0f, 0, 0, 0});
      add_object(empty, o.t_delta);
    }
    objects_.back().shading_base = o.shading_base;
  }
  for (const InstanceInfo& i : image.instances) {
    if (i.object >= objects_.size())
      throw std::runtime_error("float reference: instance of unknown object " +
                               std::to_string(i.object));
    instances_.push_back(FloatInstance{i.world_to_object, i.world_to_object32, i.object, i.id});
  }
  set_top(image.top);
}

// ---- shading (docs/shading.md, in binary32) -----------------------------------------------------

namespace {

using memif::MaterialRecord;

// dot(a, b) := (a.x*b.x + a.y*b.y) + (a.z*b.z + 0): a transformation-unit row.
inline float dot_t(const glm::vec3& a, const glm::vec3& b) {
  return (a.x * b.x + a.y * b.y) + (a.z * b.z + 0.0f);
}

inline std::uint32_t channel(std::uint32_t rgb, int c) {
  return (rgb >> (8 * c)) & 255u;
}
inline std::uint32_t mul8(std::uint32_t a, std::uint32_t b) {
  return (a * b + 127u) / 255u;
}

// fix16(x) = clamp(floor(x*65536 + 0.5), 0, 65536), exact on the float value; NaN -> 0.
inline std::uint32_t fix16(float x) {
  const double v = std::floor(static_cast<double>(x) * 65536.0 + 0.5);
  if (!(v > 0.0)) return 0;
  return v >= 65536.0 ? 65536u : static_cast<std::uint32_t>(v);
}
// fix8(x) = clamp(floor(x*256 + 0.5), 0, 256); NaN -> 0.
inline std::uint32_t fix8(float x) {
  const double v = std::floor(static_cast<double>(x) * 256.0 + 0.5);
  if (!(v > 0.0)) return 0;
  return v >= 256.0 ? 256u : static_cast<std::uint32_t>(v);
}

// One child ray's origin: T_R = [D, n, D; O] on R'_o = (a, 0, b): (D*a + n*0) + (D*b + O).
inline glm::vec3 child_origin(const glm::vec3& d, const glm::vec3& n, const glm::vec3& o, float a,
                              float b) {
  glm::vec3 r;
  for (int i = 0; i < 3; ++i)
    r[i] = (d[i] * a + n[i] * 0.0f) + (d[i] * b + o[i]);
  return r;
}

struct ShadeLight {
  glm::vec3 position;
  std::uint32_t rgb;
};

// A pending ray of one pixel (docs/shading.md section 7): weight 0..255 and depth.
struct PendingRay {
  FloatRay ray;
  std::uint32_t weight;
  std::uint32_t depth;
};

class Shader {
 public:
  Shader(const FloatScene& scene, const BuiltImage& image, const Scene& host_scene,
         const FloatParams& params)
      : scene_(scene),
        bank_(image.image.bank(memif::kShadingBank)),
        regs_(image.image.registers()),
        format_(image.image.format()),
        params_(params) {
    epsilon_ = to_float(regs_.epsilon);
    max_depth_ =
        params.max_depth >= 0 ? static_cast<std::uint32_t>(params.max_depth) : regs_.max_depth;
    if (host_scene.lights.size() != regs_.light_count)
      throw std::runtime_error("float reference: the scene has " +
                               std::to_string(host_scene.lights.size()) + " lights but the image " +
                               std::to_string(regs_.light_count) +
                               " (build the image from the same scene)");
    for (std::uint32_t l = 0; l < regs_.light_count; ++l)
      lights_.push_back(
          ShadeLight{host_scene.lights[l].position,
                     word(regs_.light_base + memif::kLightWords * l + 3) & 0xFFFFFFu});
  }

  // The pixel colour of a primary ray whose closest hit is `hit` (RGB8 word).
  std::uint32_t pixel(const FloatRay& primary, const FloatHit& hit) {
    std::uint32_t sum[3] = {0, 0, 0};
    pending_.clear();
    shade_ray(PendingRay{primary, 255u, 0u}, hit, sum);
    while (!pending_.empty()) {
      const PendingRay p = pending_.back();
      pending_.pop_back();
      const FloatHit h = scene_.trace(p.ray, 0.0f, std::numeric_limits<float>::infinity());
      shade_ray(p, h, sum);
    }
    std::uint32_t rgb = 0;
    for (int c = 0; c < 3; ++c)
      rgb |= std::min(255u, (sum[c] + 127u) / 255u) << (8 * c);
    return rgb;
  }

 private:
  std::uint32_t word(std::uint32_t address) const {
    if (address >= bank_.size())
      throw std::runtime_error("float reference: shading-bank address " + std::to_string(address) +
                               " is outside the bank");
    return bank_[address];
  }

  void shade_ray(const PendingRay& p, const FloatHit& hit, std::uint32_t sum[3]) {
    if (!hit.hit()) {
      for (int c = 0; c < 3; ++c)
        sum[c] += p.weight * channel(regs_.background_rgb, c);
      return;
    }
    const FloatInstance& inst = scene_.instances()[hit.instance];
    const FloatObject& obj = scene_.objects()[inst.object];
    const glm::vec3& O = p.ray.origin;
    const glm::vec3& D = p.ray.direction;
    const float t = hit.t;

    // Section 4: the world normal M^T * n_o, facing the ray.
    const Affine32& td = scene_.t_delta(inst.object, hit.triangle);
    const glm::vec3 n_o(td.rows[2][0], td.rows[2][1], td.rows[2][2]);
    const auto& m = inst.world_to_object32.rows;  // shading stays binary32
    glm::vec3 n;
    for (int r = 0; r < 3; ++r) {
      const auto rr = static_cast<std::size_t>(r);
      n[r] = (m[0][rr] * n_o.x + m[1][rr] * n_o.y) + (m[2][rr] * n_o.z + 0.0f);
    }
    if (hit.cos > 0.0f) n = -n;
    const float nn = dot_t(n, n);

    // Section 5: material and base colour.
    const std::uint32_t record =
        regs_.shading_record_base + memif::kShadingRecordWords * (obj.shading_base + hit.triangle);
    const std::uint32_t rec_words[4] = {word(record), word(record + 1), word(record + 2),
                                        word(record + 3)};
    const memif::ShadingRecord sr = memif::decode_shading(rec_words);
    const std::uint32_t maddr = regs_.material_base + memif::kMaterialWords * sr.material;
    std::uint32_t mat_words[memif::kMaterialWords];
    for (std::uint32_t i = 0; i < memif::kMaterialWords; ++i)
      mat_words[i] = word(maddr + i);
    const MaterialRecord mat = memif::decode_material(mat_words);
    std::uint32_t base[3];
    for (int c = 0; c < 3; ++c)
      base[c] = channel(mat.diffuse_rgba, c);
    if (mat.texture != memif::kNone) {
      const std::uint32_t texel = sample(mat, sr, hit.u, hit.v);
      for (int c = 0; c < 3; ++c)
        base[c] = mul8(base[c], channel(texel, c));
    }

    // Section 6: ambient + diffuse (+ specular) per light.
    std::uint32_t acc[3];
    for (int c = 0; c < 3; ++c)
      acc[c] = mul8(base[c], channel(regs_.ambient_rgb, c));
    const float k = dot_t(D, n) / nn;
    const float kk = k + k;
    const std::uint32_t spec_rgb = mat.specular_rgb_shininess & 0xFFFFFFu;
    const std::uint32_t shininess = mat.specular_rgb_shininess >> 24;
    const bool specular = spec_rgb != 0 && shininess >= 1;
    glm::vec3 refl;
    for (int r = 0; r < 3; ++r)
      refl[r] = (D[r] * 1.0f + n[r] * (-kk)) + (D[r] * 0.0f + 0.0f);
    for (const ShadeLight& light : lights_) {
      glm::vec3 S;
      for (int r = 0; r < 3; ++r)
        S[r] = (light.position[r] * (-1.0f) + O[r] * 1.0f) + (D[r] * t + 0.0f);
      const float nS = dot_t(n, S);
      if (!(nS < 0.0f)) continue;
      const float SS = dot_t(S, S);
      const float cos_d = (-nS) / std::sqrt(nn * SS);
      if (params_.shadows) {
        constexpr float kShadowEnd = 1.0f - 1.0f / 512.0f;
        // Origin step of R' = ((1, 0, 0), ...): (L*1 + O*0) + (D*0 + 0).
        glm::vec3 origin;
        for (int r = 0; r < 3; ++r)
          origin[r] = (light.position[r] * 1.0f + O[r] * 0.0f) + (D[r] * 0.0f + 0.0f);
        if (scene_.trace(FloatRay{origin, S}, 0.0f, kShadowEnd, true).hit()) continue;
      }
      const std::uint32_t wd = fix8(cos_d);
      for (int c = 0; c < 3; ++c)
        acc[c] += (mul8(base[c], channel(light.rgb, c)) * wd) >> 8;
      if (specular) {
        const float rL = dot_t(refl, S);
        if (rL < 0.0f) {
          const float rr = dot_t(refl, refl);
          const float cos_s = (-rL) / std::sqrt(rr * SS);
          const std::uint32_t ws = fix8(cos_s);
          std::uint32_t pw = 256;
          for (std::uint32_t i = 0; i < shininess; ++i)
            pw = (pw * ws + 128u) >> 8;
          for (int c = 0; c < 3; ++c)
            acc[c] += (mul8(channel(spec_rgb, c), channel(light.rgb, c)) * pw) >> 8;
        }
      }
    }

    // Section 7: weights and children.
    const std::uint32_t kr = mat.reflectivity;
    const std::uint32_t kt = mat.transparency;
    const std::uint32_t kf = mat.refraction;
    const std::uint32_t wl =
        params_.secondary ? mul8(p.weight, 255u - std::min(255u, kr + kt + kf)) : p.weight;
    for (int c = 0; c < 3; ++c)
      sum[c] += wl * std::min(255u, acc[c]);
    if (!params_.secondary || p.depth >= max_depth_) return;
    std::uint32_t wr = mul8(p.weight, kr);
    const std::uint32_t wt = mul8(p.weight, kt);
    const std::uint32_t wf = mul8(p.weight, kf);
    const float e = epsilon_;
    if (wf > 0) {
      // The material's eta for the side the ray comes from: the back of a triangle is inside.
      const float eta = to_float(hit.cos > 0.0f ? mat.eta_leave : mat.eta_enter);
      FloatRay child;
      if (refract_float(D, n, eta, child.direction)) {
        child.origin = child_origin(D, n, O, t, e);  // R'_o = (t, 0, e)
        pending_.push_back(PendingRay{child, wf, p.depth + 1});
      } else {
        wr = std::min(255u, wr + wf);  // total internal reflection: the reflection ray takes it
      }
    }
    if (wr > 0)
      pending_.push_back(PendingRay{FloatRay{child_origin(D, n, O, -e, t), refl}, wr, p.depth + 1});
    if (wt > 0) {
      FloatRay child;
      child.origin = child_origin(D, n, O, e, t);
      for (int r = 0; r < 3; ++r)
        child.direction[r] = (D[r] * 1.0f + n[r] * 0.0f) + (D[r] * 0.0f + 0.0f);
      pending_.push_back(PendingRay{child, wt, p.depth + 1});
    }
  }

  float to_float(std::uint32_t bits) const {
    return static_cast<float>(ff::decode(bits, format_, ff::Subnormals::kFlush));
  }

  // Section 5: the texel colour (RGB8) at barycentrics (u, v), nearest or bilinear.
  std::uint32_t sample(const MaterialRecord& mat, const memif::ShadingRecord& sr, float u,
                       float v) const {
    const std::uint64_t bu = fix16(u);
    const std::uint64_t bv = fix16(v);
    const std::uint64_t bw = bu + bv >= 65536u ? 0u : 65536u - bu - bv;
    const std::uint64_t s = sr.tex_u[0] * bu + sr.tex_u[1] * bv + sr.tex_u[2] * bw;
    const std::uint64_t tt = sr.tex_v[0] * bu + sr.tex_v[1] * bv + sr.tex_v[2] * bw;
    const std::uint64_t W = std::uint64_t{1} << mat.log2_width;
    const std::uint64_t H = std::uint64_t{1} << mat.log2_height;
    const auto texel = [&](std::uint64_t x, std::uint64_t y) {
      return word(mat.texture + static_cast<std::uint32_t>(y * W + x));
    };
    if (!mat.bilinear) {
      const std::uint64_t x = ((s * W) >> 28) & (W - 1);
      const std::uint64_t y = ((tt * H) >> 28) & (H - 1);
      return texel(x, y) & 0xFFFFFFu;
    }
    const std::int64_t X = static_cast<std::int64_t>(s * W) - (std::int64_t{1} << 27);
    const std::int64_t Y = static_cast<std::int64_t>(tt * H) - (std::int64_t{1} << 27);
    const std::uint64_t x0 = static_cast<std::uint64_t>(X >> 28) & (W - 1);
    const std::uint64_t y0 = static_cast<std::uint64_t>(Y >> 28) & (H - 1);
    const std::uint64_t x1 = (x0 + 1) & (W - 1);
    const std::uint64_t y1 = (y0 + 1) & (H - 1);
    const std::uint32_t fx = static_cast<std::uint32_t>((X >> 20) & 255);
    const std::uint32_t fy = static_cast<std::uint32_t>((Y >> 20) & 255);
    const std::uint32_t c00 = texel(x0, y0), c10 = texel(x1, y0);
    const std::uint32_t c01 = texel(x0, y1), c11 = texel(x1, y1);
    std::uint32_t out = 0;
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t top = channel(c00, c) * (256 - fx) + channel(c10, c) * fx;
      const std::uint32_t bot = channel(c01, c) * (256 - fx) + channel(c11, c) * fx;
      out |= ((top * (256 - fy) + bot * fy + 32768u) >> 16) << (8 * c);
    }
    return out;
  }

  const FloatScene& scene_;
  const std::vector<std::uint32_t>& bank_;
  const memif::FrameRegisters& regs_;
  ff::Format format_;
  FloatParams params_;
  float epsilon_ = 0.0f;
  std::uint32_t max_depth_ = 0;
  std::vector<ShadeLight> lights_;
  std::vector<PendingRay> pending_;
};

}  // namespace

bool refract_float(const glm::vec3& d, const glm::vec3& n, float eta, glm::vec3& direction) {
  const float nd = dot_t(n, d);
  const float dd = dot_t(d, d);
  const float nn = dot_t(n, n);
  const float ec = eta * (-nd);
  const float g = 1.0f - eta * eta;
  const float radicand = g * (dd * nn) + ec * ec;
  if (radicand < 0.0f) return false;
  const float mu = (ec - std::sqrt(radicand)) / nn;
  for (int r = 0; r < 3; ++r)
    direction[r] = (d[r] * eta + n[r] * mu) + (d[r] * 0.0f + 0.0f);
  return true;
}

FloatFrame render_float(const FloatScene& float_scene, const BuiltImage& image, const Scene& scene,
                        const FloatParams& params) {
  const int w = image.params.width;
  const int h = image.params.height;
  const PrimaryBasis32 basis = to_float(image.basis);
  FloatFrame frame;
  frame.width = w;
  frame.height = h;
  frame.pixels.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  frame.rgb.assign(frame.pixels.size() * 3, 0);
  std::optional<Shader> shader;
  if (params.shade) shader.emplace(float_scene, image, scene, params);
  const float inf = std::numeric_limits<float>::infinity();
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      FloatPixel& px = frame.pixels[i];
      px.ray = primary_ray(basis, x, y);
      px.hit = float_scene.trace(px.ray, 0.0f, inf, false, &frame.stats);
      if (px.hit.hit()) px.instance_id = float_scene.instances()[px.hit.instance].id;
      if (shader) {
        const std::uint32_t rgb = shader->pixel(px.ray, px.hit);
        for (int c = 0; c < 3; ++c)
          frame.rgb[3 * i + static_cast<std::size_t>(c)] =
              static_cast<std::uint8_t>(channel(rgb, c));
      }
    }
  }
  return frame;
}

FloatFrame render_float(const BuiltImage& image, const Scene& scene, const FloatParams& params) {
  const FloatScene float_scene(image, params.instance_step);
  return render_float(float_scene, image, scene, params);
}

}  // namespace saarcor::host
