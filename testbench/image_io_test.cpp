// Image files through OpenImageIO: round trips, atomic writes, one-line errors naming the file.
#include "testbench/image_io.h"
#include "testbench/testing.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace saarcor {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
  return test_support::scratch_dir("imageio");
}

Rgb8Image gradient(int w, int h) {
  Rgb8Image img;
  img.width = w;
  img.height = h;
  img.rgb.resize(static_cast<std::size_t>(w) * h * 3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t p = (static_cast<std::size_t>(y) * w + x) * 3;
      img.rgb[p] = static_cast<std::uint8_t>(x * 7);
      img.rgb[p + 1] = static_cast<std::uint8_t>(y * 11);
      img.rgb[p + 2] = static_cast<std::uint8_t>((x * y) & 255);
    }
  }
  return img;
}

TEST(ImageIo, PngRoundTripAndParentDirectoryCreated) {
  const Rgb8Image img = gradient(13, 9);
  const fs::path path = temp_dir() / "sub" / "dir" / "g.png";
  fs::remove_all(temp_dir() / "sub");
  write_rgb8(path.string(), img);
  const Rgb8Image back = read_rgb8(path.string());
  EXPECT_EQ(back.width, 13);
  EXPECT_EQ(back.height, 9);
  EXPECT_EQ(back.rgb, img.rgb);
  const FloatImage f = read_float_image(path.string());
  EXPECT_TRUE(f.eight_bit);
  EXPECT_EQ(f.channels, 3);
  EXPECT_EQ(f.data, to_float_image(img).data);
}

TEST(ImageIo, ExrRoundTripIsExact) {
  FloatImage img;
  img.width = 5;
  img.height = 4;
  img.channels = 3;
  for (int i = 0; i < 60; ++i)
    img.data.push_back(static_cast<float>(i) / 7.0f - 1.0f);
  const std::string path = (temp_dir() / "f.exr").string();
  write_float_image(path, img);
  const FloatImage back = read_float_image(path);
  EXPECT_FALSE(back.eight_bit);
  EXPECT_EQ(back.width, 5);
  EXPECT_EQ(back.channels, 3);
  EXPECT_EQ(back.data, img.data);
}

TEST(ImageIo, FailedWriteLeavesNoFileAndKeepsTheOldOne) {
  const fs::path path = temp_dir() / "keep.png";
  write_rgb8(path.string(), gradient(4, 4));
  const auto size_before = fs::file_size(path);
  EXPECT_THROW(write_file_atomically(path.string(),
                                     [](const std::string& tmp) {
                                       std::ofstream(tmp) << "partial";
                                       throw std::runtime_error("boom");
                                     }),
               std::runtime_error);
  EXPECT_EQ(fs::file_size(path), size_before);
  for (const auto& e : fs::directory_iterator(temp_dir())) {
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
  }
}

TEST(ImageIo, ErrorsNameTheFile) {
  try {
    read_float_image("/nonexistent/x.png");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/x.png: no such file");
  }
  const fs::path junk = temp_dir() / "junk.png";
  std::ofstream(junk) << "this is not a png";
  try {
    read_float_image(junk.string());
    FAIL();
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind(junk.string() + ": cannot read image", 0), 0u) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
  // Unknown extension: refused, nothing written.
  const fs::path bad = temp_dir() / "x.notanimageformat";
  try {
    write_rgb8(bad.string(), gradient(2, 2));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(bad.string() + ":", 0), 0u) << e.what();
  }
  EXPECT_FALSE(fs::exists(bad));
  // A directory in the way.
  EXPECT_THROW(write_rgb8(temp_dir().string(), gradient(2, 2)), std::runtime_error);
}

TEST(ImageIo, TextFileIsWrittenWhole) {
  const fs::path path = temp_dir() / "r" / "report.json";
  write_text_file(path.string(), "{\"a\": 1}\n");
  std::ifstream f(path);
  std::string s((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  EXPECT_EQ(s, "{\"a\": 1}\n");
}

}  // namespace
}  // namespace saarcor
