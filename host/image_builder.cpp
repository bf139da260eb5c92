// The memory image the host uploads (docs/memory-image.md; paper sections 2 and 3). Layout and
// arithmetic: docs/memory-image.md.
#include "host/image_builder.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "host/tree_objective.h"

namespace saarcor::host {

namespace {

using memif::ItemType;
using memif::MemoryImage;

// Sizes in messages: MB (2^20 bytes) with one decimal, KB below one MB.
std::string mb(std::uint64_t bytes) {
  char buf[32];
  if (bytes < 1048576)
    std::snprintf(buf, sizeof buf, "%.1f KB", static_cast<double>(bytes) / 1024.0);
  else
    std::snprintf(buf, sizeof buf, "%.1f MB", static_cast<double>(bytes) / 1048576.0);
  return buf;
}

std::uint32_t to8(float x) {
  if (!(x > 0.0f)) return 0;  // also NaN
  if (x >= 1.0f) return 255;
  return static_cast<std::uint32_t>(std::lround(static_cast<double>(x) * 255.0));
}

std::uint32_t rgb8(const glm::vec3& c) {
  return to8(c.r) | (to8(c.g) << 8) | (to8(c.b) << 16);
}

// A refracting material's index of refraction: finite, within [1/64, 64] (both ratios stay far
// inside every format's range; real media lie in 1..2.5).
double ior_of(const Material& mat, std::size_t m) {
  const double ior = mat.ior;
  if (!(ior >= 1.0 / 64.0 && ior <= 64.0))
    throw std::runtime_error("material " + std::to_string(m) + " (" + mat.name +
                             ") has index of refraction " + std::to_string(ior) +
                             "; expected 1/64..64");
  return ior;
}

// Rounds v into f so that the result is <= v (outward rounding of a box's lower corner).
std::uint32_t round_down(double v, const ff::Format& f) {
  const std::uint32_t e = ff::from_double(v, f, ff::Mode{});
  if (ff::decode(e, f, ff::Subnormals::kFlush) <= v) return e;
  const std::uint32_t mag = e & ~f.sign_mask();
  if (mag == 0) return f.sign_mask() | (1u << f.man_bits);  // below zero: -smallest normal
  if ((e & f.sign_mask()) == 0) {
    const std::uint32_t down = e - 1u;             // next smaller magnitude
    return (down >> f.man_bits) == 0 ? 0u : down;  // a subnormal reads as zero: use +0
  }
  return e + 1u;  // negative: next larger magnitude
}
std::uint32_t round_up(double v, const ff::Format& f) {
  return round_down(-v, f) ^ f.sign_mask();
}

// The nearest float not beyond v in the given direction (dir < 0: <= v).
float float_outward(double v, int dir) {
  float r = static_cast<float>(v);
  if (dir < 0 && static_cast<double>(r) > v) r = std::nextafter(r, -INFINITY);
  if (dir > 0 && static_cast<double>(r) < v) r = std::nextafter(r, INFINITY);
  return r;
}

Aabb transform_bounds(const Aabb& b, const Affine64& m) {
  Aabb out;
  if (b.empty()) return out;
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 p((k & 1) ? b.hi.x : b.lo.x, (k & 2) ? b.hi.y : b.lo.y,
                       (k & 4) ? b.hi.z : b.lo.z);
    const glm::dvec3 q = m.apply_point(p);
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }
  for (int a = 0; a < 3; ++a) {
    out.lo[a] = float_outward(lo[a], -1);
    out.hi[a] = float_outward(hi[a], +1);
  }
  return out;
}

KdTree empty_tree() {
  KdTree t;
  KdTreeNode leaf;
  leaf.leaf = true;
  t.nodes.push_back(leaf);
  t.stats.nodes = 1;
  t.stats.leaves = 1;
  t.stats.empty_leaves = 1;
  return t;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::string object_name(const Scene& scene, std::size_t o) {
  const std::string& n = scene.objects[o].name;
  return "object " + std::to_string(o) + (n.empty() ? "" : " (" + n + ")");
}

// ---- writing items -----------------------------------------------------------------------

void put(MemoryImage& im, ItemType t, std::uint32_t index, int word, std::uint32_t value) {
  const memif::WordLocation l = im.locate(t, index, word);
  im.set_word(l.bank, l.offset, value);
}

void put_node(MemoryImage& im, std::uint32_t index, const memif::KdNode& n) {
  const auto w = memif::encode_node(n);
  put(im, ItemType::kNode, index, 0, w[0]);
  put(im, ItemType::kNode, index, 1, w[1]);
}

void put_row(MemoryImage& im, std::uint32_t index, const std::array<std::uint32_t, 4>& values) {
  const auto w = ff::pack_row(values, im.format());
  for (int i = 0; i < ff::row_words(im.format()); ++i)
    put(im, ItemType::kRow, index, i, w[i]);
}

void put_raw_row(MemoryImage& im, std::uint32_t index, const std::array<std::uint32_t, 3>& w) {
  for (int i = 0; i < ff::row_words(im.format()); ++i)
    put(im, ItemType::kRow, index, i, i < 3 ? w[i] : 0u);
}

// A host tree's nodes at node_base, its lists at list_base.
void put_tree(MemoryImage& im, const KdTree& tree, std::uint32_t node_base, std::uint32_t list_base,
              const std::vector<std::uint32_t>& items) {
  const ff::Format& f = im.format();
  for (std::size_t k = 0; k < tree.nodes.size(); ++k) {
    const KdTreeNode& h = tree.nodes[k];
    memif::KdNode n;
    if (h.leaf) {
      n.leaf = true;
      n.count = h.count;
      n.first = list_base + h.first;
    } else {
      n.axis = h.axis;
      n.child_pair = node_base + h.child;
      const KdTreeNode& left = tree.nodes[h.child];
      const KdTreeNode& right = tree.nodes[h.child + 1];
      n.empty_left = left.leaf && left.count == 0;
      n.empty_right = right.leaf && right.count == 0;
      n.split = ff::from_double(static_cast<double>(h.split), f, ff::Mode{});
      if (ff::decode(n.split, f, ff::Subnormals::kFlush) != static_cast<double>(h.split))
        throw std::runtime_error("kd-tree split " + std::to_string(h.split) +
                                 " is not exact in format " + ff::format_name(f) +
                                 " (KdBuildParams::split_format differs from the image format)");
    }
    put_node(im, node_base + static_cast<std::uint32_t>(k), n);
  }
  for (std::size_t k = 0; k < items.size(); ++k)
    put(im, ItemType::kList, list_base + static_cast<std::uint32_t>(k), 0, items[k]);
}

// Items of one stripe type stored in scene bank j (0..2) when `count` items are interleaved.
std::uint64_t items_in_bank(std::uint64_t count, int j) {
  return count / memif::kSceneBanks + (static_cast<std::uint64_t>(j) < count % memif::kSceneBanks);
}

std::uint64_t stripe_words(std::uint64_t count, int item_words) {
  return (count + memif::kSceneBanks - 1) / memif::kSceneBanks *
         static_cast<std::uint64_t>(item_words);
}

// ---- scene banks ---------------------------------------------------------------------------

std::uint32_t top_copies(const BuiltImage& b) {
  return b.params.top_level_buffers == 2 ? 2u : 1u;
}

// The registers name top-level copy b.top_buffer: its tree's root and its instance records.
void name_top_copy(BuiltImage& b) {
  memif::FrameRegisters& regs = b.image.registers();
  regs.top_root = b.top_buffer * b.top_node_capacity;
  regs.instance_row_base = b.top_buffer * static_cast<std::uint32_t>(memif::kInstanceRows) *
                           static_cast<std::uint32_t>(b.instances.size());
}

// Assigns every node, list and row index and the region bases; throws when the banks overflow.
void assign_scene_layout(BuiltImage& b) {
  const std::uint64_t copies = top_copies(b);
  const std::uint64_t top_nodes = b.top_node_capacity * copies;
  const std::uint64_t top_lists = b.top_list_capacity * copies;
  std::uint64_t nodes = top_nodes, lists = top_lists;
  std::uint64_t rows =
      static_cast<std::uint64_t>(memif::kInstanceRows) * b.instances.size() * copies;
  b.triangle_row_start = static_cast<std::uint32_t>(rows);
  std::uint64_t shading = 0;
  for (ObjectInfo& o : b.objects) {
    if (!o.stored) continue;
    o.node_root = static_cast<std::uint32_t>(std::min<std::uint64_t>(nodes, memif::kNone));
    o.list_base = static_cast<std::uint32_t>(std::min<std::uint64_t>(lists, memif::kNone));
    o.triangle_row_base = static_cast<std::uint32_t>(std::min<std::uint64_t>(rows, memif::kNone));
    o.shading_base = static_cast<std::uint32_t>(std::min<std::uint64_t>(shading, memif::kNone));
    nodes += o.tree.nodes.size();
    lists += o.tree.items.size();
    rows += static_cast<std::uint64_t>(memif::kTriangleRows) * o.triangles;
    shading += o.triangles;
  }
  if (nodes > memif::kMaxNodeIndex + 1ull)
    throw std::runtime_error("scene does not fit: " + std::to_string(nodes) +
                             " kd-nodes exceed the node index range of 2^30");
  if (lists > memif::kNone || rows > memif::kNone)
    throw std::runtime_error("scene does not fit: " + std::to_string(lists) + " list entries and " +
                             std::to_string(rows) + " matrix rows exceed the 32-bit index range");
  const int rw = ff::row_words(b.params.format);
  const std::uint64_t node_words = stripe_words(nodes, 2);
  const std::uint64_t list_words = stripe_words(lists, 1);
  const std::uint64_t row_words = stripe_words(rows, rw);
  const std::uint64_t end = node_words + list_words + row_words;
  const std::uint64_t cap = b.params.bank_words;
  if (end > cap) {
    const char* region = node_words > cap                ? "nodes"
                         : node_words + list_words > cap ? "lists"
                                                         : "rows";
    const std::uint64_t over = (end - cap) * 4 * memif::kSceneBanks;
    throw std::runtime_error(
        "scene does not fit: scene banks 3-5 need " + mb(end * 4 * memif::kSceneBanks) + " of " +
        mb(cap * 4 * memif::kSceneBanks) + " (nodes " + mb(node_words * 4 * memif::kSceneBanks) +
        ", lists " + mb(list_words * 4 * memif::kSceneBanks) + ", rows " +
        mb(row_words * 4 * memif::kSceneBanks) + "; " + region + " overflow by " + mb(over) +
        " = " + std::to_string(over) + " bytes); raise --bank-mb");
  }
  memif::SceneRegions& r = b.image.regions();
  r.base = {0u, static_cast<std::uint32_t>(node_words),
            static_cast<std::uint32_t>(node_words + list_words)};
  r.count = {static_cast<std::uint32_t>(nodes), static_cast<std::uint32_t>(lists),
             static_cast<std::uint32_t>(rows)};
  b.image.registers().instance_count = static_cast<std::uint32_t>(b.instances.size());
  name_top_copy(b);
}

void write_top_level(BuiltImage& b) {
  put_tree(b.image, b.top, b.top_buffer * b.top_node_capacity, b.top_buffer * b.top_list_capacity,
           b.top.items);
}

void write_instance_matrix(BuiltImage& b, std::size_t i) {
  const std::uint32_t r0 =
      b.image.registers().instance_row_base + static_cast<std::uint32_t>(memif::kInstanceRows * i);
  for (int r = 0; r < 3; ++r)
    put_row(b.image, r0 + r, b.instances[i].world_to_object_encoded[r]);
}

// The image's rows 0-2 of instance i (in the copy the registers name) hold its matrix already.
bool instance_matrix_stored(const BuiltImage& b, std::size_t i) {
  const std::uint32_t r0 =
      b.image.registers().instance_row_base + static_cast<std::uint32_t>(memif::kInstanceRows * i);
  for (std::uint32_t r = 0; r < 3; ++r)
    if (b.image.row(r0 + r) != b.instances[i].world_to_object_encoded[r]) return false;
  return true;
}

void write_instance(BuiltImage& b, std::size_t i) {
  const ff::Format& f = b.params.format;
  const InstanceInfo& inst = b.instances[i];
  const ObjectInfo& o = b.objects[inst.object];
  const std::uint32_t r0 =
      b.image.registers().instance_row_base + static_cast<std::uint32_t>(memif::kInstanceRows * i);
  for (int r = 0; r < 3; ++r)
    put_row(b.image, r0 + r, inst.world_to_object_encoded[r]);
  put_raw_row(b.image, r0 + 3, {o.node_root, o.triangle_row_base, o.shading_base});
  std::array<std::uint32_t, 4> lo{}, hi{};
  if (!o.tree.bounds.empty()) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = round_down(o.tree.bounds.lo[a], f);
      hi[a] = round_up(o.tree.bounds.hi[a], f);
    }
  }
  put_row(b.image, r0 + 4, lo);
  put_row(b.image, r0 + 5, hi);
}

