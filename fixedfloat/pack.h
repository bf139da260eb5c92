// Packing of float encodings into 32-bit memory words (docs/memory-image.md): a matrix row of four
// values is one memory item. Four fp24 values fill exactly three words; formats wider than 24
// bits take four words per row. Value 0 sits in the low bits of word 0, bits run upwards through
// the words (little-endian bit stream).
#pragma once

#include <array>
#include <cstdint>

#include "fixedfloat/format.h"

namespace saarcor::ff {

// Words occupied by four values of format f: 3 for formats of at most 24 bits, 4 otherwise.
constexpr int row_words(const Format& f) {
  return f.bits() <= 24 ? 3 : 4;
}

// Packs four encodings into row_words(f) words (unused high bits are zero).
inline std::array<std::uint32_t, 4> pack_row(const std::array<std::uint32_t, 4>& v,
                                             const Format& f) {
  std::array<std::uint32_t, 4> w{};
  const int width = f.bits() <= 24 ? 24 : 32;
  for (int i = 0; i < 4; ++i) {
    const std::uint64_t val = v[i] & f.bits_mask();
    const int bit = i * width;
    const int word = bit / 32;
    const int off = bit % 32;
    w[word] |= static_cast<std::uint32_t>(val << off);
    if (off + width > 32) w[word + 1] |= static_cast<std::uint32_t>(val >> (32 - off));
  }
  return w;
}

// Inverse of pack_row: reads four encodings from row_words(f) words.
inline std::array<std::uint32_t, 4> unpack_row(const std::uint32_t* w, const Format& f) {
  std::array<std::uint32_t, 4> v{};
  const int width = f.bits() <= 24 ? 24 : 32;
  for (int i = 0; i < 4; ++i) {
    const int bit = i * width;
    const int word = bit / 32;
    const int off = bit % 32;
    std::uint64_t val = w[word] >> off;
    if (off + width > 32) val |= static_cast<std::uint64_t>(w[word + 1]) << (32 - off);
    v[i] = static_cast<std::uint32_t>(val) & f.bits_mask();
  }
  return v;
}

}  // namespace saarcor::ff
