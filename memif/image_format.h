// The memory image: what every 32-bit word in the SaarCOR SRAM banks means (docs/memory-image.md).
// This header is the one contract between host/ (which writes images) and units/ (which reads
// them through the caches). It depends on fixedfloat/ and the standard library only.
//
// Banks (prototype: six independent 32-bit banks of 4 MB):
//   0, 1  double-buffered frame buffer: pixel (x, y) at word y*width + x, RGB8 in bits 0..23
//   2     shading data: material table, light table, per-triangle shading records, textures
//   3-5   scene data: kd-nodes, list entries and matrix rows, interleaved item by item
//
// Scene data are typed arrays of items, addressed by item index (the address a cache sees):
//   node  2 words   kd-tree node (top-level tree and every object's bottom-level tree)
//   list  1 word    leaf list entry: instance id (top-level leaf) or triangle id (bottom level)
//   row   3 words   one row of an affine 3x4 matrix: four floats packed (fixedfloat/pack.h);
//                   4 words for formats wider than 24 bits
// Item i of a type lives in scene bank (i mod 3) at word region_base[type] + (i div 3)*item_words,
// so consecutive items spread over the three banks (decision D22) and no item straddles banks.
//
// Instance record (6 rows, at row index instance_row_base + 6*instance):
//   rows 0-2  world -> object affine matrix, row r = (m_r0, m_r1, m_r2, t_r)
//   row 3     three 32-bit words: bottom-level root node index, row index of the object's
//             triangle 0 (its T_delta rows follow, 3 per triangle), shading record index of
//             the object's triangle 0
//   rows 4-5  object-space bounds: (min x, y, z, 0) and (max x, y, z, 0)
// Triangle matrix (3 rows per triangle, at triangle_row_base + 3*triangle_id): T_delta, the
// object -> unit-triangle transform (paper section 2.1.1 with the erratum of decision D11: the
// third column of T_delta^-1 is the unit normal), so row 2 of T_delta is the unit normal. Every
// triangle of a mesh has a slot, degenerate ones included (all-zero rows, never listed), so a
// triangle id is the triangle's index within its mesh.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "fixedfloat/format.h"
#include "fixedfloat/pack.h"

