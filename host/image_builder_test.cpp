// The memory image (docs/memory-image.md; memif/image_format.h): encode then decode, layout and
// capacity accounting, overflow errors, texture and texcoord encoding, per-frame upload.
#include "host/image_builder.h"
#include "host/tree_settings.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <set>
#include <string>
#include <vector>

namespace saarcor::host {
namespace {

using memif::ItemType;

double dec(std::uint32_t bits, const ff::Format& f = ff::kFp24) {
  return ff::decode(bits, f, ff::Subnormals::kFlush);
}

Material plain_material(const std::string& name, glm::vec4 colour) {
  Material m;
  m.name = name;
  m.base_color = colour;
  return m;
}

// Three triangles, one of them degenerate (collinear), one instance at the identity.
Scene few_triangles() {
  Scene s;
  Object o;
  o.name = "few";
  o.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 2, 1}, {3, 2, 1},
                 {2, 3, 2}, {4, 4, 4}, {5, 5, 5}, {6, 6, 6}};
  o.triangles = {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}};
  o.material = {0, 1, 0};
  s.objects.push_back(o);
  Instance inst;
  inst.object = 0;
  inst.id = 7;
  s.instances.push_back(inst);
  s.materials = {plain_material("red", {1, 0, 0, 1}),
                 plain_material("half", {0.5f, 0.25f, 1, 0.5f})};
  s.lights.push_back(Light{{1, 2, 3}, {1, 0.5f, 0}, -1});
  return s;
}

// A height-field grid of n x n quads (2 n^2 triangles), instanced twice.
Scene grid_two_instances(int n, bool dynamic = false) {
  Scene s;
  Object o;
  o.name = "grid";
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x)
      o.positions.push_back(
          {float(x) / n, float(y) / n, 0.1f * std::sin(0.7f * x) * std::cos(0.5f * y)});
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const unsigned a = unsigned(y * (n + 1) + x), b = a + 1, c = a + unsigned(n + 1), d = c + 1;
      o.triangles.push_back({a, b, d});
      o.triangles.push_back({a, d, c});
    }
  o.material.assign(o.triangles.size(), 0);
  s.objects.push_back(o);
  Instance i0;
  i0.object = 0;
  i0.id = 3;
  i0.dynamic = dynamic;
  i0.object_to_world = glm::translate(glm::dmat4(1.0), glm::dvec3(-2.0, 0.0, 0.0));
  Instance i1 = i0;
  i1.id = 5;
  i1.object_to_world = glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(2.0, 0.5, -1.0)), 0.6,
                                   glm::dvec3(0.0, 1.0, 0.0)) *
                       glm::scale(glm::dmat4(1.0), glm::dvec3(2.0, 1.0, 0.5));
  s.instances = {i0, i1};
  s.materials = {plain_material("grey", {0.5f, 0.5f, 0.5f, 1})};
  s.lights.push_back(Light{{0, 5, 5}, {1, 1, 1}, -1});
  return s;
}

// One quad with a 3x5 texture and texcoords spanning several periods.
Scene textured_quad(float u_span = 2.5f) {
  Scene s;
  Object o;
  o.name = "quad";
  o.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  o.texcoords = {{-1.25f, 0.5f}, {-1.25f + u_span, 0.5f}, {-1.25f + u_span, 3.0f}, {-1.25f, 3.0f}};
  o.triangles = {{0, 1, 2}, {0, 2, 3}};
  o.material = {1, 1};
  s.objects.push_back(o);
  s.instances.push_back(Instance{});
  Texture t;
  t.name = "checker";
  t.width = 3;
  t.height = 5;
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 3; ++x)
      t.rgba.push_back(0xFF000000u | std::uint32_t(y * 16 + x));
  s.textures.push_back(t);
  Material m = plain_material("tex", {1, 1, 1, 1});
  m.texture = 0;
  m.specular = {0.2f, 0.2f, 0.2f};
  m.shininess = 20.0f;
  m.reflectivity = 0.5f;
  s.materials = {plain_material("unused", {0, 1, 0, 1}), m};
  s.lights.push_back(Light{});
  return s;
}

ImageParams small_params() {
  ImageParams p;
  p.width = 64;
  p.height = 48;
  p.bank_words = 1u << 16;  // 256 KB banks keep the tests light
  return p;
}

// The decoded tree equals the host tree: structure, split values (bit for bit after decoding),
// and each leaf's list contents.
void expect_same_tree(const KdTree& host, const DecodedTree& img, const DecodedImage& d,
                      std::uint32_t list_base) {
  ASSERT_GE(img.nodes.size(), host.nodes.size());
  // Every host node is reachable, so the decoded span is exactly the host array.
  ASSERT_EQ(img.nodes.size(), host.nodes.size());
  for (std::size_t k = 0; k < host.nodes.size(); ++k) {
    const KdTreeNode& h = host.nodes[k];
    const memif::KdNode& n = img.nodes[k];
    ASSERT_EQ(n.leaf, h.leaf) << "node " << k;
    if (h.leaf) {
      ASSERT_EQ(n.count, h.count) << "node " << k;
      EXPECT_EQ(n.first, list_base + h.first);
      const auto items = d.leaf_items(n);
      for (std::uint32_t i = 0; i < h.count; ++i)
        EXPECT_EQ(items[i], host.items[h.first + i]);
    } else {
      EXPECT_EQ(n.axis, h.axis);
      EXPECT_EQ(n.child_pair - img.root, h.child);
      EXPECT_EQ(dec(n.split, d.format), static_cast<double>(h.split)) << "node " << k;
    }
  }
}

