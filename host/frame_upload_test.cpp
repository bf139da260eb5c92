// The host's side of frame sequences (docs/frames.md): two top-level copies, what a frame reads,
// what a rebuild changes, and that the next frame's changes never touch what the frame in flight
// reads.
#include "host/frame_upload.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

namespace saarcor::host {
namespace {

// A height-field grid object instanced four times (three of them dynamic) and a static object.
Scene movers() {
  Scene s;
  Object grid;
  grid.name = "grid";
  const int n = 8;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x)
      grid.positions.push_back(
          {float(x) / n, float(y) / n, 0.1f * std::sin(0.7f * x) * std::cos(0.5f * y)});
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const unsigned a = unsigned(y * (n + 1) + x), b = a + 1, c = a + unsigned(n + 1), d = c + 1;
      grid.triangles.push_back({a, b, d});
      grid.triangles.push_back({a, d, c});
    }
  grid.material.assign(grid.triangles.size(), 0);
  Object floor;
  floor.name = "floor";
  floor.positions = {{-5, -1, -5}, {5, -1, -5}, {5, -1, 5}, {-5, -1, 5}};
  floor.triangles = {{0, 1, 2}, {0, 2, 3}};
  floor.material = {0, 0};
  s.objects = {grid, floor};
  for (int i = 0; i < 4; ++i) {
    Instance inst;
    inst.object = 0;
    inst.id = static_cast<std::uint32_t>(i);
    inst.dynamic = i > 0;
    inst.object_to_world = glm::translate(glm::dmat4(1.0), glm::dvec3(1.5 * i - 3.0, 0.0, 0.0));
    s.instances.push_back(inst);
  }
  Instance f;
  f.object = 1;
  f.id = 4;
  s.instances.push_back(f);
  Material m;
  m.name = "grey";
  s.materials = {m};
  s.lights.push_back(Light{{0, 5, 5}, {1, 1, 1}, -1});
  return s;
}

ImageParams two_copies() {
  ImageParams p;
  p.width = 32;
  p.height = 24;
  p.bank_words = 1u << 16;
  p.top_level_buffers = 2;
  return p;
}

void move(Scene& s, double t) {
  for (std::size_t i = 1; i < 4; ++i)
    s.instances[i].object_to_world =
        glm::translate(glm::dmat4(1.0), glm::dvec3(1.5 * double(i) - 3.0, t * double(i), -t));
}

bool in_reads(int bank, std::uint32_t w, const std::vector<memif::BankRange>& reads) {
  for (const memif::BankRange& r : reads)
    if (r.bank == bank && w >= r.begin && w < r.end) return true;
  return false;
}

// The words a rebuild changed: none in the shading bank or in what the frame in flight reads,
// no more than the upload counts, and applied to the old image they give the new one.
void expect_runs_outside_reads(const memif::MemoryImage& before, const BuiltImage& b,
                               const std::vector<memif::BankRange>& reads, const UploadDelta& d,
                               int frame) {
  const std::vector<memif::UploadRun> runs = changed_words(before, b.image);
  ASSERT_FALSE(runs.empty());
  EXPECT_FALSE(overlaps(runs, reads)) << "frame " << frame;
  std::uint64_t words = 0;
  for (const memif::UploadRun& r : runs) {
    EXPECT_NE(r.bank, memif::kShadingBank);
    words += r.words.size();
    for (std::uint32_t k = 0; k < r.words.size(); ++k)
      EXPECT_FALSE(in_reads(r.bank, r.offset + k, reads));
  }
  EXPECT_LE(4 * words, d.total());
  // The runs applied to the old image give the new one.
  memif::MemoryImage patched = before;
  for (const memif::UploadRun& r : runs)
    std::copy(r.words.begin(), r.words.end(), patched.bank(r.bank).begin() + r.offset);
  for (int bank = 0; bank < memif::kNumBanks; ++bank)
    EXPECT_EQ(patched.bank(bank), b.image.bank(bank)) << "bank " << bank;
}

