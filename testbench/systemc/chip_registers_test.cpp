// The register map (chip_registers.h): the frame registers' order and the address decoder.
#include "testbench/systemc/chip_registers.h"

#include <gtest/gtest.h>

namespace saarcor::vp {
namespace {

TEST(ChipRegisters, FrameRegistersRoundTripInTheDocumentedOrder) {
  memif::FrameRegisters r;
  memif::SceneRegions g;
  r.width = 64;
  r.height = 48;
  r.cam_r = {1, 2, 3};
  r.cam_p = {10, 11, 12};
  r.top_root = 7;
  r.scene_max = {20, 21, 22};
  r.light_count = 2;
  r.frame_bank = 1;
  g.base = {100, 200, 300};
  g.count = {5, 6, 7};
  const FrameRegisterWords w = encode_frame_registers(r, g);
  // Word i at 0x100 + 4i: width 0, height 1, cam_r 2..4, cam_u 5..7, cam_d 8..10, cam_p 11..13,
  // top_root 14, scene_min 15..17, scene_max 18..20, then 21..31 one word each, regions 32..37.
  EXPECT_EQ(w[0], 64u);
  EXPECT_EQ(w[1], 48u);
  EXPECT_EQ(w[3], 2u);
  EXPECT_EQ(w[13], 12u);
  EXPECT_EQ(w[14], 7u);
  EXPECT_EQ(w[19], 21u);
  EXPECT_EQ(w[26], 2u);  // light_count
  EXPECT_EQ(w[31], 1u);  // frame_bank
  EXPECT_EQ(w[33], 200u);
  EXPECT_EQ(w[37], 7u);
  EXPECT_EQ(frame_register_name(0), "width");
  EXPECT_EQ(frame_register_name(14), "top_root");
  EXPECT_EQ(frame_register_name(31), "frame_bank");
  EXPECT_EQ(frame_register_name(37), "regions.count[2]");
  memif::FrameRegisters r2;
  memif::SceneRegions g2;
  decode_frame_registers(w, r2, g2);
  EXPECT_EQ(encode_frame_registers(r2, g2), w);
  EXPECT_EQ(r2.scene_max, r.scene_max);
  EXPECT_EQ(g2.count, g.count);
}

TEST(ChipRegisters, DecodesRegionsWordsAndBanks) {
  const std::uint32_t bank_words = 1024;           // 4 KB banks
  Decoded d = decode_address(0x8, 8, bank_words);  // STATUS and FRAMES
  EXPECT_TRUE(d.error.empty());
  EXPECT_EQ(d.region, Decoded::Region::kControl);
  EXPECT_EQ(d.word, 2u);
  EXPECT_EQ(d.words, 2u);
  d = decode_address(0x100 + 4 * 31, 4, bank_words);
  EXPECT_EQ(d.region, Decoded::Region::kFrameRegisters);
  EXPECT_EQ(d.word, 31u);
  // Bank 3 starts at 0x1000_0000 + 3 * 0x0400_0000 = 0x1C00_0000; word 10 at +40.
  EXPECT_EQ(bank_address(3, 10), 0x1C00'0028u);
  d = decode_address(0x1C00'0028, 16, bank_words);
  EXPECT_TRUE(d.error.empty());
  EXPECT_EQ(d.region, Decoded::Region::kBank);
  EXPECT_EQ(d.bank, 3);
  EXPECT_EQ(d.word, 10u);
  EXPECT_EQ(d.words, 4u);
}

TEST(ChipRegisters, RefusesWhatLiesOutsideOrIsNotWords) {
  const std::uint32_t bank_words = 1024;
  EXPECT_EQ(decode_address(0x30, 4, bank_words).error,
            "address 0x00000030 lies outside the register map");
  EXPECT_EQ(decode_address(0x1000'1000, 4, bank_words).error,  // bank 0 ends at word 1023
            "address 0x10001000 lies outside the register map");
  EXPECT_EQ(decode_address(bank_address(6), 4, bank_words).error,  // six banks: 0..5
            "address 0x28000000 lies outside the register map");
  EXPECT_EQ(decode_address(0x102, 4, bank_words).error, "address 0x00000102 is not word-aligned");
  const Decoded three = decode_address(0x100, 3, bank_words);
  EXPECT_TRUE(three.length_error);
  EXPECT_EQ(three.error,
            "a transaction of 3 bytes at 0x00000100: the chip's registers and banks take whole "
            "32-bit words");
  EXPECT_TRUE(decode_address(0x100, 0, bank_words).length_error);
  // 38 frame registers end at 0x100 + 4 * 38 - 1 = 0x197.
  EXPECT_EQ(decode_address(0x190, 16, bank_words).error,
            "a transaction of 16 bytes at 0x00000190 runs past the end of its region (0x00000197)");
  EXPECT_FALSE(decode_address(0x190, 8, bank_words).length_error);
  EXPECT_TRUE(decode_address(0x190, 8, bank_words).error.empty());
}

}  // namespace
}  // namespace saarcor::vp
