// What travels on the memory interface's channels (paper section 3 "memory interface",
// docs/memif.md): item requests from units to their cache, labelled item responses back,
// word requests from caches and other clients to the memory controller, and labelled word
// responses (the "labeled broadcast" of the simple routing).
#pragma once

#include <array>
#include <cstdint>

namespace saarcor::memif {

inline constexpr int kMaxRequestWords = 4;  // largest item (a matrix row of a >24-bit format)

// Who asked: the requesting unit (any number the unit picks, e.g. its id in the DynRTP) and a
// tag it uses to match the answer (the thread id).
struct Label {
  std::uint16_t requester = 0;
  std::uint32_t tag = 0;
  friend bool operator==(const Label&, const Label&) = default;
};

// Unit -> cache: "give me item `index` of the cache's type".
struct CacheRequest {
  std::uint32_t index = 0;
  Label label;
};

// Cache -> unit: the item's words (MemoryImage::item_words of the type; the rest are zero).
struct CacheResponse {
  std::uint32_t index = 0;
  Label label;
  std::array<std::uint32_t, kMaxRequestWords> words{};
  int count = 0;
};

// Client -> memory controller: read or write `words` consecutive words of one bank.
struct MemRequest {
  std::uint16_t client = 0;  // MemoryController::add_client id: bandwidth is counted per client
  std::uint32_t tag = 0;     // returned in the response
  std::uint8_t bank = 0;
  std::uint8_t words = 1;  // 1..kMaxRequestWords
  bool write = false;
  std::uint8_t counted_bytes = 0;  // bytes to count for bandwidth; 0 = 4 * words (decision D36)
  std::uint32_t offset = 0;        // word offset within the bank
  std::array<std::uint32_t, kMaxRequestWords> data{};  // write data
};

// Memory controller -> client (reads only): the words, with the client id and tag as label.
struct MemResponse {
  std::uint16_t client = 0;
  std::uint32_t tag = 0;
  std::uint8_t count = 0;
  std::array<std::uint32_t, kMaxRequestWords> words{};
};

}  // namespace saarcor::memif