TEST(FrameUpload, TwoTopLevelCopiesAlternateAndLeaveTheCopyInFlightAlone) {
  Scene s = movers();
  BuiltImage b = build_image(s, two_copies());
  EXPECT_EQ(b.top_buffer, 0u);
  EXPECT_EQ(b.image.registers().top_root, 0u);
  EXPECT_EQ(b.image.registers().instance_row_base, 0u);
  EXPECT_EQ(b.stats.top_level_builds, 1u);
  EXPECT_EQ(b.stats.bottom_level_builds, 2u);
  // Both copies hold the whole top level: the registers may name either.
  memif::MemoryImage copy1 = b.image;
  copy1.registers().top_root = b.top_node_capacity;
  copy1.registers().instance_row_base = memif::kInstanceRows * 5;
  const DecodedTree t0 = decode_image(b.image).top, t1 = decode_image(copy1).top;
  ASSERT_EQ(t0.nodes.size(), t1.nodes.size());
  for (std::size_t k = 0; k < t0.nodes.size(); ++k) {  // the same tree at other indices
    memif::KdNode n = t0.nodes[k];
    if (n.leaf)
      n.first += b.top_list_capacity;
    else
      n.child_pair += b.top_node_capacity;
    EXPECT_EQ(t1.nodes[k], n) << "node " << k;
  }

  for (int frame = 1; frame <= 4; ++frame) {
    const std::vector<memif::BankRange> reads = frame_reads(b, frame % 2);
    const memif::MemoryImage before = b.image;
    const std::uint32_t buffer_before = b.top_buffer;
    move(s, 0.25 * frame);
    const UploadDelta d = rebuild_top_level(b, s);
    EXPECT_TRUE(d.top_rebuilt);
    EXPECT_FALSE(d.relayout);
    EXPECT_EQ(d.moved_instances, 3u);
    EXPECT_EQ(b.top_buffer, 1u - buffer_before) << "frame " << frame;
    EXPECT_EQ(b.image.registers().top_root, b.top_buffer * b.top_node_capacity);
    EXPECT_EQ(b.image.registers().instance_row_base, b.top_buffer * memif::kInstanceRows * 5);
    // The first rebuild fills copy 1, which held frame 0's matrices of all three movers; later
    // ones the copy of two frames ago: again three.
    EXPECT_EQ(d.instance_row_bytes, 3u * 36u);
    EXPECT_EQ(b.stats.top_level_builds, 1u + static_cast<std::uint64_t>(frame));
    EXPECT_EQ(b.stats.bottom_level_builds, 2u);  // never rebuilt
    expect_runs_outside_reads(before, b, reads, d, frame);
    // And the image read through the registers is the new frame's.
    const DecodedImage dec = decode_image(b.image);
    for (std::size_t i = 0; i < 5; ++i)
      EXPECT_EQ(dec.instances[i].world_to_object, b.instances[i].world_to_object_encoded);
  }

  // Nothing moves: no rebuild, no word changes, the copy in flight serves the next frame.
  const memif::MemoryImage before = b.image;
  const std::uint32_t buffer = b.top_buffer;
  const UploadDelta still = rebuild_top_level(b, s);
  EXPECT_FALSE(still.top_rebuilt);
  EXPECT_EQ(still.moved_instances, 0u);
  EXPECT_EQ(still.total(), sizeof(memif::FrameRegisters));
  EXPECT_EQ(b.top_buffer, buffer);
  EXPECT_EQ(b.stats.top_level_builds, 5u);
  EXPECT_TRUE(changed_words(before, b.image).empty());
}