TEST(ImageBuilder, FewTrianglesRoundTrip) {
  const Scene s = few_triangles();
  const BuiltImage b = build_image(s, small_params());
  const DecodedImage d = decode_image(b.image);
  ASSERT_EQ(b.objects.size(), 1u);
  const ObjectInfo& o = b.objects[0];
  EXPECT_EQ(o.triangles, 3u);
  EXPECT_EQ(o.dropped, 1u);  // the collinear one
  EXPECT_EQ(b.stats.dropped_triangles, 1u);
  EXPECT_FALSE(o.t_delta[2].has_value());

  expect_same_tree(b.top, d.top, d, 0);
  ASSERT_EQ(d.bottom.count(o.node_root), 1u);
  expect_same_tree(o.tree, d.bottom.at(o.node_root), d, o.list_base);
  // The bottom tree lists triangles 0 and 1, never the degenerate one.
  std::set<std::uint32_t> listed;
  for (const auto& n : d.bottom.at(o.node_root).nodes)
    if (n.leaf)
      for (std::uint32_t t : d.leaf_items(n))
        listed.insert(t);
  EXPECT_EQ(listed, (std::set<std::uint32_t>{0, 1}));

  // Matrices: the image holds T_delta rounded once; the degenerate slot is all zero.
  ASSERT_EQ(d.instances.size(), 1u);
  const auto& obj = s.objects[0];
  for (std::uint32_t t = 0; t < 2; ++t) {
    const glm::uvec3 tri = obj.triangles[t];
    const auto want = encoded_triangle_matrix(obj.positions[tri.x], obj.positions[tri.y],
                                              obj.positions[tri.z], ff::kFp24);
    ASSERT_TRUE(want.has_value());
    EXPECT_EQ(d.triangle_matrix(d.instances[0], t), *want) << "triangle " << t;
  }
  const EncodedAffine zero{};
  EXPECT_EQ(d.triangle_matrix(d.instances[0], 2), zero);

  // Shading: materials, lights, records.
  ASSERT_EQ(d.materials.size(), 2u);
  EXPECT_EQ(d.materials[0].diffuse_rgba, 0xFF0000FFu);  // R=255, A=255
  EXPECT_EQ(d.materials[1].diffuse_rgba, (128u << 24) | (255u << 16) | (64u << 8) | 128u);
  EXPECT_EQ(d.materials[0].texture, memif::kNone);
  ASSERT_EQ(d.lights.size(), 1u);
  EXPECT_EQ(dec(d.lights[0].position[0]), 1.0);
  EXPECT_EQ(dec(d.lights[0].position[2]), 3.0);
  EXPECT_EQ(d.lights[0].rgb, 255u | (128u << 8));
  ASSERT_EQ(d.shading.size(), 3u);
  EXPECT_EQ(d.shading[0].material, 0u);
  EXPECT_EQ(d.shading[1].material, 1u);
}

TEST(ImageBuilder, FrameRegisters) {
  const Scene s = few_triangles();
  ImageParams p = small_params();
  p.ambient_rgb = 0x102030;
  p.background_rgb = 0x405060;
  const BuiltImage b = build_image(s, p);
  const memif::FrameRegisters& r = b.image.registers();
  EXPECT_EQ(r.width, 64u);
  EXPECT_EQ(r.height, 48u);
  EXPECT_EQ(r.top_root, 0u);
  EXPECT_EQ(r.instance_count, 1u);
  EXPECT_EQ(r.light_count, 1u);
  EXPECT_EQ(r.ambient_rgb, 0x102030u);
  EXPECT_EQ(r.background_rgb, 0x405060u);
  const PrimaryBasis pb = primary_basis(b.camera, 64, 48);
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(r.cam_r[a], ff::from_double(pb.cr[a], ff::kFp24, {}));
    EXPECT_EQ(r.cam_u[a], ff::from_double(pb.cu[a], ff::kFp24, {}));
    EXPECT_EQ(r.cam_d[a], ff::from_double(pb.cd[a], ff::kFp24, {}));
    EXPECT_EQ(r.cam_p[a], ff::from_double(pb.cp[a], ff::kFp24, {}));
    // Scene bounds contain the two valid triangles (0..3 x 0..3 x 0..2) and no more than the
    // tree's bounds.
    EXPECT_LE(dec(r.scene_min[a]), b.top.bounds.lo[a]);
    EXPECT_GE(dec(r.scene_max[a]), b.top.bounds.hi[a]);
  }
  EXPECT_EQ(dec(r.scene_max[0]), 3.0);
  EXPECT_EQ(dec(r.scene_max[2]), 2.0);  // the degenerate triangle's z = 4..6 is not in the bounds
  // Epsilon: 1e-4 x diagonal (decision D14).
  const glm::dvec3 diag = glm::dvec3(b.top.bounds.hi - b.top.bounds.lo);
  EXPECT_EQ(r.epsilon, ff::from_double(1e-4 * glm::length(diag), ff::kFp24, {}));
  p.epsilon = 0.5;
  EXPECT_EQ(build_image(s, p).image.registers().epsilon, ff::from_double(0.5, ff::kFp24, {}));
}

