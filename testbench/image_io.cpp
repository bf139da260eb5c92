// Image files through OpenImageIO, written atomically (docs/compare.md: output files).
#include "testbench/image_io.h"

#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace saarcor {
namespace fs = std::filesystem;

namespace {

std::string one_line(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!s.empty() && s.back() == ' ')
    s.pop_back();
  return s;
}

std::string oiio_error(const std::string& fallback) {
  std::string e = OIIO::geterror();
  return one_line(e.empty() ? fallback : e);
}

}  // namespace

void write_file_atomically(const std::string& path,
                           const std::function<void(const std::string& tmp_path)>& write) {
  if (path.empty()) throw std::runtime_error("output file name is empty");
  const fs::path target(path);
  const fs::path parent = target.parent_path();
  if (!parent.empty()) {
    std::error_code ec;
    fs::create_directories(parent, ec);
    if (ec) {
      throw std::runtime_error(path + ": cannot create directory " + parent.string() + ": " +
                               ec.message());
    }
  }
  if (fs::is_directory(target)) throw std::runtime_error(path + ": is a directory");
  // Same extension as the target: OpenImageIO chooses the codec by it.
  static std::atomic<unsigned> counter{0};
  const std::string tmp_name = "." + target.stem().string() + ".tmp" + std::to_string(getpid()) +
                               "-" + std::to_string(counter++) + target.extension().string();
  const fs::path tmp = parent.empty() ? fs::path(tmp_name) : parent / tmp_name;
  try {
    write(tmp.string());
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    std::error_code ec2;
    fs::remove(tmp, ec2);
    throw std::runtime_error(path + ": cannot write: " + ec.message());
  }
}

void write_text_file(const std::string& path, const std::string& text) {
  write_file_atomically(path, [&](const std::string& tmp) {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw std::runtime_error(path + ": cannot open for writing");
    f << text;
    f.close();
    if (!f) throw std::runtime_error(path + ": write failed");
  });
}

namespace {

void write_oiio(const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc format,
                const void* data) {
  write_file_atomically(path, [&](const std::string& tmp) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) {
      throw std::runtime_error(
          path + ": cannot write this image format: " + oiio_error("unknown extension"));
    }
    if (!out->open(tmp, spec)) {
      throw std::runtime_error(path + ": cannot open for writing: " + one_line(out->geterror()));
    }
    const bool ok = out->write_image(format, data);
    const std::string werr = ok ? std::string() : one_line(out->geterror());
    if (!out->close() && ok) {
      throw std::runtime_error(path + ": write failed: " + one_line(out->geterror()));
    }
    if (!ok) throw std::runtime_error(path + ": write failed: " + werr);
  });
}

}  // namespace

void write_rgb8(const std::string& path, const Rgb8Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != static_cast<std::size_t>(image.width) * image.height * 3) {
    throw std::runtime_error(path + ": image to write has inconsistent size");
  }
  OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT8);
  write_oiio(path, spec, OIIO::TypeDesc::UINT8, image.rgb.data());
}

void write_float_image(const std::string& path, const FloatImage& image) {
  if (image.width <= 0 || image.height <= 0 || image.channels <= 0 ||
      image.data.size() != static_cast<std::size_t>(image.width) * image.height * image.channels) {
    throw std::runtime_error(path + ": image to write has inconsistent size");
  }
  OIIO::ImageSpec spec(image.width, image.height, image.channels, OIIO::TypeDesc::FLOAT);
  if (static_cast<int>(image.channel_names.size()) == image.channels) {
    spec.channelnames = image.channel_names;
  }
  spec.attribute("compression", "zip");
  spec.attribute("DateTime", kFixedImageDateTime);
  write_oiio(path, spec, OIIO::TypeDesc::FLOAT, image.data.data());
}

void require_readable_file(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw std::runtime_error(path + ": no such file");
  if (fs::is_directory(path, ec)) throw std::runtime_error(path + ": is a directory");
}

FloatImage read_float_image(const std::string& path) {
  require_readable_file(path);
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw std::runtime_error(path + ": cannot read image: " + oiio_error("unknown format"));
  const OIIO::ImageSpec& spec = in->spec();
  FloatImage img;
  img.width = spec.width;
  img.height = spec.height;
  img.channels = spec.nchannels;
  img.channel_names = spec.channelnames;
  img.eight_bit = spec.format == OIIO::TypeDesc::UINT8 && spec.channelformats.empty();
  if (img.width <= 0 || img.height <= 0 || img.channels <= 0) {
    throw std::runtime_error(path + ": image has no pixels");
  }
  img.data.resize(static_cast<std::size_t>(img.width) * img.height * img.channels);
  if (img.eight_bit) {
    // Converted here, not by the codec, so the values are exactly those of to_float_image.
    std::vector<std::uint8_t> raw(img.data.size());
    if (!in->read_image(0, 0, 0, img.channels, OIIO::TypeDesc::UINT8, raw.data())) {
      throw std::runtime_error(path + ": cannot read image: " + one_line(in->geterror()));
    }
    for (std::size_t i = 0; i < raw.size(); ++i)
      img.data[i] = raw[i] / 255.0f;
  } else if (!in->read_image(0, 0, 0, img.channels, OIIO::TypeDesc::FLOAT, img.data.data())) {
    throw std::runtime_error(path + ": cannot read image: " + one_line(in->geterror()));
  }
  in->close();
  return img;
}

Rgb8Image read_rgb8(const std::string& path) {
  require_readable_file(path);
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw std::runtime_error(path + ": cannot read image: " + oiio_error("unknown format"));
  const OIIO::ImageSpec& spec = in->spec();
  const int n = spec.nchannels;
  std::vector<std::uint8_t> raw(static_cast<std::size_t>(spec.width) * spec.height * n);
  if (!in->read_image(0, 0, 0, n, OIIO::TypeDesc::UINT8, raw.data())) {
    throw std::runtime_error(path + ": cannot read image: " + one_line(in->geterror()));
  }
  in->close();
  Rgb8Image img;
  img.width = spec.width;
  img.height = spec.height;
  img.rgb.resize(static_cast<std::size_t>(img.width) * img.height * 3);
  for (std::size_t p = 0; p < static_cast<std::size_t>(img.width) * img.height; ++p) {
    for (int c = 0; c < 3; ++c)
      img.rgb[p * 3 + c] = raw[p * n + (c < n ? c : 0)];
  }
  return img;
}

FloatImage to_float_image(const Rgb8Image& image) {
  FloatImage f;
  f.width = image.width;
  f.height = image.height;
  f.channels = 3;
  f.channel_names = {"R", "G", "B"};
  f.eight_bit = true;
  f.data.resize(image.rgb.size());
  for (std::size_t i = 0; i < image.rgb.size(); ++i)
    f.data[i] = image.rgb[i] / 255.0f;
  return f;
}

}  // namespace saarcor
