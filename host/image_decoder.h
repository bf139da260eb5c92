// Reading a memory image back (tests, the functional model's tests, the fuzz harnesses): every
// word the image builder (host/image_builder.h) writes, decoded through the format's accessors
// in memif/image_format.h and checked for consistency on the way.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <span>
#include <vector>

#include "fixedfloat/format.h"
#include "host/triangle_matrix.h"
#include "memif/image_format.h"

namespace saarcor::host {

// One kd-tree as stored: nodes[k] is node root + k (indices in the nodes stay absolute), covering
// every node reachable from the root.
struct DecodedTree {
  std::uint32_t root = 0;
  std::vector<memif::KdNode> nodes;
  const memif::KdNode& node(std::uint32_t index) const { return nodes.at(index - root); }
};

struct DecodedInstance {
  EncodedAffine world_to_object{};  // float encodings, row r = (m_r0, m_r1, m_r2, t_r)
  memif::InstanceHeader header;
  std::array<std::uint32_t, 3> bounds_min{};  // object-space bounds, float encodings
  std::array<std::uint32_t, 3> bounds_max{};
};

struct DecodedLight {
  std::array<std::uint32_t, 3> position{};  // float encodings
  std::uint32_t rgb = 0;
};

struct DecodedTexture {
  std::uint32_t address = 0;  // shading-bank word address of texel (0, 0)
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::vector<std::uint32_t> texels;  // RGBA8, row-major
};

struct DecodedImage {
  ff::Format format;
  memif::FrameRegisters registers;
  memif::SceneRegions regions;
  std::vector<memif::KdNode> nodes;                // every node slot
  std::vector<std::uint32_t> lists;                // every list slot
  std::vector<std::array<std::uint32_t, 4>> rows;  // every row slot as four encodings
  DecodedTree top;
  std::vector<DecodedInstance> instances;
  std::map<std::uint32_t, DecodedTree> bottom;  // by root node index
  std::vector<memif::MaterialRecord> materials;
  std::vector<DecodedLight> lights;
  std::vector<memif::ShadingRecord> shading;  // every shading record (one per triangle slot)
  std::vector<DecodedTexture> textures;       // by ascending address

  std::span<const std::uint32_t> leaf_items(const memif::KdNode& leaf) const;
  // T_delta of triangle `triangle` of the instance's object, as float encodings.
  EncodedAffine triangle_matrix(const DecodedInstance& instance, std::uint32_t triangle) const;
};

// Reads a whole image back through the format's accessors. Throws std::runtime_error naming the
// first inconsistency (a child or list index outside its region, a cycle, a record outside the
// shading bank).
DecodedImage decode_image(const memif::MemoryImage& image);

}  // namespace saarcor::host