TEST(ImageBuilder, TheCameraKeyChoosesTheRegistersCamera) {
  Scene s = few_triangles();
  for (const float z : {5.0f, 9.0f}) {
    Camera c;
    c.position = {0.5f, 0.5f, z};
    c.forward = {0, 0, -1};
    c.up = {0, 1, 0};
    c.yfov = 0.8f;
    s.cameras.push_back(c);
  }
  ImageParams p = small_params();
  EXPECT_EQ(build_image(s, p).camera.position.z, 5.0f);  // -1: the first camera
  apply_tree_setting(p, "image.camera=1");
  const BuiltImage b = build_image(s, p);
  EXPECT_EQ(b.camera.position.z, 9.0f);
  EXPECT_EQ(b.image.registers().cam_p[2], ff::from_double(9.0, ff::kFp24, {}));
}

TEST(ImageBuilder, GridWithTwoInstances) {
  const Scene s = grid_two_instances(16);
  const BuiltImage b = build_image(s, small_params());
  const DecodedImage d = decode_image(b.image);
  ASSERT_EQ(d.instances.size(), 2u);
  const ObjectInfo& o = b.objects[0];
  EXPECT_EQ(o.triangles, 512u);
  EXPECT_EQ(o.dropped, 0u);
  // Both instances share the one bottom tree, its matrices and shading records.
  for (int i = 0; i < 2; ++i) {
    const DecodedInstance& di = d.instances[static_cast<std::size_t>(i)];
    EXPECT_EQ(di.header.root, o.node_root);
    EXPECT_EQ(di.header.triangle_row_base, o.triangle_row_base);
    EXPECT_EQ(di.header.shading_base, o.shading_base);
    EXPECT_EQ(di.world_to_object, b.instances[static_cast<std::size_t>(i)].world_to_object_encoded);
    for (int a = 0; a < 3; ++a) {
      EXPECT_LE(dec(di.bounds_min[a]), o.tree.bounds.lo[a]);
      EXPECT_GE(dec(di.bounds_max[a]), o.tree.bounds.hi[a]);
    }
  }
  // Layout: top-level first (root 0), the object's tree after it; instance records first in rows.
  EXPECT_EQ(o.node_root, b.top.nodes.size());
  EXPECT_EQ(o.list_base, b.top.items.size());
  EXPECT_EQ(o.triangle_row_base, 12u);
  EXPECT_EQ(o.shading_base, 0u);
  EXPECT_EQ(d.bottom.size(), 1u);
  expect_same_tree(b.top, d.top, d, 0);
  expect_same_tree(o.tree, d.bottom.at(o.node_root), d, o.list_base);
  // Every triangle's matrix decodes to the once-rounded binary64 T_delta.
  for (std::uint32_t t = 0; t < o.triangles; ++t)
    ASSERT_EQ(d.triangle_matrix(d.instances[1], t), encode_affine(*o.t_delta[t], ff::kFp24));
  // The instance matrix undoes the instance transform (to fp24 precision).
  const glm::dvec3 p_obj(0.25, 0.75, 0.05);
  const glm::dvec3 p_world = glm::dvec3(s.instances[1].object_to_world * glm::dvec4(p_obj, 1.0));
  Affine64 w;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      w.rows[r][c] = dec(d.instances[1].world_to_object[r][c]);
  const glm::dvec3 back = w.apply_point(p_world);
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR(back[a], p_obj[a], 1e-4);
  // Instance metadata.
  EXPECT_EQ(b.instances[0].id, 3u);
  EXPECT_EQ(b.instances[1].id, 5u);
  EXPECT_EQ(b.instances[1].world_to_object32.rows[0][3],
            static_cast<float>(b.instances[1].world_to_object.rows[0][3]));
  // The top tree's leaves name both instances.
  std::set<std::uint32_t> seen;
  for (const auto& n : d.top.nodes)
    if (n.leaf)
      for (std::uint32_t i : d.leaf_items(n))
        seen.insert(i);
  EXPECT_EQ(seen, (std::set<std::uint32_t>{0, 1}));
}

// Both levels share the traversal stack (64 entries in the prototype): the top level's depth
// limit plus every bottom tree's fit it, whatever depth is asked for, so a packet can never
// overflow the stack (DynRtc's stack overflow error stays unreachable for built images).
TEST(ImageBuilder, TopAndBottomDepthsFitTheTraversalStack) {
  const Scene s = grid_two_instances(16);
  ImageParams p = small_params();
  const BuiltImage automatic = build_image(s, p);
  // 512 triangles: 8 + 1.3 * 9 = 19.7, so at most 20 levels below the root.
  EXPECT_LE(automatic.objects[0].tree.stats.depth, 20u);
  EXPECT_GT(automatic.objects[0].tree.stats.depth, 6u);
  std::vector<std::uint32_t> bottom;
  for (int stack : {4, 9, 12}) {
    p.stack_entries = stack;
    p.kd.max_depth = 1000;  // asked for more than the stack holds
    const BuiltImage b = build_image(s, p);
    EXPECT_LE(b.top.stats.depth + b.objects[0].tree.stats.depth, static_cast<std::uint32_t>(stack))
        << stack;
    bottom.push_back(b.objects[0].tree.stats.depth);
  }
  // The stack bounds the trees: a larger one lets the bottom tree go deeper.
  EXPECT_LT(bottom[0], bottom[1]);
  EXPECT_LT(bottom[1], bottom[2]);
  p.stack_entries = 1;
  EXPECT_THROW(build_image(s, p), std::runtime_error);
}

