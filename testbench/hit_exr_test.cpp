// The hit EXR round trip: what OpenImageIO decodes from the file is exactly the records in
// memory, bit for bit, every pixel and every channel.
#include "testbench/hit_exr.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include "testbench/image_io.h"
#include "testbench/testing.h"

namespace saarcor {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
  return test_support::scratch_dir("hitexr");
}

std::uint32_t bits(float f) {
  std::uint32_t b;
  std::memcpy(&b, &f, 4);
  return b;
}

// Random records with awkward values: misses (inf), negative zero, subnormals, NaN payloads,
// ids up to 0xFFFFFFFE.
HitBuffer random_hits(int w, int h, unsigned seed) {
  std::mt19937 rng(seed);
  HitBuffer hb;
  hb.width = w;
  hb.height = h;
  hb.pixels.resize(static_cast<std::size_t>(w) * h);
  auto rf = [&] {
    std::uint32_t b = rng();
    float f;
    std::memcpy(&f, &b, 4);
    return f;
  };
  for (auto& p : hb.pixels) {
    p.ox = rf();
    p.oy = rf();
    p.oz = rf();
    p.dx = rf();
    p.dy = rf();
    p.dz = rf();
    if (rng() % 4 == 0) continue;  // a miss: t = inf, ids ~0
    p.t = rf();
    p.u = rf();
    p.v = rf();
    p.cos = rng() % 8 == 0 ? -0.0f : rf();
    p.instance = rng() % 0xFFFFFFFFu;
    p.triangle = rng() % 0xFFFFFFFFu;
  }
  return hb;
}

TEST(HitExr, RoundTripIsBitExactThroughOpenImageIO) {
  const HitBuffer hb = random_hits(37, 23, 4711);
  const std::string path = (temp_dir() / "hits.exr").string();
  write_hit_exr(path, hb);

  // Decode with plain OpenImageIO (not our reader): each named channel in its own type.
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in) << OIIO::geterror();
  const OIIO::ImageSpec& spec = in->spec();
  ASSERT_EQ(spec.width, 37);
  ASSERT_EQ(spec.height, 23);
  ASSERT_EQ(spec.nchannels, 12);
  for (int c = 0; c < 12; ++c) {
    const int idx = spec.channelindex(kHitExrChannels[c]);
    ASSERT_GE(idx, 0) << kHitExrChannels[c];
    const bool is_uint = c == 4 || c == 5;
    EXPECT_EQ(spec.channelformat(idx), is_uint ? OIIO::TypeDesc::UINT : OIIO::TypeDesc::FLOAT)
        << kHitExrChannels[c];
    std::vector<std::uint32_t> ch(hb.pixels.size());
    ASSERT_TRUE(in->read_image(0, 0, idx, idx + 1,
                               is_uint ? OIIO::TypeDesc::UINT : OIIO::TypeDesc::FLOAT, ch.data()));
    for (std::size_t p = 0; p < hb.pixels.size(); ++p) {
      const PixelHit& h = hb.pixels[p];
      const std::uint32_t want[12] = {bits(h.t),  bits(h.u),  bits(h.v),  bits(h.cos),
                                      h.instance, h.triangle, bits(h.ox), bits(h.oy),
                                      bits(h.oz), bits(h.dx), bits(h.dy), bits(h.dz)};
      ASSERT_EQ(ch[p], want[c]) << kHitExrChannels[c] << " at pixel " << p % 37 << "," << p / 37;
    }
  }
  in->close();

  // And our reader gives back the same buffer.
  const HitBuffer back = read_hit_exr(path);
  ASSERT_EQ(back.width, hb.width);
  ASSERT_EQ(back.height, hb.height);
  for (std::size_t p = 0; p < hb.pixels.size(); ++p) {
    const PixelHit& a = hb.pixels[p];
    const PixelHit& b = back.pixels[p];
    ASSERT_EQ(bits(a.t), bits(b.t));
    ASSERT_EQ(bits(a.u), bits(b.u));
    ASSERT_EQ(bits(a.cos), bits(b.cos));
    ASSERT_EQ(a.instance, b.instance);
    ASSERT_EQ(a.triangle, b.triangle);
    ASSERT_EQ(bits(a.dz), bits(b.dz));
  }
  EXPECT_TRUE(is_hit_exr(path));
}

