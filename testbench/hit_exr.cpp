// Hit EXR read/write through OpenImageIO with per-channel formats (float and uint channels).
#include "testbench/hit_exr.h"

#include <OpenImageIO/imageio.h>
#include <cstring>
#include <stdexcept>

#include "testbench/image_io.h"

namespace saarcor {
namespace {

constexpr int kChannels = static_cast<int>(kHitExrChannels.size());

bool is_uint_channel(int c) {
  return c == 4 || c == 5;
}

// The record as twelve 32-bit words in kHitExrChannels order.
void to_words(const PixelHit& h, std::uint32_t* w) {
  const float f[12] = {h.t, h.u, h.v, h.cos, 0, 0, h.ox, h.oy, h.oz, h.dx, h.dy, h.dz};
  for (int c = 0; c < kChannels; ++c)
    std::memcpy(&w[c], &f[c], 4);
  w[4] = h.instance;
  w[5] = h.triangle;
}

PixelHit from_words(const std::uint32_t* w) {
  float f[12];
  for (int c = 0; c < kChannels; ++c)
    std::memcpy(&f[c], &w[c], 4);
  PixelHit h;
  h.t = f[0];
  h.u = f[1];
  h.v = f[2];
  h.cos = f[3];
  h.instance = w[4];
  h.triangle = w[5];
  h.ox = f[6];
  h.oy = f[7];
  h.oz = f[8];
  h.dx = f[9];
  h.dy = f[10];
  h.dz = f[11];
  return h;
}

std::string one_line(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return s;
}

std::unique_ptr<OIIO::ImageInput> open_input(const std::string& path) {
  require_readable_file(path);
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    std::string e = OIIO::geterror();
    throw std::runtime_error(path +
                             ": cannot read image: " + one_line(e.empty() ? "unknown format" : e));
  }
  return in;
}

}  // namespace

void write_hit_exr(const std::string& path, const HitBuffer& hits) {
  if (hits.width <= 0 || hits.height <= 0 ||
      hits.pixels.size() != static_cast<std::size_t>(hits.width) * hits.height) {
    throw std::runtime_error(path + ": hit buffer to write has inconsistent size");
  }
  OIIO::ImageSpec spec(hits.width, hits.height, kChannels, OIIO::TypeDesc::FLOAT);
  spec.channelnames.assign(kHitExrChannels.begin(), kHitExrChannels.end());
  spec.channelformats.clear();
  for (int c = 0; c < kChannels; ++c) {
    spec.channelformats.push_back(is_uint_channel(c) ? OIIO::TypeDesc::UINT
                                                     : OIIO::TypeDesc::FLOAT);
  }
  spec.attribute("compression", "zip");
  // Without it OpenImageIO stamps the time of writing (capDate): reruns would differ byte-wise.
  spec.attribute("DateTime", kFixedImageDateTime);
  std::vector<std::uint32_t> words(hits.pixels.size() * kChannels);
  for (std::size_t p = 0; p < hits.pixels.size(); ++p)
    to_words(hits.pixels[p], &words[p * kChannels]);

  write_file_atomically(path, [&](const std::string& tmp) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw std::runtime_error(path + ": cannot write a hit EXR with this file extension");
    if (!out->supports("channelformats")) {
      throw std::runtime_error(path + ": this file format cannot hold a hit EXR (use .exr)");
    }
    if (!out->open(tmp, spec)) {
      throw std::runtime_error(path + ": cannot open for writing: " + one_line(out->geterror()));
    }
    // UNKNOWN = the data is in the native per-channel formats of the spec.
    const bool ok = out->write_image(OIIO::TypeDesc::UNKNOWN, words.data());
    const std::string err = ok ? std::string() : one_line(out->geterror());
    const bool closed = out->close();
    if (!ok) throw std::runtime_error(path + ": write failed: " + err);
    if (!closed) throw std::runtime_error(path + ": write failed: " + one_line(out->geterror()));
  });
}

bool is_hit_exr(const std::string& path) {
  auto in = open_input(path);
  const auto& names = in->spec().channelnames;
  for (const auto& n : names) {
    if (n == "hit.t") return true;
  }
  return false;
}

HitBuffer read_hit_exr(const std::string& path) {
  auto in = open_input(path);
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0) throw std::runtime_error(path + ": image has no pixels");
  // EXR stores channels sorted by name: find each by name, with its byte offset in a native pixel.
  std::vector<std::size_t> offset_of(spec.nchannels);
  std::size_t pixel_bytes = 0;
  for (int i = 0; i < spec.nchannels; ++i) {
    offset_of[i] = pixel_bytes;
    pixel_bytes += spec.channelformat(i).size();
  }
  std::size_t offsets[12];
  for (int c = 0; c < kChannels; ++c) {
    int found = -1;
    for (int i = 0; i < spec.nchannels; ++i) {
      if (spec.channelnames[i] == kHitExrChannels[c]) found = i;
    }
    if (found < 0) {
      throw std::runtime_error(path + ": not a hit EXR: channel " + kHitExrChannels[c] +
                               " missing");
    }
    const OIIO::TypeDesc want = is_uint_channel(c) ? OIIO::TypeDesc::UINT : OIIO::TypeDesc::FLOAT;
    if (spec.channelformat(found) != want) {
      throw std::runtime_error(path + ": not a hit EXR: channel " + kHitExrChannels[c] + " is " +
                               spec.channelformat(found).c_str() + ", expected " + want.c_str());
    }
    offsets[c] = offset_of[found];
  }
  const std::size_t npix = static_cast<std::size_t>(spec.width) * spec.height;
  std::vector<unsigned char> raw(npix * pixel_bytes);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UNKNOWN, raw.data())) {
    throw std::runtime_error(path + ": cannot read image: " + one_line(in->geterror()));
  }
  in->close();
  HitBuffer hits;
  hits.width = spec.width;
  hits.height = spec.height;
  hits.pixels.resize(npix);
  for (std::size_t p = 0; p < npix; ++p) {
    std::uint32_t w[12];
    for (int c = 0; c < kChannels; ++c)
      std::memcpy(&w[c], &raw[p * pixel_bytes + offsets[c]], 4);
    hits.pixels[p] = from_words(w);
  }
  return hits;
}

}  // namespace saarcor