TEST(ImageBuilder, BytesPerBankAccounting) {
  const Scene s = grid_two_instances(16);
  const BuiltImage b = build_image(s, small_params());
  const memif::SceneRegions& r = b.image.regions();
  const std::uint64_t nodes = r.count[0], lists = r.count[1], rows = r.count[2];
  EXPECT_EQ(nodes, b.top.nodes.size() + b.objects[0].tree.nodes.size());
  EXPECT_EQ(lists, b.top.items.size() + b.objects[0].tree.items.size());
  EXPECT_EQ(rows, 2u * 6u + 512u * 3u);
  // fp24: 8 B per node, 4 B per list entry, 12 B per row, spread over the three banks.
  EXPECT_EQ(b.stats.scene_bytes(), 8 * nodes + 4 * lists + 12 * rows);
  EXPECT_EQ(b.stats.top_node_bytes + b.stats.bottom_node_bytes, 8 * nodes);
  EXPECT_EQ(b.stats.top_list_bytes + b.stats.bottom_list_bytes, 4 * lists);
  EXPECT_EQ(b.stats.instance_row_bytes, 2u * 6u * 12u);
  EXPECT_EQ(b.stats.triangle_row_bytes, 512u * 36u);
  EXPECT_EQ(b.stats.reserved_bytes, 0u);  // static scene: no headroom
  // Each scene bank: count the words up to the end of the row stripe that are used by items.
  for (int j = 0; j < 3; ++j) {
    const std::uint64_t per_bank = b.stats.bytes_per_bank[3 + j];
    const auto share = [&](std::uint64_t n, std::uint64_t w) {
      return (n / 3 + (std::uint64_t(j) < n % 3)) * w * 4;
    };
    EXPECT_EQ(per_bank, share(nodes, 2) + share(lists, 1) + share(rows, 3)) << "bank " << 3 + j;
    // Nothing is written beyond the row stripe.
    const std::uint32_t end = r.base[2] + static_cast<std::uint32_t>((rows + 2) / 3 * 3);
    for (std::uint32_t w = end; w < b.image.bank_words(); ++w)
      ASSERT_EQ(b.image.word(3 + j, w), 0u) << "bank " << 3 + j << " word " << w;
  }
  // Shading bank: 1 material (8 words), 1 light, 512 records, no texture.
  EXPECT_EQ(b.stats.bytes_per_bank[2], 32u + 16u + 512u * 16u);
  EXPECT_EQ(b.stats.bytes_per_bank[0], 64u * 48u * 4u);
  EXPECT_EQ(full_upload_bytes(b), b.stats.scene_bytes() + b.stats.bytes_per_bank[2]);
}

TEST(ImageBuilder, TexturedQuad) {
  const Scene s = textured_quad();
  const BuiltImage b = build_image(s, small_params());
  const DecodedImage d = decode_image(b.image);
  ASSERT_EQ(d.materials.size(), 2u);
  const memif::MaterialRecord& m = d.materials[1];
  EXPECT_EQ(m.log2_width, 2u);   // 3 -> 4
  EXPECT_EQ(m.log2_height, 3u);  // 5 -> 8
  EXPECT_EQ(m.reflectivity, 128u);
  EXPECT_EQ(m.specular_rgb_shininess, 51u | (51u << 8) | (51u << 16) | (20u << 24));
  EXPECT_TRUE(m.bilinear);
  ASSERT_EQ(d.textures.size(), 1u);
  EXPECT_EQ(d.textures[0].address, m.texture);
  EXPECT_EQ(b.stats.textures, 1u);
  EXPECT_EQ(b.stats.resampled_textures, 1u);
  EXPECT_EQ(b.stats.texture_bytes, 4u * 8u * 4u);
  // Nearest neighbour from 3x5 onto 4x8: source x = floor((2x+1)*3/8), y = floor((2y+1)*5/16).
  for (std::uint32_t y = 0; y < 8; ++y)
    for (std::uint32_t x = 0; x < 4; ++x) {
      const std::uint32_t sx = (2 * x + 1) * 3 / 8, sy = (2 * y + 1) * 5 / 16;
      EXPECT_EQ(d.textures[0].texels[y * 4 + x], s.textures[0].rgba[sy * 3 + sx]) << x << "," << y;
    }
  // Texcoords: u in {-1.25, 1.25} -> floor -2 -> {0.75, 3.25}; v in {0.5, 3.0} -> {0.5, 3.0}.
  ASSERT_EQ(d.shading.size(), 2u);
  const memif::ShadingRecord& r0 = d.shading[0];  // vertices 0, 1, 2
  EXPECT_EQ(r0.material, 1u);
  EXPECT_EQ(r0.tex_u[0], 3072u);   // 0.75 * 4096
  EXPECT_EQ(r0.tex_u[1], 13312u);  // 3.25 * 4096
  EXPECT_EQ(r0.tex_v[0], 2048u);   // 0.5
  EXPECT_EQ(r0.tex_v[2], 12288u);  // 3.0
  EXPECT_EQ(b.stats.clamped_texcoords, 0u);
  // 20 periods: the far vertices are beyond 16 periods of the floor and clamp to 0xFFFF.
  const BuiltImage wide = build_image(textured_quad(20.0f), small_params());
  const DecodedImage dw = decode_image(wide.image);
  EXPECT_EQ(dw.shading[0].tex_u[1], 0xFFFFu);
  EXPECT_EQ(dw.shading[0].tex_u[0], 3072u);
  EXPECT_EQ(wide.stats.clamped_texcoords, 3u);  // vertex 1 and 2 of triangle 0, vertex 2 of 1
}

