// The memory image file (memif/image_file.h): a round trip keeps every word, register and region;
// a foreign, corrupt, truncated or newer file is one error line, never a crash.
#include "memif/image_file.h"

#include <gtest/gtest.h>

#include <sstream>
#include <stdexcept>
#include <string>

namespace saarcor::memif {
namespace {

// A small fp24 image: 64-word banks, a few words in the scene and shading banks.
MemoryImage small_image() {
  MemoryImage image(ff::kFp24, 64);
  image.regions().base = {0, 4, 6};
  image.regions().count = {8, 5, 9};
  image.registers().width = 16;
  image.registers().height = 8;
  image.registers().cam_d = {1, 2, 0x3f0000};
  image.registers().instance_row_base = 0;
  image.registers().instance_count = 1;
  image.registers().epsilon = 0x2a1234;
  image.set_word(3, 0, 0x0000000b);
  image.set_word(5, 17, 0xdeadbeef);
  image.set_word(2, 63, 7);  // the bank's last word: the whole bank is stored
  return image;
}

std::string bytes_of(const MemoryImage& image) {
  std::ostringstream out;
  write_image_file(image, out);
  return out.str();
}

std::string read_error(const std::string& bytes) {
  std::istringstream in(bytes);
  try {
    read_image_file(in, "x.img");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// FNV-1a, written out again: the checksum a forged header needs.
void reseal(std::string& b) {
  std::uint32_t h = 2166136261u;
  for (std::size_t i = 0; i + 4 < b.size(); ++i)
    h = (h ^ static_cast<std::uint8_t>(b[i])) * 16777619u;
  for (int i = 0; i < 4; ++i)
    b[b.size() - 4 + static_cast<std::size_t>(i)] = static_cast<char>(h >> (8 * i));
}

TEST(ImageFile, RoundTripKeepsEveryWordRegisterAndRegion) {
  const MemoryImage a = small_image();
  std::istringstream in(bytes_of(a));
  const MemoryImage b = read_image_file(in, "x.img");
  EXPECT_EQ(b.format(), a.format());
  EXPECT_EQ(b.bank_words(), 64u);
  for (int k = 0; k < kNumBanks; ++k)
    EXPECT_EQ(b.bank(k), a.bank(k)) << "bank " << k;
  EXPECT_EQ(b.regions().base, a.regions().base);
  EXPECT_EQ(b.regions().count, a.regions().count);
  EXPECT_EQ(b.registers().cam_d, a.registers().cam_d);
  EXPECT_EQ(b.registers().epsilon, 0x2a1234u);
  EXPECT_EQ(b.registers().width, 16u);
}

TEST(ImageFile, StoresEachBankUpToItsLastNonZeroWord) {
  // 8 magic + 4 version + 2 format + 1 bank size + 6 regions + 32 registers words, then per bank
  // a count: banks 0, 1, 4 empty, bank 2 all 64 words, bank 3 one word, bank 5 18 words; the
  // checksum: 8 + 4 * (1 + 2 + 1 + 6 + 32 + 6 + 64 + 1 + 18 + 1) = 536 bytes.
  EXPECT_EQ(bytes_of(small_image()).size(), 536u);
}

TEST(ImageFile, ForeignCorruptTruncatedAndNewerFilesAreOneLine) {
  const std::string good = bytes_of(small_image());
  EXPECT_EQ(read_error("GIF89a not an image at all"),
            "memory image file x.img: not a saarcor memory image (no SAARCORI magic)");
  EXPECT_EQ(read_error(""),
            "memory image file x.img: not a saarcor memory image (no SAARCORI magic)");
  std::string flipped = good;
  flipped[200] = static_cast<char>(flipped[200] ^ 0x10);
  EXPECT_EQ(read_error(flipped),
            "memory image file x.img: checksum mismatch (corrupt or truncated file)");
  EXPECT_EQ(read_error(good.substr(0, 300)),
            "memory image file x.img: checksum mismatch (corrupt or truncated file)");
  std::string newer = good;
  newer[8] = 2;
  reseal(newer);
  EXPECT_EQ(read_error(newer), "memory image file x.img: version 2; this reader reads version 1");
  std::string huge_bank = good;
  huge_bank[20] = 0;  // bank size word 20..23 = 0x40000000 words
  huge_bank[23] = 0x40;
  reseal(huge_bank);
  EXPECT_EQ(read_error(huge_bank), "memory image file x.img: a bank size out of range");
}

TEST(ImageFile, RegionsBeyondTheBanksAreRefused) {
  MemoryImage image = small_image();
  image.regions().count[2] = 100;  // 34 rows per bank of 3 words from word 6: beyond 64 words
  EXPECT_EQ(read_error(bytes_of(image)), "memory image file x.img: a row region beyond its banks");
  MemoryImage wide = small_image();
  wide.registers().width = 0;
  EXPECT_EQ(read_error(bytes_of(wide)),
            "memory image file x.img: a resolution outside 1..16384 per side");
}

TEST(ImageFile, MissingPathIsOneLine) {
  try {
    read_image_file(std::string("/nonexistent/scene.img"));
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "memory image file /nonexistent/scene.img: cannot open");
  }
}

}  // namespace
}  // namespace saarcor::memif