namespace saarcor::memif {

inline constexpr int kNumBanks = 6;
inline constexpr int kFrameBank0 = 0;
inline constexpr int kFrameBank1 = 1;
inline constexpr int kShadingBank = 2;
inline constexpr int kFirstSceneBank = 3;
inline constexpr int kSceneBanks = 3;
inline constexpr std::uint32_t kDefaultBankWords = 1u << 20;  // 4 MB of 32-bit words
inline constexpr std::uint32_t kNone = 0xFFFFFFFFu;           // "no address", "no hit"

enum class ItemType : std::uint8_t { kNode = 0, kList = 1, kRow = 2 };
inline constexpr int kItemTypes = 3;

inline const char* item_type_name(ItemType t) {
  switch (t) {
    case ItemType::kNode:
      return "node";
    case ItemType::kList:
      return "list";
    case ItemType::kRow:
      return "row";
  }
  return "?";
}

// ---- kd-nodes (64 bits, D16) ----------------------------------------------------------------
// inner: word0 = axis (0..2) | empty_left << 2 | empty_right << 3 | child_pair << 4
//        (left child = child_pair, right = child_pair + 1), word1 = split position (float
//        encoding of the image format). The empty flags mark a child that is a leaf without
//        items: the traversal unit learns it with the parent's fetch and never steps into it.
// leaf:  word0 = 3 | count << 2, word1 = index of the first list entry
struct KdNode {
  bool leaf = false;
  std::uint32_t axis = 0;        // inner
  bool empty_left = false;       // inner: the left child is an empty leaf
  bool empty_right = false;      // inner: the right child is an empty leaf
  std::uint32_t child_pair = 0;  // inner
  std::uint32_t split = 0;       // inner: float encoding
  std::uint32_t count = 0;       // leaf
  std::uint32_t first = 0;       // leaf: list entry index
  friend bool operator==(const KdNode&, const KdNode&) = default;
};
inline constexpr std::uint32_t kMaxNodeIndex = (1u << 28) - 1u;

inline std::array<std::uint32_t, 2> encode_node(const KdNode& n) {
  if (n.leaf) return {3u | (n.count << 2), n.first};
  return {n.axis | (std::uint32_t{n.empty_left} << 2) | (std::uint32_t{n.empty_right} << 3) |
              (n.child_pair << 4),
          n.split};
}
inline KdNode decode_node(std::uint32_t w0, std::uint32_t w1) {
  KdNode n;
  if ((w0 & 3u) == 3u) {
    n.leaf = true;
    n.count = w0 >> 2;
    n.first = w1;
  } else {
    n.axis = w0 & 3u;
    n.empty_left = ((w0 >> 2) & 1u) != 0;
    n.empty_right = ((w0 >> 3) & 1u) != 0;
    n.child_pair = w0 >> 4;
    n.split = w1;
  }
  return n;
}

// ---- instance header row --------------------------------------------------------------------
struct InstanceHeader {
  std::uint32_t root = 0;               // bottom-level root node index
  std::uint32_t triangle_row_base = 0;  // row index of triangle 0's T_delta
  std::uint32_t shading_base = 0;       // shading record index of triangle 0
  friend bool operator==(const InstanceHeader&, const InstanceHeader&) = default;
};
inline constexpr int kInstanceRows = 6;
inline constexpr int kTriangleRows = 3;

// ---- shading bank ---------------------------------------------------------------------------
// Material record (kMaterialWords = 8 words at material_base + 8*material; a power of two, so
// the RGS forms the address with a shift as for the 4-word records):
//   w0 diffuse RGB8 (bits 0..23) | opacity A8 (24..31)
//   w1 specular RGB8 | shininess exponent (24..31)
//   w2 texture: word address of texel (0,0) in the shading bank, kNone = untextured
//   w3 log2 texture width (0..3) | log2 height (4..7) | reflectivity 0..255 (8..15)
//      | transparency 0..255 (16..23) | bit 24: bilinear filtering | bit 25: refracts (w4..w6
//      hold its refraction: the RGS reads w4..w7 only then)
//   w4 refraction weight 0..255 (bits 0..7) | reserved, 0 (8..31)
//   w5 eta on entering: 1 / ior (outside over inside; a float encoding of the image format)
//   w6 eta on leaving: ior (inside over outside; a float encoding of the image format)
//   w7 reserved, 0
// A hit on the front of a triangle (D'z <= 0) enters the material, a hit on its back leaves it;
// the host stores both ratios (rounded once from binary64), so the RGS selects one by the sign of
// D'z instead of dividing. Both are 0 in a material that does not refract.
// Texels: RGBA8, one word each, row-major, power-of-two sizes, wrap = repeat.
struct MaterialRecord {
  std::uint32_t diffuse_rgba = 0xFFFFFFFFu;
  std::uint32_t specular_rgb_shininess = 0;
  std::uint32_t texture = kNone;
  std::uint32_t log2_width = 0;
  std::uint32_t log2_height = 0;
  std::uint32_t reflectivity = 0;
  std::uint32_t transparency = 0;
  bool bilinear = true;
  std::uint32_t refraction = 0;  // weight of the refraction ray, 0..255
  std::uint32_t eta_enter = 0;   // float encoding of 1 / ior
  std::uint32_t eta_leave = 0;   // float encoding of ior
  friend bool operator==(const MaterialRecord&, const MaterialRecord&) = default;
};
inline constexpr int kMaterialWords = 8;
inline constexpr int kMaterialBaseWords = 4;                  // w0..w3, what every shaded hit needs
inline constexpr std::uint32_t kMaterialRefracts = 1u << 25;  // w3: w4..w7 are needed
inline std::array<std::uint32_t, kMaterialWords> encode_material(const MaterialRecord& m) {
  return {m.diffuse_rgba,
          m.specular_rgb_shininess,
          m.texture,
          (m.log2_width & 15u) | ((m.log2_height & 15u) << 4) | ((m.reflectivity & 255u) << 8) |
              ((m.transparency & 255u) << 16) | (m.bilinear ? (1u << 24) : 0u) |
              ((m.refraction & 255u) != 0 ? kMaterialRefracts : 0u),
          m.refraction & 255u,
          m.eta_enter,
          m.eta_leave,
          0u};
}
inline MaterialRecord decode_material(const std::uint32_t* w) {
  MaterialRecord m;
  m.diffuse_rgba = w[0];
  m.specular_rgb_shininess = w[1];
  m.texture = w[2];
  m.log2_width = w[3] & 15u;
  m.log2_height = (w[3] >> 4) & 15u;
  m.reflectivity = (w[3] >> 8) & 255u;
  m.transparency = (w[3] >> 16) & 255u;
  m.bilinear = ((w[3] >> 24) & 1u) != 0;
  m.refraction = w[4] & 255u;
  m.eta_enter = w[5];
  m.eta_leave = w[6];
  return m;
}

// Shading record per triangle (4 words = 16 B at shading_record_base + 4*record):
//   w0 material index (bits 0..15) | flags (16..31, reserved, 0)
//   w1..w3 texture coordinates of vertices A, B, C: u in bits 0..15, v in bits 16..31, unsigned
//   fixed point 4.12 in texture periods, after subtracting the triangle's integer floor (exact
//   under repeat wrapping); coordinates beyond 16 periods are clamped by the host and counted.
// Barycentrics: hit point = A*u + B*v + C*(1-u-v) (unit-triangle vertices (1,0,0),(0,1,0),(0,0,0)).
struct ShadingRecord {
  std::uint32_t material = 0;
  std::array<std::uint16_t, 3> tex_u{};
  std::array<std::uint16_t, 3> tex_v{};
  friend bool operator==(const ShadingRecord&, const ShadingRecord&) = default;
};
inline constexpr int kShadingRecordWords = 4;
inline constexpr int kTexcoordFracBits = 12;
inline std::array<std::uint32_t, 4> encode_shading(const ShadingRecord& s) {
  std::array<std::uint32_t, 4> w{s.material & 0xFFFFu, 0, 0, 0};
  for (int i = 0; i < 3; ++i)
    w[1 + i] = s.tex_u[i] | (std::uint32_t{s.tex_v[i]} << 16);
  return w;
}
inline ShadingRecord decode_shading(const std::uint32_t* w) {
  ShadingRecord s;
  s.material = w[0] & 0xFFFFu;
  for (int i = 0; i < 3; ++i) {
    s.tex_u[i] = static_cast<std::uint16_t>(w[1 + i] & 0xFFFFu);
    s.tex_v[i] = static_cast<std::uint16_t>(w[1 + i] >> 16);
  }
  return s;
}

// Light record (4 words at light_base + 4*light): w0..w2 position x, y, z (float encodings, one
// per word), w3 intensity RGB8. Point lights, no attenuation (decision D34).
inline constexpr int kLightWords = 4;

// ---- per-frame registers (written by the host over the bus, not stored in SRAM) --------------
// All floats are encodings of the image format.
struct FrameRegisters {
  std::uint32_t width = 512;
  std::uint32_t height = 384;
  // Primary-ray transformation T_init = [Cr, Cu, Cd; Cp] (paper section 2.2.2), pre-scaled by the
  // host (decision D8) so that the RGS issues R' = ((0,0,0), (px, py, 1)) with integer pixel
  // indices px, py: direction = px*Cr + py*Cu + Cd, with the pixel-centre offset folded into Cd.
  std::array<std::uint32_t, 3> cam_r{}, cam_u{}, cam_d{}, cam_p{};
  std::uint32_t top_root = 0;                // top-level root node index
  std::array<std::uint32_t, 3> scene_min{};  // world bounds of the top-level tree
  std::array<std::uint32_t, 3> scene_max{};
  std::uint32_t instance_row_base = 0;  // row index of instance record 0
  std::uint32_t instance_count = 0;
  std::uint32_t material_base = 0;        // shading-bank word address of material record 0
  std::uint32_t shading_record_base = 0;  // shading-bank word address of shading record 0
  std::uint32_t light_base = 0;           // shading-bank word address of light record 0
  std::uint32_t light_count = 0;
  std::uint32_t ambient_rgb = 0x202020u;  // RGB8
  std::uint32_t background_rgb = 0;       // RGB8
  std::uint32_t epsilon = 0;              // self-intersection offset e (float encoding)
  std::uint32_t max_depth = 3;            // secondary-ray depth bound
  std::uint32_t frame_bank = kFrameBank0;
};

// ---- the whole image ---------------------------------------------------------------------
struct SceneRegions {
  // Per scene bank, word offset where each item type's stripe starts, and item counts.
  std::array<std::uint32_t, kItemTypes> base{};   // word offset within every scene bank
  std::array<std::uint32_t, kItemTypes> count{};  // items of each type
};

// Where one word of an item sits.
struct WordLocation {
  int bank = 0;
  std::uint32_t offset = 0;
};

class MemoryImage {
 public:
  MemoryImage() = default;
  MemoryImage(ff::Format format, std::uint32_t bank_words)
      : format_(format), bank_words_(bank_words) {
    for (auto& b : banks_)
      b.assign(bank_words, 0u);
  }