TEST(ImageBuilder, LargeTexturesAreBoxFilteredToAtMost1024) {
  Scene s = textured_quad();
  Texture& t = s.textures[0];
  t.width = 2048;
  t.height = 3;
  t.rgba.assign(2048u * 3u, 0);
  for (std::uint32_t x = 0; x < 2048; ++x)
    for (std::uint32_t y = 0; y < 3; ++y)
      t.rgba[y * 2048 + x] = (x & 1) ? 0xFF0000FFu : 0xFF000001u;
  ImageParams p = small_params();
  p.bank_words = 1u << 14;
  const DecodedImage d = decode_image(build_image(s, p).image);
  ASSERT_EQ(d.textures.size(), 1u);
  EXPECT_EQ(d.textures[0].width, 1024u);
  EXPECT_EQ(d.textures[0].height, 4u);
  // Pairs (1, 255) average to 128 (rounded half up); alpha stays 255.
  EXPECT_EQ(d.textures[0].texels[0], 0xFF000080u);
}

TEST(ImageBuilder, SplitValuesAreTheHostFloats) {
  // A finer grid forces many inner nodes with non-trivial split values.
  const Scene s = grid_two_instances(40);
  const BuiltImage b = build_image(s, small_params());
  const ObjectInfo& o = b.objects[0];
  int inner = 0;
  for (std::size_t k = 0; k < o.tree.nodes.size(); ++k) {
    const KdTreeNode& h = o.tree.nodes[k];
    if (h.leaf) continue;
    ++inner;
    const memif::KdNode n = b.image.node(o.node_root + static_cast<std::uint32_t>(k));
    ASSERT_FALSE(n.leaf);
    ASSERT_EQ(static_cast<float>(dec(n.split)), h.split);
  }
  EXPECT_GT(inner, 100);
}

TEST(ImageBuilder, WiderFormatUsesFourWordRows) {
  const Scene s = grid_two_instances(8);
  ImageParams p = small_params();
  p.format = ff::kFp32;
  const BuiltImage b = build_image(s, p);
  EXPECT_EQ(b.image.item_words(ItemType::kRow), 4);
  const DecodedImage d = decode_image(b.image);
  const ObjectInfo& o = b.objects[0];
  expect_same_tree(o.tree, d.bottom.at(o.node_root), d, o.list_base);
  for (std::uint32_t t = 0; t < o.triangles; ++t)
    ASSERT_EQ(d.triangle_matrix(d.instances[0], t), encode_affine(*o.t_delta[t], ff::kFp32));
  EXPECT_EQ(b.stats.triangle_row_bytes, o.triangles * 48u);
}