// Writes the whole scene-bank content (after assign_scene_layout).
void write_scene_banks(BuiltImage& b) {
  for (int k = 0; k < memif::kSceneBanks; ++k) {
    auto& bank = b.image.bank(memif::kFirstSceneBank + k);
    std::fill(bank.begin(), bank.end(), 0u);
  }
  // Reserved top-level slots hold empty leaves, so every node slot decodes to a valid node.
  memif::KdNode empty;
  empty.leaf = true;
  for (std::uint32_t k = 0; k < b.top_node_capacity * top_copies(b); ++k)
    put_node(b.image, k, empty);
  // Every copy holds the whole top level, so either can serve a frame.
  const std::uint32_t current = b.top_buffer;
  for (std::uint32_t c = 0; c < top_copies(b); ++c) {
    b.top_buffer = c;
    name_top_copy(b);
    write_top_level(b);
    for (std::size_t i = 0; i < b.instances.size(); ++i)
      write_instance(b, i);
  }
  b.top_buffer = current;
  name_top_copy(b);
  const ff::Format& f = b.params.format;
  for (const ObjectInfo& o : b.objects) {
    if (!o.stored) continue;
    put_tree(b.image, o.tree, o.node_root, o.list_base, o.tree.items);
    for (std::uint32_t t = 0; t < o.triangles; ++t) {
      const std::uint32_t r0 = o.triangle_row_base + memif::kTriangleRows * t;
      if (!o.t_delta[t]) continue;  // degenerate: all-zero rows, never listed
      const EncodedAffine e = encode_affine(*o.t_delta[t], f);
      for (int r = 0; r < 3; ++r)
        put_row(b.image, r0 + r, e[r]);
    }
  }
}

