// Reading a memory image back: the scene banks' regions, both tree levels (every reachable node
// checked once), the instance records and the shading bank, in the builder's order
// (docs/memory-image.md).
#include "host/image_decoder.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "host/image_builder.h"

namespace saarcor::host {

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

// An inner node's child pair and empty flags, checked against the nodes.
void check_inner_node(const DecodedImage& d, std::uint32_t k) {
  const memif::KdNode& n = d.nodes[k];
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
}

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
    check_inner_node(d, k);
    stack.push_back(n.child_pair + 1);
    stack.push_back(n.child_pair);
  }
  DecodedTree t;
  t.root = root;
  t.nodes.assign(d.nodes.begin() + root, d.nodes.begin() + last + 1);
  return t;
}

// Every node, list entry and row slot of the scene banks, after the regions are checked.
void decode_scene_banks(const memif::MemoryImage& image, DecodedImage& d) {
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
}

// The top-level tree, the instance records and each instance's bottom-level tree; returns the
// row after the instance records (where the triangle rows begin).
std::uint64_t decode_instances(const memif::MemoryImage& image, DecodedImage& d) {
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
  return inst_end;
}

// Refuses a region that reaches beyond the shading bank.
void need_in_bank(const std::vector<std::uint32_t>& bank, std::uint64_t from, std::uint64_t words,
                  const char* what) {
  if (from + words > bank.size())
    throw std::runtime_error(std::string("corrupt image: ") + what + " beyond the shading bank");
}

// The textures the materials name, each once, by ascending address.
void decode_textures(const std::vector<std::uint32_t>& bank, DecodedImage& d) {
  std::map<std::uint32_t, std::pair<std::uint32_t, std::uint32_t>> tex;
  for (const auto& m : d.materials)
    if (m.texture != memif::kNone) tex[m.texture] = {m.log2_width, m.log2_height};
  for (const auto& [address, dims] : tex) {
    DecodedTexture t;
    t.address = address;
    t.width = 1u << dims.first;
    t.height = 1u << dims.second;
    need_in_bank(bank, address, std::uint64_t{t.width} * t.height, "texture");
    t.texels.assign(bank.begin() + address,
                    bank.begin() + address + std::size_t{t.width} * t.height);
    d.textures.push_back(std::move(t));
  }
}

// Shading bank, in the builder's order: materials up to the light table, lights, one shading
// record per triangle slot (the rows after the instance records, from inst_end), textures.
void decode_shading_bank(const memif::MemoryImage& image, std::uint64_t inst_end, DecodedImage& d) {
  const memif::FrameRegisters& regs = d.registers;
  const auto& bank = image.bank(memif::kShadingBank);
  if (regs.light_base < regs.material_base)
    throw std::runtime_error("corrupt image: light table before the material table");
  const std::uint32_t materials = (regs.light_base - regs.material_base) / memif::kMaterialWords;
  need_in_bank(bank, regs.material_base, std::uint64_t{materials} * memif::kMaterialWords,
               "materials");
  for (std::uint32_t m = 0; m < materials; ++m)
    d.materials.push_back(
        memif::decode_material(&bank[regs.material_base + memif::kMaterialWords * m]));
  need_in_bank(bank, regs.light_base, std::uint64_t{regs.light_count} * memif::kLightWords,
               "lights");
  for (std::uint32_t l = 0; l < regs.light_count; ++l) {
    const std::size_t a = regs.light_base + std::size_t{memif::kLightWords} * l;
    d.lights.push_back({{bank[a], bank[a + 1], bank[a + 2]}, bank[a + 3]});
  }
  const std::uint64_t records = (d.rows.size() - inst_end) / memif::kTriangleRows;
  need_in_bank(bank, regs.shading_record_base, records * memif::kShadingRecordWords,
               "shading records");
  d.shading.reserve(records);
  for (std::uint64_t s = 0; s < records; ++s)
    d.shading.push_back(
        memif::decode_shading(&bank[regs.shading_record_base + memif::kShadingRecordWords * s]));
  decode_textures(bank, d);
}

}  // namespace

DecodedImage decode_image(const memif::MemoryImage& image) {
  DecodedImage d;
  d.format = image.format();
  d.registers = image.registers();
  d.regions = image.regions();
  decode_scene_banks(image, d);
  const std::uint64_t inst_end = decode_instances(image, d);
  decode_shading_bank(image, inst_end, d);
  return d;
}

}  // namespace saarcor::host
