// The memory image the host uploads (docs/memory-image.md; paper section 3: "camera settings and
// scene data are uploaded by the host"; section 2: a top-level kd-tree over object instances,
// one bottom-level tree per object, rebuilt only at the top when instances move). Writes the
// words memif/image_format.h defines; docs/memory-image.md gives the layout and its arithmetic.
//
// Scene banks 3-5 (item-interleaved, decision D22):
//   nodes  [top-level tree, reserved capacity][object 0's tree][object 1's tree]...
//   lists  [top-level lists, reserved capacity][object 0's lists]...
//   rows   [instance records, 6 rows each][object 0's T_delta, 3 rows per triangle slot]...
// Shading bank 2: [materials][lights][shading records, one per triangle slot][textures].
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fixedfloat/format.h"
#include "host/kdtree.h"
#include "host/primary_rays.h"
#include "host/scene.h"
#include "host/triangle_matrix.h"
#include "memif/image_format.h"

namespace saarcor::host {

struct ImageParams {
  ff::Format format = ff::kFp24;                        // every float in the image
  std::uint32_t bank_words = memif::kDefaultBankWords;  // 32-bit words per bank (1M = 4 MB)
  KdBuildParams kd;  // both levels; kd.split_format is forced to `format`
  // The top level's item cost in units of kd.intersection_cost. A top-level item is an object
  // visit: a transformation like a triangle test's, a 6-cycle box clip, the bottom tree's descent
  // and its own triangle tests, about 16 triangle tests' worth (docs/kdtree.md, "Top level").
  float top_item_cost_factor = 16.0f;
  // The bottom-level trees' objective (host/tree_objective.h, `kd.objective`): 0 = the plain SAH
  // sum at kd.traversal_cost, 1 = the K_T ladder's tree with the lowest busiest-unit load. The
  // top level keeps the plain sum (docs/kdtree.md "Busiest unit").
  int tree_objective = 0;
  // With the objective, only a tree whose SAH-expected traversal and transformation loads differ
  // by this factor or more is walked ("overloads one unit while others idle"); 1: every tree.
  float tree_objective_ratio = 1.0f;
  // Traversal stack entries per packet in the hardware (the prototype's 64, shared by both
  // levels): the top level's depth limit plus every bottom tree's must fit it, so the builder
  // caps the bottom trees' depth at stack_entries minus the top's (docs/kdtree.md).
  int stack_entries = 64;
  int width = 512;
  int height = 384;
  int camera = -1;  // index into Scene::cameras; -1 = scene_camera() (first camera, else default)
  double epsilon = 0.0;  // self-intersection offset (absolute); 0 = 1e-4 x world-bounds diagonal
  std::uint32_t ambient_rgb = 0x202020u;  // RGB8
  std::uint32_t background_rgb = 0;       // RGB8
  std::uint32_t max_depth = 3;            // secondary-ray depth bound
  // Node and list slots reserved for the top-level tree, as a multiple of its first build, when
  // the scene has dynamic instances: a per-frame rebuild that fits needs no relayout.
  double top_level_headroom = 2.0;
  // Copies of the top level (its tree, its lists, the instance records) in the scene banks: 1, or
  // 2 for frame sequences, where the host writes the next frame's copy while the frame in flight
  // reads the other (docs/frames.md, decisions D46). The registers name the current copy.
  int top_level_buffers = 1;
  // Textures are resampled to power-of-two sizes of at most this many texels per side.
  std::uint32_t max_texture_size = 1024;
  // When the shading bank overflows, halve the largest texture until it fits (counted in
  // ImageStats::texture_halvings) instead of refusing the scene.
  bool fit_textures = true;
  // Texture filter written into every material record (the RGS reads 4 texels per textured hit
  // with bilinear filtering, 1 without; the paper rendered Scene6 and Office unfiltered).
  bool bilinear = true;
};

struct InstanceInfo {
  std::uint32_t id = 0;        // glTF node index (built-ins: instance index), hit records report it
  std::uint32_t object = 0;    // index into Scene::objects and BuiltImage::objects
  Affine64 world_to_object;    // binary64 inverse of object_to_world
  Affine32 world_to_object32;  // the same rounded once to binary32 (float reference)
  EncodedAffine world_to_object_encoded{};  // the same rounded once to the image format
  Aabb world_bounds;                        // conservative: the object bounds' corners transformed
  bool in_top_level = false;                // false when its object has no non-degenerate triangle
};

struct ObjectInfo {
  bool stored = false;  // false when no instance uses it: nothing of it is in the image
  std::uint32_t node_root = memif::kNone;        // node index of its tree's root
  std::uint32_t list_base = 0;                   // list index of its tree's item 0
  std::uint32_t triangle_row_base = 0;           // row index of triangle 0's T_delta
  std::uint32_t shading_base = 0;                // shading record index of triangle 0
  std::uint32_t triangles = 0;                   // triangle slots (degenerate included)
  std::uint32_t dropped = 0;                     // degenerate slots (scene flag or no T_delta)
  KdTree tree;                                   // its bottom-level tree (items: triangle ids)
  std::vector<std::optional<Affine64>> t_delta;  // per slot; std::nullopt = dropped
};

struct ImageStats {
  std::array<std::uint64_t, memif::kNumBanks> bytes_per_bank{};  // words holding data, x4
  // Scene banks, summed over the three banks.
  std::uint64_t top_node_bytes = 0;  // the top-level tree (without the reserved slots)
  std::uint64_t bottom_node_bytes = 0;
  std::uint64_t top_list_bytes = 0;
  std::uint64_t bottom_list_bytes = 0;
  std::uint64_t instance_row_bytes = 0;  // instance records
  std::uint64_t triangle_row_bytes = 0;  // T_delta
  std::uint64_t reserved_bytes = 0;      // top-level capacity not used by the current tree
  // Shading bank.
  std::uint64_t material_bytes = 0;
  std::uint64_t light_bytes = 0;
  std::uint64_t shading_record_bytes = 0;
  std::uint64_t texture_bytes = 0;
  std::uint64_t frame_buffer_bytes = 0;  // per frame-buffer bank
  // Counts.
  std::uint64_t stored_objects = 0;
  std::uint64_t triangle_slots = 0;      // stored objects' triangles, degenerate included
  std::uint64_t dropped_triangles = 0;   // in stored objects
  std::uint64_t clamped_texcoords = 0;   // vertex texcoords beyond 16 periods of the floor
  std::uint64_t textures = 0;            // textures stored (those a material uses)
  std::uint64_t resampled_textures = 0;  // of those, how many changed size
  std::uint64_t texture_halvings = 0;    // halvings made to fit the shading bank
  double top_build_seconds = 0.0;
  double bottom_build_seconds = 0.0;  // all bottom-level trees
  // Trees built since build_image began (the frame sequence counts rebuilds by their change):
  // the top level once per build or rebuild, a bottom level once per stored object.
  std::uint64_t top_level_builds = 0;
  std::uint64_t bottom_level_builds = 0;
  std::uint64_t scene_bytes() const;  // words of the three scene banks holding data, x4
};

struct BuiltImage {
  memif::MemoryImage image;
  ImageParams params;
  Camera camera;                        // the camera the registers hold
  PrimaryBasis basis;                   // its binary64 T_init (the registers hold it rounded once)
  KdTree top;                           // items: instance indices
  std::vector<InstanceInfo> instances;  // Scene::instances order = hit record instance index
  std::vector<ObjectInfo> objects;      // Scene::objects order
  ImageStats stats;
  // Node slots 0 .. capacity-1 belong to the top level (copy c of top_level_buffers at c x
  // capacity); list slots likewise; copy c's instance records start at row c x 6 x instances.
  std::uint32_t top_node_capacity = 0;
  std::uint32_t top_list_capacity = 0;
  std::uint32_t top_buffer = 0;          // the copy the registers name (always 0 with one copy)
  std::uint32_t triangle_row_start = 0;  // first T_delta row (after the instance records)
};

// Builds every bottom-level tree, the top-level tree and the whole image. Throws
// std::runtime_error with one line for a scene that does not fit (naming the bank, the region
// and the overflow in bytes), a singular or non-affine instance transform, a material or texture
// index out of range, a non-finite texture coordinate, or a bad camera.
// The depth limits the builder gives the two levels: the top level's for `instances` instances,
// and a bottom tree's over `triangles` triangles; their sum fits params.stack_entries.
int top_level_depth(const ImageParams& params, std::size_t instances);
int bottom_level_depth(const ImageParams& params, std::size_t triangles, std::size_t instances);

BuiltImage build_image(const Scene& scene, const ImageParams& params = {});

// Bytes a full upload writes: every data word of the scene banks and the shading bank.
std::uint64_t full_upload_bytes(const BuiltImage& image);

// What one frame of a dynamic scene uploads over the host bus (paper section 2: only the top
// level is rebuilt when objects move).
struct UploadDelta {
  std::uint64_t top_node_bytes = 0;      // the new top-level tree
  std::uint64_t top_list_bytes = 0;      // its lists
  std::uint64_t instance_row_bytes = 0;  // world -> object rows of moved instances (3 rows each)
  std::uint64_t register_bytes = 0;      // the frame registers (camera, bounds, ...)
  std::uint64_t relayout_bytes = 0;      // a full upload when the top level outgrew its capacity
  std::uint64_t light_bytes = 0;         // light records of lights that moved (16 B each)
  std::uint32_t moved_instances = 0;
  bool relayout = false;
  // False only with two top-level copies when no instance moved: the copy in flight serves the
  // next frame too, and only the registers change.
  bool top_rebuilt = true;
  std::uint64_t total() const {
    return top_node_bytes + top_list_bytes + instance_row_bytes + register_bytes + relayout_bytes +
           light_bytes;
  }
};

// Re-evaluates the instances of `scene` (the same scene, its transforms at a new time): new
// world -> object matrices, world bounds, a new top-level tree written into its reserved slots,
// new scene bounds and camera registers, and the light records of lights that moved. Bottom-level
// trees, triangle matrices and the rest of the shading data stay. With two top-level copies the
// new tree and every instance's matrix go into the copy the registers do not name, and the
// registers then name it (instance_row_bytes counts the instances whose rows that copy did not
// hold yet); when no instance moved nothing is rebuilt (top_rebuilt = false). When the new
// top-level tree outgrows the reserved slots the scene banks are laid out again (relayout = true)
// and everything in them counts as uploaded. Throws, leaving `built` unchanged, when `scene` does
// not have the same objects and instances as the one the image was built from, or has a bad
// instance transform or camera; throws when a relayout does not fit the banks (then `built` must be
// built again).
UploadDelta rebuild_top_level(BuiltImage& built, const Scene& scene);

// ---- reading an image back (tests, the functional model's tests) ------------------------------

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