void fill_scene_stats(BuiltImage& b) {
  ImageStats& s = b.stats;
  const memif::SceneRegions& r = b.image.regions();
  const int rw = ff::row_words(b.params.format);
  for (int j = 0; j < memif::kSceneBanks; ++j) {
    s.bytes_per_bank[memif::kFirstSceneBank + j] =
        4 * (items_in_bank(r.count[0], j) * 2 + items_in_bank(r.count[1], j) +
             items_in_bank(r.count[2], j) * static_cast<std::uint64_t>(rw));
  }
  s.top_node_bytes = 8 * b.top.nodes.size();
  s.top_list_bytes = 4 * b.top.items.size();
  const std::uint64_t copies = top_copies(b);
  s.reserved_bytes = 8 * (b.top_node_capacity * copies - b.top.nodes.size()) +
                     4 * (b.top_list_capacity * copies - b.top.items.size());
  s.bottom_node_bytes = 8 * (r.count[0] - b.top_node_capacity * copies);
  s.bottom_list_bytes = 4 * (r.count[1] - b.top_list_capacity * copies);
  s.instance_row_bytes = 4ull * rw * memif::kInstanceRows * b.instances.size() * copies;
  s.triangle_row_bytes = 4ull * rw * (r.count[2] - std::uint64_t{b.triangle_row_start});
}

// ---- top level -----------------------------------------------------------------------------

void build_top_level(BuiltImage& b) {
  std::vector<Aabb> boxes;
  std::vector<std::uint32_t> which;
  for (std::size_t i = 0; i < b.instances.size(); ++i) {
    if (!b.instances[i].in_top_level) continue;
    boxes.push_back(b.instances[i].world_bounds);
    which.push_back(static_cast<std::uint32_t>(i));
  }
  const auto t0 = std::chrono::steady_clock::now();
  if (boxes.empty()) {
    b.top = empty_tree();
  } else {
    KdBuildParams top = b.params.kd;
    top.intersection_cost *= b.params.top_item_cost_factor;
    top.max_depth = top_level_depth(b.params, b.instances.size());
    // The node bound is a bound per triangle (a tree no larger than the triangle matrices it
    // indexes); an instance stands for a whole object, and cutting SunCOR's top tree to 4 nodes
    // per instance costs 2.3 % of its frame rate.
    top.max_nodes_per_item = 0.0f;
    b.top = build_kdtree(std::span<const Aabb>(boxes), top);
    for (std::uint32_t& item : b.top.items)
      item = which.at(item);
  }
  b.stats.top_build_seconds = seconds_since(t0);
  ++b.stats.top_level_builds;
}

void update_instance(BuiltImage& b, std::size_t i, const Instance& inst) {
  InstanceInfo& info = b.instances[i];
  const auto w = world_to_object(inst.object_to_world);
  if (!w)
    throw std::runtime_error("instance " + std::to_string(i) + " (node " + std::to_string(inst.id) +
                             ") has a singular or non-affine transform");
  info.id = inst.id;
  info.object = inst.object;
  info.world_to_object = *w;
  info.world_to_object32 = to_float(*w);
  info.world_to_object_encoded = encode_affine(*w, b.params.format);
  if (!all_finite(info.world_to_object_encoded, b.params.format))
    throw std::runtime_error("instance " + std::to_string(i) + " (node " + std::to_string(inst.id) +
                             "): its world -> object matrix overflows format " +
                             ff::format_name(b.params.format));
  const Aabb& ob = b.objects[inst.object].tree.bounds;
  info.world_bounds = transform_bounds(ob, affine_from_glm(inst.object_to_world));
  info.in_top_level = !ob.empty();
}

Camera choose_camera(const Scene& scene, const ImageParams& p) {
  if (p.camera < 0) return scene_camera(scene);
  if (static_cast<std::size_t>(p.camera) >= scene.cameras.size())
    throw std::runtime_error("camera " + std::to_string(p.camera) +
                             " does not exist (the scene has " +
                             std::to_string(scene.cameras.size()) + " cameras)");
  return scene.cameras[static_cast<std::size_t>(p.camera)];
}

void set_view_registers(BuiltImage& b, const Scene& scene) {
  const ff::Format& f = b.params.format;
  memif::FrameRegisters& regs = b.image.registers();
  b.camera = choose_camera(scene, b.params);
  b.basis = primary_basis(b.camera, b.params.width, b.params.height);
  for (int a = 0; a < 3; ++a) {
    regs.cam_r[a] = ff::from_double(b.basis.cr[a], f, ff::Mode{});
    regs.cam_u[a] = ff::from_double(b.basis.cu[a], f, ff::Mode{});
    regs.cam_d[a] = ff::from_double(b.basis.cd[a], f, ff::Mode{});
    regs.cam_p[a] = ff::from_double(b.basis.cp[a], f, ff::Mode{});
  }
  const Aabb& wb = b.top.bounds;
  for (int a = 0; a < 3; ++a) {
    regs.scene_min[a] = wb.empty() ? 0u : round_down(wb.lo[a], f);
    regs.scene_max[a] = wb.empty() ? 0u : round_up(wb.hi[a], f);
  }
}

// ---- shading bank --------------------------------------------------------------------------

struct StoredTexture {
  std::uint32_t log2_width = 0;
  std::uint32_t log2_height = 0;
  std::vector<std::uint32_t> texels;
};

std::uint32_t pow2_at_least(std::uint32_t n) {
  std::uint32_t p = 1;
  while (p < n)
    p <<= 1;
  return p;
}

std::uint32_t average2(std::uint32_t a, std::uint32_t b) {
  std::uint32_t out = 0;
  for (int c = 0; c < 4; ++c) {
    const std::uint32_t x = (a >> (8 * c)) & 255u, y = (b >> (8 * c)) & 255u;
    out |= ((x + y + 1) / 2) << (8 * c);
  }
  return out;
}