TEST(HitExr, MissIsInfinityAndAllOnesIds) {
  HitBuffer hb;
  hb.width = 2;
  hb.height = 1;
  hb.pixels.resize(2);
  hb.pixels[1].t = 2.5f;
  hb.pixels[1].instance = 7;
  hb.pixels[1].triangle = 0;
  const std::string path = (temp_dir() / "miss.exr").string();
  write_hit_exr(path, hb);
  const HitBuffer back = read_hit_exr(path);
  EXPECT_TRUE(std::isinf(back.pixels[0].t));
  EXPECT_GT(back.pixels[0].t, 0.0f);
  EXPECT_EQ(back.pixels[0].instance, 0xFFFFFFFFu);
  EXPECT_EQ(back.pixels[0].triangle, 0xFFFFFFFFu);
  EXPECT_FALSE(back.pixels[0].hit());
  EXPECT_TRUE(back.pixels[1].hit());
  EXPECT_EQ(back.pixels[1].t, 2.5f);
}

TEST(HitExr, PlainImageIsNotAHitExr) {
  FloatImage img;
  img.width = 4;
  img.height = 3;
  img.channels = 3;
  img.data.assign(36, 0.5f);
  const std::string path = (temp_dir() / "plain.exr").string();
  write_float_image(path, img);
  EXPECT_FALSE(is_hit_exr(path));
  try {
    read_hit_exr(path);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not a hit EXR: channel hit.t missing"), std::string::npos)
        << e.what();
  }
}

TEST(HitExr, WrongChannelTypeIsRefused) {
  // hit.instance stored as float: refused with a message naming the channel.
  OIIO::ImageSpec spec(1, 1, 12, OIIO::TypeDesc::FLOAT);
  spec.channelnames.assign(kHitExrChannels.begin(), kHitExrChannels.end());
  const std::string path = (temp_dir() / "floatids.exr").string();
  {
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out->open(path, spec));
    std::vector<float> px(12, 1.0f);
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, px.data()));
    out->close();
  }
  try {
    read_hit_exr(path);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("channel hit.instance is float, expected uint"),
              std::string::npos)
        << e.what();
  }
}

TEST(HitExr, MissingFileNamesTheFile) {
  try {
    read_hit_exr("/nonexistent/dir/hits.exr");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/dir/hits.exr: no such file");
  }
}

TEST(HitExr, WriteToNonExrExtensionLeavesNoFile) {
  HitBuffer hb = random_hits(3, 2, 1);
  const fs::path path = temp_dir() / "hits.png";
  fs::remove(path);
  EXPECT_THROW(write_hit_exr(path.string(), hb), std::runtime_error);
  EXPECT_FALSE(fs::exists(path));
  for (const auto& e : fs::directory_iterator(temp_dir())) {
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
  }
}

// Two writes of the same records, a second boundary apart, are the same bytes: OpenImageIO would
// stamp the time of writing into the header (capDate), so the writer gives a fixed DateTime.
TEST(HitExr, RewriteGivesTheSameBytes) {
  const HitBuffer hb = random_hits(9, 7, 99);
  const std::string a = (temp_dir() / "same_a.exr").string();
  const std::string b = (temp_dir() / "same_b.exr").string();
  write_hit_exr(a, hb);
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  write_hit_exr(b, hb);
  auto slurp = [](const std::string& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
  };
  const std::string bytes = slurp(a);
  ASSERT_GT(bytes.size(), 500u);
  EXPECT_EQ(slurp(b), bytes);
  auto in = OIIO::ImageInput::open(a);
  ASSERT_TRUE(in) << OIIO::geterror();
  EXPECT_EQ(in->spec().get_string_attribute("DateTime"), kFixedImageDateTime);
  in->close();
  // The float image writer (image.exr) keeps the same rule.
  const std::string fa = (temp_dir() / "image_a.exr").string();
  const std::string fb = (temp_dir() / "image_b.exr").string();
  Rgb8Image img;
  img.width = 4;
  img.height = 3;
  img.rgb.assign(36, 200);
  write_float_image(fa, to_float_image(img));
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  write_float_image(fb, to_float_image(img));
  EXPECT_EQ(slurp(fa), slurp(fb));
}

}  // namespace
}  // namespace saarcor