std::string error_of(const Scene& s, const ImageParams& p) {
  try {
    build_image(s, p);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(ImageBuilder, SceneThatDoesNotFitNamesBankAndOverflow) {
  const Scene s = grid_two_instances(16);
  const BuiltImage ok = build_image(s, small_params());
  const memif::SceneRegions& r = ok.image.regions();
  const std::uint64_t end = r.base[2] + (r.count[2] + 2) / 3 * 3;  // words per scene bank
  ImageParams p = small_params();
  p.bank_words = r.base[2] + 10;  // nodes and lists fit, the rows do not
  p.width = 16;
  p.height = 16;
  const std::string e = error_of(s, p);
  EXPECT_NE(e.find("scene does not fit: scene banks 3-5 need"), std::string::npos) << e;
  EXPECT_NE(e.find("rows overflow by"), std::string::npos) << e;
  EXPECT_NE(e.find("raise --bank-mb"), std::string::npos) << e;
  // The overflow in bytes is exact: the words beyond the bank size, times three banks.
  EXPECT_NE(e.find("= " + std::to_string((end - p.bank_words) * 12) + " bytes"), std::string::npos)
      << e;
  p.bank_words = 100;  // not even the nodes fit
  p.width = 8;
  p.height = 8;
  EXPECT_NE(error_of(s, p).find("nodes overflow by"), std::string::npos) << error_of(s, p);

  // Shading bank: a 64x64 texture (16 KB) in 8 KB banks whose scene banks still fit. Refused
  // when textures may not give way...
  Scene t = textured_quad();
  t.textures[0].width = 64;
  t.textures[0].height = 64;
  t.textures[0].rgba.assign(64 * 64, 0xFF336699u);
  ImageParams q = small_params();
  q.bank_words = 2048;
  q.width = 32;
  q.height = 32;
  q.fit_textures = false;
  const std::string e2 = error_of(t, q);
  EXPECT_NE(e2.find("scene does not fit: shading bank 2 needs 16.1 KB of 8.0 KB"),
            std::string::npos)
      << e2;
  EXPECT_NE(e2.find("textures overflow by 8.1 KB = 8304 bytes"), std::string::npos) << e2;
  // ... and by default halved until they fit: 2048 words hold 16 material, 4 light and 8 record
  // words, so 64x64 -> 32x64 (2048 texels, too many) -> 32x32.
  q.fit_textures = true;
  const BuiltImage fitted = build_image(t, q);
  EXPECT_EQ(fitted.stats.texture_halvings, 2u);
  EXPECT_EQ(fitted.stats.resampled_textures, 1u);
  const DecodedImage dt = decode_image(fitted.image);
  ASSERT_EQ(dt.textures.size(), 1u);
  EXPECT_EQ(dt.textures[0].width, 32u);
  EXPECT_EQ(dt.textures[0].height, 32u);
  EXPECT_EQ(dt.textures[0].texels[31 * 32 + 31], 0xFF336699u);
  EXPECT_EQ(fitted.stats.bytes_per_bank[2], 4u * (28u + 1024u));

  // Frame buffer.
  ImageParams fb = small_params();
  fb.bank_words = 1000;
  const std::string e3 = error_of(few_triangles(), fb);
  EXPECT_NE(e3.find("frame buffer bank 0 needs"), std::string::npos) << e3;
}

// The material record's refraction words (memif/image_format.h): the weight, and both ratios of
// the indices rounded once from binary64: 1 / ior on entering, ior on leaving. A material that
// does not refract keeps them 0. An index outside 1/64..64 is refused.
TEST(ImageBuilder, RefractionWeightAndEtas) {
  Scene s = few_triangles();
  s.materials[1].refraction = 0.8f;
  s.materials[1].ior = 1.33f;
  for (const ff::Format f : {ff::kFp24, ff::Format{7, 23}}) {
    ImageParams p = small_params();
    p.format = f;
    const DecodedImage d = decode_image(build_image(s, p).image);
    ASSERT_EQ(d.materials.size(), 2u);
    const memif::MaterialRecord& m = d.materials[1];
    EXPECT_EQ(m.refraction, 204u);  // 0.8 * 255
    EXPECT_EQ(m.eta_enter, ff::from_double(1.0 / static_cast<double>(1.33f), f, ff::Mode{}));
    EXPECT_EQ(m.eta_leave, ff::from_double(static_cast<double>(1.33f), f, ff::Mode{}));
    EXPECT_NEAR(dec(m.eta_enter, f) * dec(m.eta_leave, f), 1.0, 2e-5);
    EXPECT_EQ(d.materials[0].refraction, 0u);
    EXPECT_EQ(d.materials[0].eta_enter, 0u);
    EXPECT_EQ(d.materials[0].eta_leave, 0u);
  }
  for (const float bad : {0.0f, 100.0f, std::nanf("")}) {
    s.materials[1].ior = bad;
    EXPECT_NE(error_of(s, small_params()).find("material 1 (half) has index of refraction"),
              std::string::npos)
        << bad;
  }
}

TEST(ImageBuilder, BadInputsGiveOneLineErrors) {
  Scene singular = few_triangles();
  singular.instances[0].object_to_world[1] = glm::dvec4(0.0);
  EXPECT_NE(error_of(singular, small_params()).find("instance 0 (node 7) has a singular"),
            std::string::npos);

  Scene bad_material = few_triangles();
  bad_material.objects[0].material[1] = 9;
  EXPECT_NE(error_of(bad_material, small_params()).find("triangle 1 references material 9 of 2"),
            std::string::npos);

  Scene bad_texture = textured_quad();
  bad_texture.textures[0].rgba.pop_back();
  EXPECT_NE(error_of(bad_texture, small_params()).find("has 14 texels for a size of 3x5"),
            std::string::npos);

  Scene bad_uv = textured_quad();
  bad_uv.objects[0].texcoords[2].x = std::nanf("");
  EXPECT_NE(error_of(bad_uv, small_params()).find("non-finite texture coordinate"),
            std::string::npos);

  ImageParams cam = small_params();
  cam.camera = 2;
  EXPECT_NE(error_of(few_triangles(), cam).find("camera 2 does not exist"), std::string::npos);

  Scene bad_object = few_triangles();
  bad_object.instances[0].object = 4;
  EXPECT_NE(error_of(bad_object, small_params()).find("instance 0 references object 4 of 1"),
            std::string::npos);

  ImageParams size = small_params();
  size.width = 0;
  EXPECT_NE(error_of(few_triangles(), size).find("image size 0x48"), std::string::npos);

  for (const float factor : {0.0f, -1.0f, std::nanf(""), HUGE_VALF}) {
    ImageParams top = small_params();
    top.top_item_cost_factor = factor;
    EXPECT_NE(error_of(few_triangles(), top).find("top-level item cost factor"), std::string::npos)
        << factor;
  }
}

TEST(ImageBuilder, FlaggedDegenerateTrianglesAreDropped) {
  Scene s = few_triangles();
  s.objects[0].degenerate = {1, 0, 1};  // the loader says triangle 0 is degenerate too
  const BuiltImage b = build_image(s, small_params());
  EXPECT_EQ(b.objects[0].dropped, 2u);
  EXPECT_EQ(b.objects[0].tree.items, std::vector<std::uint32_t>{1});
}

TEST(ImageBuilder, EmptyAndUnusedObjects) {
  Scene s = few_triangles();
  s.objects.push_back(s.objects[0]);  // object 1: no instance, not stored
  Object flat;
  flat.name = "flat";
  flat.positions = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
  flat.triangles = {{0, 1, 2}};
  s.objects.push_back(flat);  // object 2: only a degenerate triangle
  Instance i2;
  i2.object = 2;
  s.instances.push_back(i2);
  const BuiltImage b = build_image(s, small_params());
  EXPECT_FALSE(b.objects[1].stored);
  EXPECT_EQ(b.objects[1].node_root, memif::kNone);
  EXPECT_TRUE(b.objects[2].stored);
  EXPECT_FALSE(b.instances[1].in_top_level);
  const DecodedImage d = decode_image(b.image);
  EXPECT_EQ(d.bottom.size(), 2u);
  for (const auto& n : d.top.nodes) {
    if (!n.leaf) continue;
    for (std::uint32_t i : d.leaf_items(n)) {
      EXPECT_EQ(i, 0u);
    }
  }
}

TEST(ImageBuilder, SceneWithoutInstancesIsAnEmptyTopLevel) {
  Scene s = few_triangles();
  s.instances.clear();
  const BuiltImage b = build_image(s, small_params());
  EXPECT_EQ(b.stats.stored_objects, 0u);
  const DecodedImage d = decode_image(b.image);
  ASSERT_EQ(d.top.nodes.size(), 1u);
  EXPECT_TRUE(d.top.nodes[0].leaf);
  EXPECT_EQ(d.top.nodes[0].count, 0u);
  EXPECT_EQ(d.registers.instance_count, 0u);
  EXPECT_EQ(d.registers.epsilon, ff::from_double(1e-4, ff::kFp24, {}));
  EXPECT_EQ(b.stats.scene_bytes(), 8u);
}

TEST(ImageBuilder, UploadDeltaWhenOneInstanceMoves) {
  Scene s = grid_two_instances(16, /*dynamic=*/true);
  BuiltImage b = build_image(s, small_params());
  EXPECT_GT(b.stats.reserved_bytes, 0u);  // dynamic: headroom for the top level
  const std::uint64_t full = full_upload_bytes(b);
  const auto root_before = b.objects[0].node_root;
  const std::vector<std::uint32_t> bank_before = b.image.bank(3);

  s.instances[1].object_to_world =
      glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 3.0, 0.0)) * s.instances[1].object_to_world;
  const UploadDelta delta = rebuild_top_level(b, s);
  EXPECT_FALSE(delta.relayout);
  EXPECT_EQ(delta.moved_instances, 1u);
  EXPECT_EQ(delta.instance_row_bytes, 36u);  // three fp24 rows
  EXPECT_EQ(delta.top_node_bytes, 8 * b.top.nodes.size());
  EXPECT_EQ(delta.top_list_bytes, 4 * b.top.items.size());
  EXPECT_GT(delta.total(), 0u);
  EXPECT_LT(delta.total(), full);
  EXPECT_LT(delta.total() * 20, full);  // the bottom level (18 KB of matrices) stays
  EXPECT_EQ(b.objects[0].node_root, root_before);
  // The image agrees with the new top level and the moved instance's matrix.
  const DecodedImage d = decode_image(b.image);
  expect_same_tree(b.top, d.top, d, 0);
  EXPECT_EQ(d.instances[1].world_to_object, b.instances[1].world_to_object_encoded);
  EXPECT_EQ(dec(d.registers.scene_max[1]), static_cast<double>(b.top.bounds.hi[1]));
  // Words that changed in a scene bank all lie in the top-level slots or instance 1's rows.
  const auto& bank_after = b.image.bank(3);
  const memif::SceneRegions& r = b.image.regions();
  for (std::uint32_t w = 0; w < bank_after.size(); ++w) {
    if (bank_after[w] == bank_before[w]) continue;
    const bool top_nodes = w < (b.top_node_capacity + 2) / 3 * 2;
    const bool top_lists = w >= r.base[1] && w < r.base[1] + (b.top_list_capacity + 2) / 3;
    const bool inst_rows =
        w >= r.base[2] && w < r.base[2] + 4 * 3;  // rows 0..11 -> bank words 0..11
    EXPECT_TRUE(top_nodes || top_lists || inst_rows) << "word " << w;
  }
  // A singular transform is refused and leaves the image as it was.
  Scene bad = s;
  bad.instances[0].object_to_world[0] = glm::dvec4(0.0);
  const std::vector<std::uint32_t> bank_ok = b.image.bank(3);
  EXPECT_THROW(rebuild_top_level(b, bad), std::runtime_error);
  EXPECT_EQ(b.image.bank(3), bank_ok);
  // Nothing moves: only the top level and the registers.
  const UploadDelta still = rebuild_top_level(b, s);
  EXPECT_EQ(still.moved_instances, 0u);
  EXPECT_EQ(still.instance_row_bytes, 0u);
}