// Halves a power-of-two texture along x (or y) with a 2:1 box filter.
void halve_width(std::vector<std::uint32_t>& px, std::uint32_t& pw, std::uint32_t ph) {
  std::vector<std::uint32_t> half(static_cast<std::size_t>(pw / 2) * ph);
  for (std::uint32_t y = 0; y < ph; ++y)
    for (std::uint32_t x = 0; x < pw / 2; ++x)
      half[static_cast<std::size_t>(y) * (pw / 2) + x] =
          average2(px[static_cast<std::size_t>(y) * pw + 2 * x],
                   px[static_cast<std::size_t>(y) * pw + 2 * x + 1]);
  px.swap(half);
  pw /= 2;
}
void halve_height(std::vector<std::uint32_t>& px, std::uint32_t pw, std::uint32_t& ph) {
  std::vector<std::uint32_t> half(static_cast<std::size_t>(pw) * (ph / 2));
  for (std::uint32_t y = 0; y < ph / 2; ++y)
    for (std::uint32_t x = 0; x < pw; ++x)
      half[static_cast<std::size_t>(y) * pw + x] =
          average2(px[static_cast<std::size_t>(2 * y) * pw + x],
                   px[static_cast<std::size_t>(2 * y + 1) * pw + x]);
  px.swap(half);
  ph /= 2;
}

// Halves the larger side (width on a tie) of a stored texture.
void halve(StoredTexture& t) {
  std::uint32_t pw = 1u << t.log2_width, ph = 1u << t.log2_height;
  if (pw >= ph) {
    halve_width(t.texels, pw, ph);
    --t.log2_width;
  } else {
    halve_height(t.texels, pw, ph);
    --t.log2_height;
  }
}

// Nearest-neighbour up to the next power of two, then 2:1 box filtering down to at most
// max_size (docs/memory-image.md). Integer arithmetic only: deterministic.
StoredTexture resample(const Texture& t, std::size_t index, std::uint32_t max_size) {
  if (t.width <= 0 || t.height <= 0 ||
      t.rgba.size() != static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height))
    throw std::runtime_error("texture " + std::to_string(index) + " (" + t.name + ") has " +
                             std::to_string(t.rgba.size()) + " texels for a size of " +
                             std::to_string(t.width) + "x" + std::to_string(t.height));
  const auto w = static_cast<std::uint32_t>(t.width), h = static_cast<std::uint32_t>(t.height);
  std::uint32_t pw = pow2_at_least(w), ph = pow2_at_least(h);
  std::vector<std::uint32_t> px(static_cast<std::size_t>(pw) * ph);
  for (std::uint32_t y = 0; y < ph; ++y) {
    const std::uint64_t sy = (2ull * y + 1) * h / (2ull * ph);
    for (std::uint32_t x = 0; x < pw; ++x) {
      const std::uint64_t sx = (2ull * x + 1) * w / (2ull * pw);
      px[static_cast<std::size_t>(y) * pw + x] = t.rgba[sy * w + sx];
    }
  }
  while (pw > max_size)
    halve_width(px, pw, ph);
  while (ph > max_size)
    halve_height(px, pw, ph);
  StoredTexture s;
  while ((1u << s.log2_width) < pw)
    ++s.log2_width;
  while ((1u << s.log2_height) < ph)
    ++s.log2_height;
  s.texels = std::move(px);
  return s;
}

// 4.12 fixed point of x >= 0, clamped to the largest code; counts a clamp.
std::uint16_t texcoord_4_12(double x, std::uint64_t& clamped) {
  const double q = std::nearbyint(x * (1 << memif::kTexcoordFracBits));
  if (q > 65535.0) {
    ++clamped;
    return 65535;
  }
  return static_cast<std::uint16_t>(q);
}

// The light records (at light_base); returns how many of them changed.
std::uint32_t write_lights(BuiltImage& b, const Scene& scene) {
  auto& bank = b.image.bank(memif::kShadingBank);
  std::uint32_t changed = 0;
  for (std::size_t l = 0; l < scene.lights.size(); ++l) {
    const Light& L = scene.lights[l];
    const std::size_t a = b.image.registers().light_base + memif::kLightWords * l;
    std::array<std::uint32_t, memif::kLightWords> w{};
    for (int k = 0; k < 3; ++k)
      w[static_cast<std::size_t>(k)] =
          ff::from_double(static_cast<double>(L.position[k]), b.params.format, ff::Mode{});
    w[3] = rgb8(L.color);
    if (!std::equal(w.begin(), w.end(), bank.begin() + static_cast<std::ptrdiff_t>(a))) ++changed;
    std::copy(w.begin(), w.end(), bank.begin() + static_cast<std::ptrdiff_t>(a));
  }
  return changed;
}