  const ff::Format& format() const { return format_; }
  std::uint32_t bank_words() const { return bank_words_; }
  int item_words(ItemType t) const {
    return t == ItemType::kNode ? 2 : t == ItemType::kList ? 1 : ff::row_words(format_);
  }

  SceneRegions& regions() { return regions_; }
  const SceneRegions& regions() const { return regions_; }
  FrameRegisters& registers() { return regs_; }
  const FrameRegisters& registers() const { return regs_; }

  WordLocation locate(ItemType t, std::uint32_t index, int word = 0) const {
    const auto ti = static_cast<int>(t);
    return {kFirstSceneBank + static_cast<int>(index % kSceneBanks),
            regions_.base[ti] + (index / kSceneBanks) * static_cast<std::uint32_t>(item_words(t)) +
                static_cast<std::uint32_t>(word)};
  }

  std::uint32_t word(int bank, std::uint32_t offset) const { return banks_.at(bank).at(offset); }
  void set_word(int bank, std::uint32_t offset, std::uint32_t value) {
    banks_.at(bank).at(offset) = value;
  }
  std::vector<std::uint32_t>& bank(int b) { return banks_.at(b); }
  const std::vector<std::uint32_t>& bank(int b) const { return banks_.at(b); }

  // Item access by (type, index): what a cache line fill reads.
  std::uint32_t item_word(ItemType t, std::uint32_t index, int word) const {
    const WordLocation l = locate(t, index, word);
    return banks_[l.bank][l.offset];
  }
  KdNode node(std::uint32_t index) const {
    return decode_node(item_word(ItemType::kNode, index, 0), item_word(ItemType::kNode, index, 1));
  }
  std::uint32_t list_entry(std::uint32_t index) const {
    return item_word(ItemType::kList, index, 0);
  }
  // Four float encodings of one matrix row.
  std::array<std::uint32_t, 4> row(std::uint32_t index) const {
    std::array<std::uint32_t, 4> w{};
    for (int i = 0; i < item_words(ItemType::kRow); ++i)
      w[i] = item_word(ItemType::kRow, index, i);
    return ff::unpack_row(w.data(), format_);
  }
  // The header row of an instance record read as three raw words.
  InstanceHeader instance_header(std::uint32_t instance) const {
    const std::uint32_t r = regs_.instance_row_base + kInstanceRows * instance + 3;
    return {item_word(ItemType::kRow, r, 0), item_word(ItemType::kRow, r, 1),
            item_word(ItemType::kRow, r, 2)};
  }

 private:
  ff::Format format_ = ff::kFp24;
  std::uint32_t bank_words_ = kDefaultBankWords;
  std::array<std::vector<std::uint32_t>, kNumBanks> banks_;
  SceneRegions regions_;
  FrameRegisters regs_;
};

// ---- words of a frame sequence (docs/frames.md) ------------------------------------------
// What the host writes between frames and what a frame in flight reads, as words of the banks:
// the host computes both (host/frame_upload.h), the host bus refuses a write into a range the
// frame in flight reads (memif/host_bus.h).

// Words [begin, end) of one bank, named for messages.
struct BankRange {
  int bank = 0;
  std::uint32_t begin = 0;
  std::uint32_t end = 0;
  std::string what;
};

// One run of consecutive words for one bank.
struct UploadRun {
  int bank = 0;
  std::uint32_t offset = 0;
  std::vector<std::uint32_t> words;
};

}  // namespace saarcor::memif