TEST(ImageBuilder, TopLevelOutgrowingItsSlotsIsLaidOutAgain) {
  // Eight copies stacked in one place: the top level is one leaf. Spread far apart, the SAH
  // splits them, and the new tree no longer fits the slots reserved for it.
  Scene s = grid_two_instances(8, /*dynamic=*/true);
  s.instances.resize(8, s.instances[0]);
  for (Instance& i : s.instances)
    i.object_to_world = glm::dmat4(1.0);
  ImageParams p = small_params();
  p.top_level_headroom = 1.0;  // no spare slots
  BuiltImage b = build_image(s, p);
  ASSERT_EQ(b.top_node_capacity, b.top.nodes.size());
  const std::uint64_t triangle_rows_before = b.stats.triangle_row_bytes;

  Scene other = s;
  other.instances.pop_back();
  EXPECT_THROW(rebuild_top_level(b, other), std::runtime_error);  // not the same instances

  for (std::size_t k = 0; k < s.instances.size(); ++k)
    s.instances[k].object_to_world =
        glm::translate(glm::dmat4(1.0), glm::dvec3(10.0 * double(k), 0.0, 0.0));
  const UploadDelta d = rebuild_top_level(b, s);
  ASSERT_GT(b.top.nodes.size(), 1u);
  EXPECT_TRUE(d.relayout);
  EXPECT_EQ(d.moved_instances, 7u);
  EXPECT_EQ(d.relayout_bytes, b.stats.scene_bytes());
  EXPECT_EQ(b.stats.triangle_row_bytes, triangle_rows_before);
  EXPECT_EQ(b.objects[0].node_root, b.top_node_capacity);
  const DecodedImage dec_img = decode_image(b.image);
  expect_same_tree(b.top, dec_img.top, dec_img, 0);
  expect_same_tree(b.objects[0].tree, dec_img.bottom.at(b.objects[0].node_root), dec_img,
                   b.objects[0].list_base);
  for (std::size_t k = 0; k < s.instances.size(); ++k)
    EXPECT_EQ(dec_img.instances[k].world_to_object, b.instances[k].world_to_object_encoded);
}