void write_shading_bank(BuiltImage& b, const Scene& scene) {
  MemoryImage& im = b.image;
  memif::FrameRegisters& regs = im.registers();
  ImageStats& s = b.stats;
  const std::size_t materials = std::max<std::size_t>(1, scene.materials.size());
  if (materials > 65536)
    throw std::runtime_error("scene has " + std::to_string(materials) +
                             " materials; shading records address at most 65536");
  // Textures used by a material, stored once each, in texture index order.
  std::vector<std::uint8_t> used(scene.textures.size(), 0);
  for (std::size_t m = 0; m < scene.materials.size(); ++m) {
    const int t = scene.materials[m].texture;
    if (t < -1 || t >= static_cast<int>(scene.textures.size()))
      throw std::runtime_error("material " + std::to_string(m) + " (" + scene.materials[m].name +
                               ") references texture " + std::to_string(t) + " of " +
                               std::to_string(scene.textures.size()));
    if (t >= 0) used[static_cast<std::size_t>(t)] = 1;
  }
  if (b.params.max_texture_size < 1 || b.params.max_texture_size > 32768 ||
      (b.params.max_texture_size & (b.params.max_texture_size - 1)) != 0)
    throw std::runtime_error("maximum texture size " + std::to_string(b.params.max_texture_size) +
                             " is not a power of two in 1..32768");
  std::vector<StoredTexture> textures(scene.textures.size());
  std::uint64_t texel_words = 0;
  for (std::size_t t = 0; t < scene.textures.size(); ++t) {
    if (!used[t]) continue;
    textures[t] = resample(scene.textures[t], t, b.params.max_texture_size);
    texel_words += textures[t].texels.size();
    ++s.textures;
  }
  const std::uint64_t material_words = memif::kMaterialWords * materials;
  const std::uint64_t light_words = memif::kLightWords * scene.lights.size();
  const std::uint64_t record_words = memif::kShadingRecordWords * s.triangle_slots;
  // Textures give way before the scene is refused: halve the largest (lowest index on a tie)
  // until the bank fits or every texture is down to 1x1.
  while (b.params.fit_textures &&
         material_words + light_words + record_words + texel_words > b.params.bank_words) {
    std::size_t largest = textures.size();
    for (std::size_t t = 0; t < textures.size(); ++t)
      if (used[t] && textures[t].texels.size() > 1 &&
          (largest == textures.size() ||
           textures[t].texels.size() > textures[largest].texels.size()))
        largest = t;
    if (largest == textures.size()) break;
    texel_words -= textures[largest].texels.size();
    halve(textures[largest]);
    texel_words += textures[largest].texels.size();
    ++s.texture_halvings;
  }
  for (std::size_t t = 0; t < scene.textures.size(); ++t)
    if (used[t] &&
        ((1u << textures[t].log2_width) != static_cast<std::uint32_t>(scene.textures[t].width) ||
         (1u << textures[t].log2_height) != static_cast<std::uint32_t>(scene.textures[t].height)))
      ++s.resampled_textures;
  const std::uint64_t end = material_words + light_words + record_words + texel_words;
  if (end > b.params.bank_words) {
    const std::uint64_t cap = b.params.bank_words;
    const char* region = material_words > cap                                ? "materials"
                         : material_words + light_words > cap                ? "lights"
                         : material_words + light_words + record_words > cap ? "shading records"
                                                                             : "textures";
    throw std::runtime_error("scene does not fit: shading bank 2 needs " + mb(end * 4) + " of " +
                             mb(cap * 4) + " (materials " + mb(material_words * 4) + ", lights " +
                             mb(light_words * 4) + ", shading records " + mb(record_words * 4) +
                             ", textures " + mb(texel_words * 4) + "; " + region + " overflow by " +
                             mb((end - cap) * 4) + " = " + std::to_string((end - cap) * 4) +
                             " bytes); raise --bank-mb");
  }
  regs.material_base = 0;
  regs.light_base = static_cast<std::uint32_t>(material_words);
  regs.light_count = static_cast<std::uint32_t>(scene.lights.size());
  regs.shading_record_base = static_cast<std::uint32_t>(material_words + light_words);
  auto& bank = im.bank(memif::kShadingBank);
  // Textures.
  std::vector<std::uint32_t> tex_address(scene.textures.size(), memif::kNone);
  std::uint64_t at = material_words + light_words + record_words;
  for (std::size_t t = 0; t < scene.textures.size(); ++t) {
    if (!used[t]) continue;
    tex_address[t] = static_cast<std::uint32_t>(at);
    std::copy(textures[t].texels.begin(), textures[t].texels.end(),
              bank.begin() + static_cast<std::ptrdiff_t>(at));
    at += textures[t].texels.size();
  }
  // Materials.
  for (std::size_t m = 0; m < materials; ++m) {
    memif::MaterialRecord rec;
    if (m < scene.materials.size()) {
      const Material& mat = scene.materials[m];
      rec.diffuse_rgba = to8(mat.base_color.r) | (to8(mat.base_color.g) << 8) |
                         (to8(mat.base_color.b) << 16) | (to8(mat.base_color.a) << 24);
      const float sh = std::clamp(mat.shininess, 0.0f, 255.0f);
      rec.specular_rgb_shininess =
          rgb8(mat.specular) | (static_cast<std::uint32_t>(std::lround(sh)) << 24);
      if (mat.texture >= 0) {
        const auto t = static_cast<std::size_t>(mat.texture);
        rec.texture = tex_address[t];
        rec.log2_width = textures[t].log2_width;
        rec.log2_height = textures[t].log2_height;
      }
      rec.reflectivity = to8(mat.reflectivity);
      rec.transparency = to8(mat.transparency);
      rec.refraction = to8(mat.refraction);
      if (rec.refraction > 0) {
        // Both ratios rounded once from binary64, so the RGS selects one instead of dividing.
        const double ior = ior_of(mat, m);
        rec.eta_enter = ff::from_double(1.0 / ior, b.params.format, ff::Mode{});
        rec.eta_leave = ff::from_double(ior, b.params.format, ff::Mode{});
      }
    }
    rec.bilinear = b.params.bilinear;
    const auto w = memif::encode_material(rec);
    std::copy(w.begin(), w.end(),
              bank.begin() + static_cast<std::ptrdiff_t>(memif::kMaterialWords * m));
  }
  write_lights(b, scene);
  // Shading records: one per triangle slot of every stored object.
  for (std::size_t oi = 0; oi < b.objects.size(); ++oi) {
    const ObjectInfo& info = b.objects[oi];
    if (!info.stored) continue;
    const Object& obj = scene.objects[oi];
    const bool has_uv = !obj.texcoords.empty();
    if (has_uv && obj.texcoords.size() != obj.positions.size())
      throw std::runtime_error(object_name(scene, oi) + " has " +
                               std::to_string(obj.texcoords.size()) + " texture coordinates for " +
                               std::to_string(obj.positions.size()) + " vertices");
    for (std::uint32_t t = 0; t < info.triangles; ++t) {
      memif::ShadingRecord rec;
      rec.material = obj.material.empty() ? 0u : obj.material[t];
      if (rec.material >= materials)
        throw std::runtime_error(object_name(scene, oi) + " triangle " + std::to_string(t) +
                                 " references material " + std::to_string(rec.material) + " of " +
                                 std::to_string(scene.materials.size()));
      if (has_uv) {
        const glm::uvec3& tri = obj.triangles[t];
        const glm::vec2 uv[3] = {obj.texcoords[tri.x], obj.texcoords[tri.y], obj.texcoords[tri.z]};
        for (const glm::vec2& c : uv)
          if (!std::isfinite(c.x) || !std::isfinite(c.y))
            throw std::runtime_error(object_name(scene, oi) + " triangle " + std::to_string(t) +
                                     " has a non-finite texture coordinate");
        // Subtracting the triangle's integer floor is exact under repeat wrapping.
        const double fu = std::floor(std::min({uv[0].x, uv[1].x, uv[2].x}));
        const double fv = std::floor(std::min({uv[0].y, uv[1].y, uv[2].y}));
        for (int k = 0; k < 3; ++k) {
          std::uint64_t clamped = 0;
          rec.tex_u[k] = texcoord_4_12(static_cast<double>(uv[k].x) - fu, clamped);
          rec.tex_v[k] = texcoord_4_12(static_cast<double>(uv[k].y) - fv, clamped);
          s.clamped_texcoords += clamped > 0 ? 1 : 0;
        }
      }
      const auto w = memif::encode_shading(rec);
      const std::size_t a =
          regs.shading_record_base +
          static_cast<std::size_t>(memif::kShadingRecordWords) * (info.shading_base + t);
      std::copy(w.begin(), w.end(), bank.begin() + static_cast<std::ptrdiff_t>(a));
    }
  }
  s.material_bytes = material_words * 4;
  s.light_bytes = light_words * 4;
  s.shading_record_bytes = record_words * 4;
  s.texture_bytes = texel_words * 4;
  s.bytes_per_bank[memif::kShadingBank] = end * 4;
}

}  // namespace

