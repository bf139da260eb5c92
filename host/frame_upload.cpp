// The host's side of a frame sequence: what a frame reads, what changed (docs/frames.md).
#include "host/frame_upload.h"

#include <stdexcept>
#include <string>

namespace saarcor::host {
namespace {

using memif::ItemType;

// Words of scene bank 3 + j holding items [first, end) of type t (item i lives in bank
// 3 + i mod 3, D22, so a range of items is one range of words in each bank).
memif::BankRange item_words(const memif::MemoryImage& im, ItemType t, std::uint64_t first,
                            std::uint64_t end, int j, const std::string& what) {
  const auto per_bank = [j](std::uint64_t i) {
    const auto jj = static_cast<std::uint64_t>(j);
    return i > jj ? (i - jj + memif::kSceneBanks - 1) / memif::kSceneBanks : 0;
  };
  const std::uint64_t base = im.regions().base[static_cast<std::size_t>(t)];
  const auto iw = static_cast<std::uint64_t>(im.item_words(t));
  return {memif::kFirstSceneBank + j, static_cast<std::uint32_t>(base + per_bank(first) * iw),
          static_cast<std::uint32_t>(base + per_bank(end) * iw), what};
}

}  // namespace

std::vector<memif::BankRange> frame_reads(const BuiltImage& b, int frame_bank) {
  const memif::MemoryImage& im = b.image;
  const bool two = b.params.top_level_buffers == 2;
  const std::uint64_t other = 1u - b.top_buffer;
  const std::uint64_t rows = std::uint64_t{memif::kInstanceRows} * b.instances.size();
  struct Stripe {
    ItemType type;
    std::uint64_t slots;  // items per top-level copy
    const char* what;
  };
  const Stripe stripes[] = {
      {ItemType::kNode, b.top_node_capacity, "kd-nodes"},
      {ItemType::kList, b.top_list_capacity, "list entries"},
      {ItemType::kRow, rows, "matrix rows"},
  };
  std::vector<memif::BankRange> reads;
  for (const Stripe& s : stripes) {
    const std::uint64_t count = im.regions().count[static_cast<std::size_t>(s.type)];
    // Everything in use but the other copy's slots, which the next frame's upload may fill.
    const std::uint64_t gap_from = two ? other * s.slots : count;
    const std::uint64_t gap_to = two ? gap_from + s.slots : count;
    for (int j = 0; j < memif::kSceneBanks; ++j) {
      for (const auto& [from, to] : {std::pair{std::uint64_t{0}, gap_from}, {gap_to, count}}) {
        const memif::BankRange r = item_words(im, s.type, from, to, j, s.what);
        if (r.end > r.begin) reads.push_back(r);
      }
    }
  }
  const auto shading = static_cast<std::uint32_t>(b.stats.bytes_per_bank[memif::kShadingBank] / 4);
  if (shading > 0)
    reads.push_back({memif::kShadingBank, 0, shading,
                     "shading data (materials, lights, shading records, textures)"});
  const std::uint32_t pixels = im.registers().width * im.registers().height;
  reads.push_back({frame_bank, 0, pixels, "the frame buffer it writes"});
  return reads;
}

std::vector<memif::BankRange> data_words(const BuiltImage& b) {
  std::vector<memif::BankRange> out;
  const auto shading = static_cast<std::uint32_t>(b.stats.bytes_per_bank[memif::kShadingBank] / 4);
  if (shading > 0) out.push_back({memif::kShadingBank, 0, shading, "shading data"});
  const char* names[memif::kItemTypes] = {"kd-nodes", "list entries", "matrix rows"};
  for (int j = 0; j < memif::kSceneBanks; ++j)
    for (int t = 0; t < memif::kItemTypes; ++t) {
      const memif::BankRange r =
          item_words(b.image, static_cast<ItemType>(t), 0,
                     b.image.regions().count[static_cast<std::size_t>(t)], j, names[t]);
      if (r.end > r.begin) out.push_back(r);
    }
  return out;
}

std::vector<memif::UploadRun> changed_words(const memif::MemoryImage& before,
                                            const memif::MemoryImage& after) {
  if (before.bank_words() != after.bank_words())
    throw std::runtime_error("changed_words: banks of " + std::to_string(before.bank_words()) +
                             " and " + std::to_string(after.bank_words()) + " words");
  std::vector<memif::UploadRun> runs;
  for (int bank = memif::kShadingBank; bank < memif::kNumBanks; ++bank) {
    const std::uint32_t* a = before.bank(bank).data();
    const std::uint32_t* b = after.bank(bank).data();
    const std::uint32_t n = after.bank_words();
    for (std::uint32_t w = 0; w < n;) {
      if (a[w] == b[w]) {
        ++w;
        continue;
      }
      memif::UploadRun r{bank, w, {}};
      while (w < n && a[w] != b[w])
        r.words.push_back(b[w++]);
      runs.push_back(std::move(r));
    }
  }
  return runs;
}

bool overlaps(const std::vector<memif::UploadRun>& runs,
              const std::vector<memif::BankRange>& reads) {
  for (const memif::UploadRun& u : runs) {
    const std::uint64_t end = u.offset + std::uint64_t{u.words.size()};
    for (const memif::BankRange& r : reads)
      if (r.bank == u.bank && !u.words.empty() && u.offset < r.end && end > r.begin) return true;
  }
  return false;
}

}  // namespace saarcor::host