TEST(ImageBuilder, DuckRoundTrip) {
  // A real textured glTF model: 4,212 triangles, one 512x512 texture.
  const Scene s = load_scene(std::string(SAARCOR_SHARED_SCENES) + "/Duck/Duck.gltf");
  const BuiltImage b = build_image(s);
  const DecodedImage d = decode_image(b.image);
  ASSERT_EQ(b.objects.size(), 1u);
  const ObjectInfo& o = b.objects[0];
  EXPECT_EQ(o.triangles, 4212u);
  expect_same_tree(b.top, d.top, d, 0);
  expect_same_tree(o.tree, d.bottom.at(o.node_root), d, o.list_base);
  ASSERT_EQ(d.instances.size(), 1u);
  for (std::uint32_t t = 0; t < o.triangles; ++t)
    ASSERT_EQ(d.triangle_matrix(d.instances[0], t), encode_affine(*o.t_delta[t], ff::kFp24));
  ASSERT_EQ(d.shading.size(), 4212u);
  ASSERT_EQ(d.textures.size(), 1u);
  EXPECT_EQ(d.textures[0].width, 512u);
  EXPECT_EQ(d.textures[0].height, 512u);
  EXPECT_EQ(d.textures[0].texels, s.textures[0].rgba);  // already a power of two: unchanged
  EXPECT_EQ(b.stats.resampled_textures, 0u);
  // Texture coordinates of one triangle, recomputed here.
  const Object& obj = s.objects[0];
  for (std::uint32_t t : {0u, 1000u, 4211u}) {
    const glm::uvec3 tri = obj.triangles[t];
    const glm::vec2 uv[3] = {obj.texcoords[tri.x], obj.texcoords[tri.y], obj.texcoords[tri.z]};
    const double fu = std::floor(std::min({uv[0].x, uv[1].x, uv[2].x}));
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(d.shading[t].tex_u[k], std::lround((double(uv[k].x) - fu) * 4096.0)) << t;
  }
  EXPECT_EQ(b.stats.bytes_per_bank[2],
            4u * (8u * d.materials.size() + 4u * d.lights.size() + 4u * 4212u + 512u * 512u));
}

TEST(DecodeImage, CorruptImagesAreRefused) {
  BuiltImage b = build_image(grid_two_instances(4), small_params());
  memif::MemoryImage im = b.image;
  // Point the root's child pair beyond the node region.
  const memif::WordLocation l = im.locate(ItemType::kNode, 0, 0);
  im.set_word(l.bank, l.offset, 0u | (100000u << 4));
  try {
    decode_image(im);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("child pair 100000 outside"), std::string::npos)
        << e.what();
  }
  memif::MemoryImage im2 = b.image;
  im2.registers().instance_count = 1000;
  EXPECT_THROW(decode_image(im2), std::runtime_error);
  // An empty-child flag on a child with items: the traversal would skip geometry.
  const std::uint32_t root = b.objects[0].node_root;
  memif::MemoryImage im3 = b.image;
  memif::KdNode n = im3.node(root);
  ASSERT_FALSE(n.leaf);
  const memif::KdNode left = im3.node(n.child_pair);
  ASSERT_FALSE(left.leaf && left.count == 0);
  n.empty_left = true;
  const memif::WordLocation l3 = im3.locate(ItemType::kNode, root, 0);
  im3.set_word(l3.bank, l3.offset, memif::encode_node(n)[0]);
  try {
    decode_image(im3);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("empty flag of its left child disagrees"),
              std::string::npos)
        << e.what();
  }
}

// Inner nodes flag their empty children (the traversal never steps into them).
TEST(ImageBuilder, InnerNodesFlagTheirEmptyChildren) {
  const BuiltImage b = build_image(grid_two_instances(16), small_params());
  const DecodedImage d = decode_image(b.image);
  int flagged = 0;
  for (const memif::KdNode& n : d.nodes) {
    if (n.leaf) continue;
    const memif::KdNode& l = d.nodes[n.child_pair];
    const memif::KdNode& r = d.nodes[n.child_pair + 1];
    EXPECT_EQ(n.empty_left, l.leaf && l.count == 0);
    EXPECT_EQ(n.empty_right, r.leaf && r.count == 0);
    flagged += n.empty_left + n.empty_right;
  }
  EXPECT_GT(flagged, 0);
  // The encoding keeps the flags apart from the axis and the child pair.
  memif::KdNode x;
  x.axis = 2;
  x.empty_right = true;
  x.child_pair = memif::kMaxNodeIndex;
  x.split = 0x123456u;
  const auto w = memif::encode_node(x);
  EXPECT_EQ(memif::decode_node(w[0], w[1]), x);
  x.empty_right = false;
  x.empty_left = true;
  EXPECT_EQ(memif::decode_node(memif::encode_node(x)[0], w[1]), x);
}

}  // namespace
}  // namespace saarcor::host