// The top level's depth limit: the automatic one for every instance the scene has (so a per-frame
// rebuild keeps the budget the bottom trees were built for), at most half the traversal stack;
// kd.max_depth sets the bottom trees' limit (docs/kdtree.md "Depth and the stack").
int top_level_depth(const ImageParams& p, std::size_t instances) {
  return std::min(kd_auto_max_depth(instances), p.stack_entries / 2);
}

int bottom_level_depth(const ImageParams& p, std::size_t triangles, std::size_t instances) {
  return std::min(kd_max_depth(p.kd, triangles), p.stack_entries - top_level_depth(p, instances));
}

std::uint64_t ImageStats::scene_bytes() const {
  std::uint64_t n = 0;
  for (int j = 0; j < memif::kSceneBanks; ++j)
    n += bytes_per_bank[memif::kFirstSceneBank + j];
  return n;
}

BuiltImage build_image(const Scene& scene, const ImageParams& params) {
  if (!params.format.valid())
    throw std::runtime_error("image format " + ff::format_name(params.format) +
                             " is not supported");
  if (params.bank_words == 0) throw std::runtime_error("bank size must be at least one word");
  if (!(params.top_item_cost_factor > 0.0f) || !std::isfinite(params.top_item_cost_factor))
    throw std::runtime_error("top-level item cost factor " +
                             std::to_string(params.top_item_cost_factor) +
                             " must be positive and finite");
  if (params.tree_objective != static_cast<int>(KdObjective::kSahSum) &&
      params.tree_objective != static_cast<int>(KdObjective::kBusiestUnit))
    throw std::runtime_error("kd-tree objective " + std::to_string(params.tree_objective) +
                             " must be 0 (SAH sum) or 1 (busiest unit)");
  if (!(params.tree_objective_ratio >= 1.0f && params.tree_objective_ratio <= 1e6f))
    throw std::runtime_error("kd-tree objective ratio " +
                             std::to_string(params.tree_objective_ratio) + " must be 1..1e6");
  if (params.top_level_buffers != 1 && params.top_level_buffers != 2)
    throw std::runtime_error("top-level copies " + std::to_string(params.top_level_buffers) +
                             " must be 1 or 2 (double-buffered)");
  if (params.stack_entries < 2 || params.stack_entries > 4096)
    throw std::runtime_error("traversal stack of " + std::to_string(params.stack_entries) +
                             " entries is outside 2..4096");
  BuiltImage b;
  b.params = params;
  b.params.kd.split_format = params.format;
  const ff::Format& f = params.format;

  // The frame buffer and the RGS's exact int -> float pixel indices (decision D8).
  const std::uint64_t pixels = static_cast<std::uint64_t>(std::max(params.width, 0)) *
                               static_cast<std::uint64_t>(std::max(params.height, 0));
  const std::uint64_t max_index = 1ull << (f.man_bits + 1);
  if (params.width <= 0 || params.height <= 0 ||
      static_cast<std::uint64_t>(params.width) > max_index ||
      static_cast<std::uint64_t>(params.height) > max_index)
    throw std::runtime_error("image size " + std::to_string(params.width) + "x" +
                             std::to_string(params.height) + " is outside 1.." +
                             std::to_string(max_index) + " (pixel indices must be exact in " +
                             ff::format_name(f) + ")");
  if (pixels > params.bank_words)
    throw std::runtime_error("scene does not fit: frame buffer bank 0 needs " + mb(pixels * 4) +
                             " of " + mb(std::uint64_t{params.bank_words} * 4) + " for " +
                             std::to_string(params.width) + "x" + std::to_string(params.height) +
                             " (overflow by " + std::to_string((pixels - params.bank_words) * 4) +
                             " bytes); raise --bank-mb");

  // Bottom level: T_delta per slot, then the tree over the non-degenerate triangles, for every
  // object an instance uses.
  b.objects.resize(scene.objects.size());
  for (std::size_t i = 0; i < scene.instances.size(); ++i) {
    const std::uint32_t o = scene.instances[i].object;
    if (o >= scene.objects.size())
      throw std::runtime_error("instance " + std::to_string(i) + " references object " +
                               std::to_string(o) + " of " + std::to_string(scene.objects.size()));
    b.objects[o].stored = true;
  }
  for (std::size_t oi = 0; oi < scene.objects.size(); ++oi) {
    ObjectInfo& info = b.objects[oi];
    if (!info.stored) continue;
    const Object& obj = scene.objects[oi];
    const std::size_t n = obj.triangles.size();
    if (n > memif::kNone / memif::kTriangleRows)
      throw std::runtime_error(object_name(scene, oi) + " has too many triangles (" +
                               std::to_string(n) + ")");
    info.triangles = static_cast<std::uint32_t>(n);
    info.t_delta.assign(n, std::nullopt);
    std::vector<std::uint8_t> skip(n, 1);
    for (std::size_t t = 0; t < n; ++t) {
      const glm::uvec3& tri = obj.triangles[t];
      if (tri.x >= obj.positions.size() || tri.y >= obj.positions.size() ||
          tri.z >= obj.positions.size())
        throw std::runtime_error(object_name(scene, oi) + " triangle " + std::to_string(t) +
                                 " indexes a vertex beyond its " +
                                 std::to_string(obj.positions.size()));
      if (t < obj.degenerate.size() && obj.degenerate[t]) continue;
      auto m = triangle_matrix(obj.positions[tri.x], obj.positions[tri.y], obj.positions[tri.z]);
      if (!m || !fits_format(*m, f)) continue;
      info.t_delta[t] = *m;
      skip[t] = 0;
    }
    info.dropped = static_cast<std::uint32_t>(std::count(skip.begin(), skip.end(), 1));
    const auto t0 = std::chrono::steady_clock::now();
    if (info.dropped == n) {
      info.tree = empty_tree();
    } else {
      // Top + bottom must fit the traversal stack (both levels share it).
      KdBuildParams kd = b.params.kd;
      kd.max_depth = bottom_level_depth(params, n - info.dropped, scene.instances.size());
      info.tree = build_kdtree_for_units(
          std::span<const glm::vec3>(obj.positions), std::span<const glm::uvec3>(obj.triangles),
          std::span<const std::uint8_t>(skip), kd, static_cast<KdObjective>(params.tree_objective),
          params.tree_objective_ratio);
    }
    const double secs = seconds_since(t0);
    b.stats.bottom_build_seconds += secs;
    ++b.stats.bottom_level_builds;
    ++b.stats.stored_objects;
    b.stats.triangle_slots += n;
    b.stats.dropped_triangles += info.dropped;
  }

  // Instances and the top level.
  b.instances.resize(scene.instances.size());
  for (std::size_t i = 0; i < scene.instances.size(); ++i)
    update_instance(b, i, scene.instances[i]);
  build_top_level(b);
  bool dynamic = false;
  for (const Instance& inst : scene.instances)
    dynamic = dynamic || inst.dynamic;
  const double headroom = dynamic ? std::max(1.0, params.top_level_headroom) : 1.0;
  b.top_node_capacity =
      static_cast<std::uint32_t>(std::ceil(headroom * static_cast<double>(b.top.nodes.size())));
  b.top_list_capacity =
      static_cast<std::uint32_t>(std::ceil(headroom * static_cast<double>(b.top.items.size())));

  b.image = MemoryImage(f, params.bank_words);
  assign_scene_layout(b);
  write_shading_bank(b, scene);
  write_scene_banks(b);
  fill_scene_stats(b);
  b.stats.frame_buffer_bytes = pixels * 4;
  b.stats.bytes_per_bank[memif::kFrameBank0] = pixels * 4;
  b.stats.bytes_per_bank[memif::kFrameBank1] = pixels * 4;

  // Frame registers.
  memif::FrameRegisters& regs = b.image.registers();
  regs.width = static_cast<std::uint32_t>(params.width);
  regs.height = static_cast<std::uint32_t>(params.height);
  set_view_registers(b, scene);
  const glm::vec3 diag = b.top.bounds.empty() ? glm::vec3(0.0f) : b.top.bounds.hi - b.top.bounds.lo;
  double eps = params.epsilon;
  if (!(eps > 0.0)) eps = 1e-4 * glm::length(glm::dvec3(diag));
  if (!(eps > 0.0) || !std::isfinite(eps)) eps = 1e-4;  // an empty or flat scene
  regs.epsilon = ff::from_double(eps, f, ff::Mode{});
  regs.ambient_rgb = params.ambient_rgb & 0xFFFFFFu;
  regs.background_rgb = params.background_rgb & 0xFFFFFFu;
  regs.max_depth = params.max_depth;
  regs.frame_bank = memif::kFrameBank0;
  return b;
}

