// The RGS's memory traffic and the frame buffer in the cycle model (docs/shading.md section 9):
// the frame is read back from the bank the RGS wrote, every pixel is one word, the shading reads
// follow the filter, the caller's image is unchanged, and a frame too large for a bank is refused.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "host/image_builder.h"
#include "host/scene.h"
#include "testbench/chip.h"
#include "testbench/dynrtc_testing.h"
#include "units/functional_model.h"

namespace saarcor::units {
namespace {

using testing::build;

double stat(const CycleFrame& c, const std::string& name) {
  const auto j = nlohmann::json::parse(c.stats_json);
  return j.at(name).at("value").get<double>();
}

// Every pixel is written once, one word, into the back bank the registers name; the image is read
// from there and equals the functional model's; the caller's image keeps its banks.
TEST(RgsTraffic, EveryPixelIsOneWordInTheBackBankAndTheImageIsReadFromIt) {
  host::BuiltImage b = build("builtin:room", 48, 32);
  const std::uint32_t pixels = 48 * 32;
  const FunctionalFrame fn = run_functional(b.image, functional_params(prototype_params()));
  for (const int bank : {memif::kFrameBank0, memif::kFrameBank1}) {
    b.image.registers().frame_bank = static_cast<std::uint32_t>(bank);
    const CycleFrame c = run_cycle(b.image, prototype_params());
    EXPECT_EQ(c.frame_bank, bank);
    EXPECT_EQ(stat(c, "dynrtp0.rgs.frame_writes"), pixels);
    EXPECT_EQ(c.frame_bytes, 3u * pixels);  // RGB8: 3 bytes of each word counted (D36)
    EXPECT_EQ(c.frame.rgb, fn.rgb) << "bank " << bank;
    // The run wrote a copy: the caller's frame-buffer banks are still the builder's zeros.
    for (std::uint32_t i = 0; i < pixels; ++i)
      ASSERT_EQ(b.image.word(bank, i), 0u) << "bank " << bank << " word " << i;
    // Shading reads: at least a 16-byte record per hit and a 16-byte light record per packet.
    EXPECT_GT(c.shading_bytes, 16u * pixels / 2);
    EXPECT_DOUBLE_EQ(c.shading_bytes_per_pixel,
                     static_cast<double>(c.shading_bytes + c.frame_bytes) / pixels);
  }
}

// Without shading the RGS reads nothing and still writes every pixel (black).
TEST(RgsTraffic, HitSinkFrameReadsNoShadingDataAndWritesEveryPixel) {
  const host::BuiltImage b = build("builtin:room", 32, 24);
  CycleRunOptions o;
  o.shading.shade = false;
  const CycleFrame c = run_cycle(b.image, prototype_params(), o);
  EXPECT_EQ(c.shading_bytes, 0u);
  EXPECT_EQ(c.figures.bw_shading(), 0.0);
  EXPECT_EQ(c.frame_bytes, 3u * 32 * 24);
  EXPECT_GT(c.figures.bw_frame(), 0.0);
  EXPECT_DOUBLE_EQ(c.figures.bw_total(), c.figures.bw_dynrtc() + c.figures.bw_frame());
}

// Bilinear filtering reads four texels per textured hit, nearest one: the same hits, 12 more
// bytes per textured hit, and a slower frame (the paper: "10 % at most"; printed).
TEST(RgsTraffic, BilinearReadsThreeMoreTexelsPerTexturedHit) {
  const std::string duck = testing::shared("Duck/Duck.gltf");
  const host::BuiltImage bi = build(duck, 64, 48, 4, true);
  const host::BuiltImage ne = build(duck, 64, 48, 4, false);
  const CycleFrame b = run_cycle(bi.image, prototype_params());
  const CycleFrame n = run_cycle(ne.image, prototype_params());
  // The duck is textured everywhere: every hit pixel reads 3 texels more.
  std::uint64_t hits = 0;
  for (const auto& px : b.frame.pixels)
    hits += px.instance != memif::kNone ? 1 : 0;
  ASSERT_GT(hits, 100u);
  EXPECT_EQ(b.shading_bytes - n.shading_bytes, 12u * hits);
  EXPECT_EQ(stat(b, "dynrtp0.rgs.shading_reads") - stat(n, "dynrtp0.rgs.shading_reads"),
            3.0 * static_cast<double>(hits));
  EXPECT_GT(b.cycles, n.cycles);
  std::printf("Duck 64x48: bilinear %.1f fps, nearest %.1f fps: %.1f %% slower (paper: <= 10 %%)\n",
              b.fps, n.fps, 100.0 * (1.0 - b.fps / n.fps));
}

// A frame needs width x height words of one frame-buffer bank.
TEST(RgsTraffic, FrameLargerThanABankIsRefused) {
  const host::Scene scene = host::load_scene("builtin:cube");
  host::ImageParams ip;
  ip.width = 32;
  ip.height = 32;
  ip.bank_words = 2048;
  host::BuiltImage b = host::build_image(scene, ip);  // (the builder checks its own frame)
  b.image.registers().width = 64;                     // 4096 pixels do not fit
  b.image.registers().height = 64;
  try {
    run_cycle(b.image, prototype_params());
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("frame needs 4096 frame-buffer words, a bank holds 2048"),
              std::string::npos)
        << e.what();
  }
}

// The RGS's traffic shows in the bandwidth and bounds a frame: the shading pipeline's depth moves
// it, with the same image.
TEST(RgsTraffic, ShadingDepthMovesTheFrameNotTheImage) {
  const host::BuiltImage b = build("builtin:room", 32, 24);
  CycleParams deep = prototype_params();
  deep.rgs_depth = 100;
  const CycleFrame base = run_cycle(b.image, prototype_params());
  const CycleFrame slow = run_cycle(b.image, deep);
  EXPECT_GT(slow.cycles, base.cycles);
  EXPECT_EQ(slow.frame.rgb, base.frame.rgb);
  EXPECT_EQ(slow.shading_bytes, base.shading_bytes);
}

}  // namespace
}  // namespace saarcor::units
