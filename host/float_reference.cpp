// The float reference renderer (DESIGN.md section 9, model 1; paper sections 2.1, 2.2.2, 3.1 and
// DESIGN.md sections 5 and 7): two-level kd-tree traversal, world -> object transform, unit-
// triangle intersection, all in binary32 in the datapath op order. docs/float-reference.md.
#include "host/float_reference.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>

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

// out_r = (m_r0*x + m_r1*y) + (m_r2*z + t_r): the transformation unit's adder tree (DIGEST D5).
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

bool intersect_unit_triangle(const Affine32& t_delta, const FloatRay& ray, float t_min,
                             float t_best, float& t, float& u, float& v, float& cos) {
  const glm::vec3 o = transform_point(t_delta, ray.origin);
  const glm::vec3 d = transform_vector(t_delta, ray.direction);
  const float tt = -o.z / d.z;
  // D'z = 0 gives +-inf or NaN: both fail t < t_best below (t_best is finite or +inf).
  if (!(tt > t_min && tt < t_best)) return false;
  const float uu = o.x + tt * d.x;
  const float vv = o.y + tt * d.y;
  if (!(uu >= 0.0f && vv >= 0.0f && uu + vv <= 1.0f)) return false;
  t = tt;
  u = uu;
  v = vv;
  cos = d.z;
  return true;
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
  instances_.push_back(FloatInstance{to_float(world_to_object), object, id});
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

// Front-to-back kd traversal (Wald's formulation, DESIGN.md section 5): d = (split - O) / D per
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
      if (!(d < t_far)) {  // d >= t_far, or NaN: the ray lies in the plane (either side will do)
        node = near_child;
      } else if (d <= t_near) {
        node = far_child;
      } else {
        stack[top++] = StackEntry{far_child, d, t_far};
        node = near_child;
        t_far = d;
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
  const FloatRay ray{transform_point(inst.world_to_object, world.origin),
                     transform_vector(inst.world_to_object, world.direction)};
  // DIGEST D29: the object's tree is traversed over the ray's whole [t_min, t_best], clipped to
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
               if (intersect_unit_triangle(matrices[tri], ray, t_min, hit.t, t, u, v, c)) {
                 hit = FloatHit{t, u, v, c, instance, tri};
                 if constexpr (kAnyHit) return true;
               }
             }
             return hit.t <= leaf_far;
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
               return hit.t <= leaf_far;
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

}  // namespace saarcor::host