std::uint64_t full_upload_bytes(const BuiltImage& image) {
  return image.stats.scene_bytes() + image.stats.bytes_per_bank[memif::kShadingBank];
}

UploadDelta rebuild_top_level(BuiltImage& b, const Scene& scene) {
  if (scene.objects.size() != b.objects.size() || scene.instances.size() != b.instances.size())
    throw std::runtime_error(
        "rebuild_top_level: the scene has " + std::to_string(scene.objects.size()) +
        " objects and " + std::to_string(scene.instances.size()) +
        " instances, the image was built for " + std::to_string(b.objects.size()) + " and " +
        std::to_string(b.instances.size()));
  // Bad input is refused before anything changes.
  for (std::size_t i = 0; i < b.instances.size(); ++i) {
    if (scene.instances[i].object != b.instances[i].object)
      throw std::runtime_error("rebuild_top_level: instance " + std::to_string(i) +
                               " now references another object");
    const auto w = world_to_object(scene.instances[i].object_to_world);
    if (!w || !fits_format(*w, b.params.format))
      throw std::runtime_error("instance " + std::to_string(i) + " (node " +
                               std::to_string(scene.instances[i].id) +
                               ") has a singular, non-affine or out-of-range transform");
  }
  if (scene.lights.size() != b.image.registers().light_count)
    throw std::runtime_error(
        "rebuild_top_level: the scene has " + std::to_string(scene.lights.size()) +
        " lights, the image was built for " + std::to_string(b.image.registers().light_count));
  primary_basis(choose_camera(scene, b.params), b.params.width, b.params.height);
  UploadDelta d;
  std::vector<std::uint8_t> moved(b.instances.size(), 0);
  for (std::size_t i = 0; i < b.instances.size(); ++i) {
    const EncodedAffine before = b.instances[i].world_to_object_encoded;
    update_instance(b, i, scene.instances[i]);
    if (b.instances[i].world_to_object_encoded != before) {
      moved[i] = 1;
      ++d.moved_instances;
    }
  }
  d.light_bytes = 4ull * memif::kLightWords * write_lights(b, scene);
  d.register_bytes = sizeof(memif::FrameRegisters);
  const bool two = top_copies(b) == 2;
  if (two && d.moved_instances == 0) {
    // Nothing the hardware reads of the top level changed: the copy in flight serves on.
    d.top_rebuilt = false;
    set_view_registers(b, scene);
    return d;
  }
  if (two) {  // the frame in flight reads the other copy
    b.top_buffer ^= 1u;
    name_top_copy(b);
  }
  build_top_level(b);
  const int rw = ff::row_words(b.params.format);
  if (b.top.nodes.size() > b.top_node_capacity || b.top.items.size() > b.top_list_capacity) {
    const double headroom = std::max(1.0, b.params.top_level_headroom);
    b.top_node_capacity =
        static_cast<std::uint32_t>(std::ceil(headroom * static_cast<double>(b.top.nodes.size())));
    b.top_list_capacity =
        static_cast<std::uint32_t>(std::ceil(headroom * static_cast<double>(b.top.items.size())));
    assign_scene_layout(b);
    write_scene_banks(b);
    fill_scene_stats(b);
    d.relayout = true;
    d.relayout_bytes = b.stats.scene_bytes();
  } else {
    write_top_level(b);
    std::uint64_t rewritten = 0;
    for (std::size_t i = 0; i < b.instances.size(); ++i) {
      // The other copy holds the matrices of two frames ago: it needs every row that differs.
      if (two ? !instance_matrix_stored(b, i) : moved[i] != 0) {
        write_instance_matrix(b, i);
        ++rewritten;
      }
    }
    fill_scene_stats(b);
    d.top_node_bytes = 8 * b.top.nodes.size();
    d.top_list_bytes = 4 * b.top.items.size();
    d.instance_row_bytes = 4ull * rw * 3 * rewritten;
  }
  set_view_registers(b, scene);
  return d;
}

// ---- decoding --------------------------------------------------------------------------------

std::span<const std::uint32_t> DecodedImage::leaf_items(const memif::KdNode& leaf) const {
  return std::span<const std::uint32_t>(lists).subspan(leaf.first, leaf.count);
}

EncodedAffine DecodedImage::triangle_matrix(const DecodedInstance& instance,
                                            std::uint32_t triangle) const {
  const std::uint64_t r0 =
      instance.header.triangle_row_base + std::uint64_t{memif::kTriangleRows} * triangle;
  if (r0 + 3 > rows.size())
    throw std::runtime_error("triangle " + std::to_string(triangle) + " lies outside the rows");
  return {rows[r0], rows[r0 + 1], rows[r0 + 2]};
}