TEST(FrameUpload, OneCopyOrAMovingLightTouchesWhatTheFrameReads) {
  Scene s = movers();
  ImageParams p = two_copies();
  p.top_level_buffers = 1;
  BuiltImage one = build_image(s, p);
  const std::vector<memif::BankRange> reads = frame_reads(one, memif::kFrameBank0);
  const memif::MemoryImage before = one.image;
  move(s, 0.5);
  rebuild_top_level(one, s);
  EXPECT_TRUE(overlaps(changed_words(before, one.image), reads));

  // A light that moves is rewritten in the shading bank, which every frame reads.
  Scene lit = movers();
  BuiltImage two = build_image(lit, two_copies());
  const std::vector<memif::BankRange> reads2 = frame_reads(two, memif::kFrameBank0);
  const memif::MemoryImage before2 = two.image;
  lit.lights[0].position.x += 1.0f;
  const UploadDelta d = rebuild_top_level(two, lit);
  EXPECT_FALSE(d.top_rebuilt);
  EXPECT_EQ(d.light_bytes, 16u);
  const std::vector<memif::UploadRun> runs = changed_words(before2, two.image);
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].bank, memif::kShadingBank);
  EXPECT_EQ(runs[0].offset, two.image.registers().light_base);
  EXPECT_TRUE(overlaps(runs, reads2));
  lit.lights.pop_back();
  EXPECT_THROW(rebuild_top_level(two, lit), std::runtime_error);
}

TEST(FrameUpload, FrameReadsCoverTheImageButTheOtherCopy) {
  const Scene s = movers();
  const BuiltImage b = build_image(s, two_copies());
  const std::vector<memif::BankRange> reads = frame_reads(b, memif::kFrameBank1);
  // Every node, list entry and row a frame reads through the registers is covered; the other
  // copy's slots are not.
  const memif::MemoryImage& im = b.image;
  const auto covered = [&](memif::ItemType t, std::uint32_t i) {
    for (int w = 0; w < im.item_words(t); ++w) {
      const memif::WordLocation l = im.locate(t, i, w);
      if (!in_reads(l.bank, l.offset, reads)) return false;
    }
    return true;
  };
  for (std::uint32_t i = 0; i < im.regions().count[0]; ++i)
    EXPECT_EQ(covered(memif::ItemType::kNode, i),
              i < b.top_node_capacity || i >= 2 * b.top_node_capacity)
        << "node " << i;
  for (std::uint32_t i = 0; i < im.regions().count[1]; ++i)
    EXPECT_EQ(covered(memif::ItemType::kList, i),
              i < b.top_list_capacity || i >= 2 * b.top_list_capacity)
        << "list " << i;
  for (std::uint32_t i = 0; i < im.regions().count[2]; ++i)
    EXPECT_EQ(covered(memif::ItemType::kRow, i), i < 30 || i >= 60) << "row " << i;
  EXPECT_TRUE(in_reads(memif::kShadingBank, 0, reads));
  EXPECT_TRUE(in_reads(memif::kFrameBank1, 32 * 24 - 1, reads));
  EXPECT_FALSE(in_reads(memif::kFrameBank1, 32 * 24, reads));
  EXPECT_FALSE(in_reads(memif::kFrameBank0, 0, reads));
  // The data words are what a full upload writes, and outside them every word is zero.
  std::uint64_t words = 0;
  memif::MemoryImage masked = im;
  for (const memif::BankRange& r : data_words(b)) {
    words += r.end - r.begin;
    std::fill(masked.bank(r.bank).begin() + r.begin, masked.bank(r.bank).begin() + r.end, 0u);
  }
  EXPECT_EQ(4 * words, full_upload_bytes(b));
  for (int bank = memif::kShadingBank; bank < memif::kNumBanks; ++bank)
    EXPECT_TRUE(std::ranges::all_of(masked.bank(bank), [](std::uint32_t w) { return w == 0; }))
        << "bank " << bank;
  memif::MemoryImage other(ff::kFp24, 1024);
  EXPECT_THROW(changed_words(im, other), std::runtime_error);
}

}  // namespace
}  // namespace saarcor::host
