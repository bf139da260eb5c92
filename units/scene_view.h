// The scene banks as a thread program reads them on the host (docs/memory-image.md).
#pragma once

#include <array>
#include <cstdint>

#include "memif/image_format.h"

namespace saarcor::units {

// Direct reads of kd-nodes and list entries from the scene banks: what MemoryImage::node and
// list_entry compute (item i of a type in bank 3 + i mod 3 at word base[type] + (i div 3) * words),
// with the bank addresses taken once, and host prefetches of items the thread will read soon
// (no effect on results). Refreshed at every primary packet, so an image rebuilt between frames
// is read afresh.
class SceneView {
 public:
  void refresh(const memif::MemoryImage& image) {
    for (int b = 0; b < memif::kSceneBanks; ++b)
      bank_[static_cast<std::size_t>(b)] = image.bank(memif::kFirstSceneBank + b).data();
    node_base_ = image.regions().base[static_cast<std::size_t>(memif::ItemType::kNode)];
    list_base_ = image.regions().base[static_cast<std::size_t>(memif::ItemType::kList)];
    row_base_ = image.regions().base[static_cast<std::size_t>(memif::ItemType::kRow)];
    row_words_ = static_cast<std::uint32_t>(image.item_words(memif::ItemType::kRow));
  }
  std::uint32_t list_entry(std::uint32_t index) const {
    return bank_[index % memif::kSceneBanks][list_base_ + index / memif::kSceneBanks];
  }
  // The words of matrix row `index`.
  const std::uint32_t* row_words(std::uint32_t index) const {
    return bank_[index % memif::kSceneBanks] + row_base_ +
           (index / memif::kSceneBanks) * row_words_;
  }
  void prefetch_list(std::uint32_t index) const {
    __builtin_prefetch(bank_[index % memif::kSceneBanks] + list_base_ + index / memif::kSceneBanks);
  }
  // Rows first .. first + n - 1 (a row may straddle two host cache lines: both ends).
  void prefetch_rows(std::uint32_t first, std::uint32_t n) const {
    for (std::uint32_t r = first; r < first + n; ++r) {
      const std::uint32_t* w =
          bank_[r % memif::kSceneBanks] + row_base_ + (r / memif::kSceneBanks) * row_words_;
      __builtin_prefetch(w);
      __builtin_prefetch(w + row_words_ - 1u);
    }
  }
  memif::KdNode node(std::uint32_t index) const {
    const std::uint32_t* w = node_words(index);
    return memif::decode_node(w[0], w[1]);
  }
  void prefetch_node(std::uint32_t index) const { __builtin_prefetch(node_words(index)); }

 private:
  const std::uint32_t* node_words(std::uint32_t index) const {
    return bank_[index % memif::kSceneBanks] + node_base_ + (index / memif::kSceneBanks) * 2u;
  }
  std::array<const std::uint32_t*, memif::kSceneBanks> bank_{};
  std::uint32_t node_base_ = 0, list_base_ = 0, row_base_ = 0, row_words_ = 3;
};

}  // namespace saarcor::units