namespace {

DecodedTree extract_tree(const DecodedImage& d, std::uint32_t root) {
  if (root >= d.nodes.size())
    throw std::runtime_error("corrupt image: root node " + std::to_string(root) + " outside the " +
                             std::to_string(d.nodes.size()) + " nodes");
  std::vector<std::uint32_t> stack{root};
  std::vector<std::uint8_t> seen(d.nodes.size(), 0);
  std::uint32_t last = root;
  while (!stack.empty()) {
    const std::uint32_t k = stack.back();
    stack.pop_back();
    if (seen[k])
      throw std::runtime_error("corrupt image: node " + std::to_string(k) + " is reached twice");
    seen[k] = 1;
    last = std::max(last, k);
    const memif::KdNode& n = d.nodes[k];
    if (n.leaf) {
      if (std::uint64_t{n.first} + n.count > d.lists.size())
        throw std::runtime_error("corrupt image: leaf " + std::to_string(k) + " lists entries " +
                                 std::to_string(n.first) + "+" + std::to_string(n.count) +
                                 " beyond the " + std::to_string(d.lists.size()) + " list entries");
      continue;
    }
    if (n.axis > 2 || std::uint64_t{n.child_pair} + 1 >= d.nodes.size() || n.child_pair <= k)
      throw std::runtime_error("corrupt image: node " + std::to_string(k) + " has child pair " +
                               std::to_string(n.child_pair) + " outside the tree");
    for (int side = 0; side < 2; ++side) {
      const memif::KdNode& c = d.nodes[n.child_pair + static_cast<std::uint32_t>(side)];
      if ((side == 0 ? n.empty_left : n.empty_right) != (c.leaf && c.count == 0))
        throw std::runtime_error("corrupt image: node " + std::to_string(k) +
                                 "'s empty flag of its " + (side == 0 ? "left" : "right") +
                                 " child disagrees with the child");
    }
    stack.push_back(n.child_pair + 1);
    stack.push_back(n.child_pair);
  }
  DecodedTree t;
  t.root = root;
  t.nodes.assign(d.nodes.begin() + root, d.nodes.begin() + last + 1);
  return t;
}

}  // namespace

DecodedImage decode_image(const memif::MemoryImage& image) {
  DecodedImage d;
  d.format = image.format();
  d.registers = image.registers();
  d.regions = image.regions();
  const memif::SceneRegions& r = d.regions;
  const int rw = ff::row_words(d.format);
  const std::uint64_t end =
      stripe_words(r.count[0], 2) + stripe_words(r.count[1], 1) + stripe_words(r.count[2], rw);
  if (r.base[1] < stripe_words(r.count[0], 2) ||
      r.base[2] < r.base[1] + stripe_words(r.count[1], 1) ||
      r.base[2] + stripe_words(r.count[2], rw) > image.bank_words() || end > image.bank_words())
    throw std::runtime_error("corrupt image: scene regions overlap or exceed the bank");
  d.nodes.reserve(r.count[0]);
  for (std::uint32_t i = 0; i < r.count[0]; ++i)
    d.nodes.push_back(image.node(i));
  d.lists.reserve(r.count[1]);
  for (std::uint32_t i = 0; i < r.count[1]; ++i)
    d.lists.push_back(image.list_entry(i));
  d.rows.reserve(r.count[2]);
  for (std::uint32_t i = 0; i < r.count[2]; ++i)
    d.rows.push_back(image.row(i));

  const memif::FrameRegisters& regs = d.registers;
  d.top = extract_tree(d, regs.top_root);
  const std::uint64_t inst_end =
      regs.instance_row_base + std::uint64_t{memif::kInstanceRows} * regs.instance_count;
  if (inst_end > d.rows.size())
    throw std::runtime_error("corrupt image: " + std::to_string(regs.instance_count) +
                             " instance records do not fit in the " +
                             std::to_string(d.rows.size()) + " rows");
  for (std::uint32_t i = 0; i < regs.instance_count; ++i) {
    const std::uint32_t r0 = regs.instance_row_base + memif::kInstanceRows * i;
    DecodedInstance inst;
    for (int k = 0; k < 3; ++k)
      inst.world_to_object[k] = d.rows[r0 + k];
    inst.header = image.instance_header(i);
    for (int a = 0; a < 3; ++a) {
      inst.bounds_min[a] = d.rows[r0 + 4][a];
      inst.bounds_max[a] = d.rows[r0 + 5][a];
    }
    if (!d.bottom.count(inst.header.root))
      d.bottom.emplace(inst.header.root, extract_tree(d, inst.header.root));
    d.instances.push_back(inst);
  }
  for (const auto& node : d.top.nodes)
    if (node.leaf)
      for (std::uint32_t item : d.leaf_items(node))
        if (item >= regs.instance_count)
          throw std::runtime_error("corrupt image: top-level list names instance " +
                                   std::to_string(item) + " of " +
                                   std::to_string(regs.instance_count));

  // Shading bank, in the builder's order: materials up to the light table, lights, one shading
  // record per triangle slot (the rows after the instance records), textures.
  const auto& bank = image.bank(memif::kShadingBank);
  auto need = [&](std::uint64_t from, std::uint64_t words, const char* what) {
    if (from + words > bank.size())
      throw std::runtime_error(std::string("corrupt image: ") + what + " beyond the shading bank");
  };
  if (regs.light_base < regs.material_base)
    throw std::runtime_error("corrupt image: light table before the material table");
  const std::uint32_t materials = (regs.light_base - regs.material_base) / memif::kMaterialWords;
  need(regs.material_base, std::uint64_t{materials} * memif::kMaterialWords, "materials");
  for (std::uint32_t m = 0; m < materials; ++m)
    d.materials.push_back(
        memif::decode_material(&bank[regs.material_base + memif::kMaterialWords * m]));
  need(regs.light_base, std::uint64_t{regs.light_count} * memif::kLightWords, "lights");
  for (std::uint32_t l = 0; l < regs.light_count; ++l) {
    const std::size_t a = regs.light_base + std::size_t{memif::kLightWords} * l;
    d.lights.push_back({{bank[a], bank[a + 1], bank[a + 2]}, bank[a + 3]});
  }
  const std::uint64_t records = (d.rows.size() - inst_end) / memif::kTriangleRows;
  need(regs.shading_record_base, records * memif::kShadingRecordWords, "shading records");
  d.shading.reserve(records);
  for (std::uint64_t s = 0; s < records; ++s)
    d.shading.push_back(
        memif::decode_shading(&bank[regs.shading_record_base + memif::kShadingRecordWords * s]));
  std::map<std::uint32_t, std::pair<std::uint32_t, std::uint32_t>> tex;
  for (const auto& m : d.materials)
    if (m.texture != memif::kNone) tex[m.texture] = {m.log2_width, m.log2_height};
  for (const auto& [address, dims] : tex) {
    DecodedTexture t;
    t.address = address;
    t.width = 1u << dims.first;
    t.height = 1u << dims.second;
    need(address, std::uint64_t{t.width} * t.height, "texture");
    t.texels.assign(bank.begin() + address,
                    bank.begin() + address + std::size_t{t.width} * t.height);
    d.textures.push_back(std::move(t));
  }
  return d;
}

}  // namespace saarcor::host
