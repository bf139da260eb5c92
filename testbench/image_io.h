// Image files of the testbench (README.md "Layout": image I/O stays in testbench/ and host/):
// every image the tools write or read goes through OpenImageIO here. Writers never leave a
// partial file behind: they write a temporary file beside the target and rename it into place.
// Every failure throws std::runtime_error with one line naming the file.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "testbench/hit_buffer.h"

namespace saarcor {

// A float image with N interleaved channels (the shaded image as EXR, or an image read back).
struct FloatImage {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<std::string> channel_names;
  std::vector<float> data;  // width * height * channels, row-major, row 0 at the top
  bool eight_bit = false;   // read from a file whose pixels are 8-bit (values are v / 255)
  float at(int x, int y, int c) const {
    return data[(static_cast<std::size_t>(y) * width + x) * channels + c];
  }
};

// The DateTime every written image carries (an EXR's capDate). OpenImageIO stamps the time of
// writing when none is given, and that stamp alone made two runs of the same command write
// different bytes; the Unix epoch (SOURCE_DATE_EPOCH=0's date) says "no date" and keeps every
// file a function of the run's inputs (docs/runs.md).
inline constexpr const char* kFixedImageDateTime = "1970:01:01 00:00:00";

// Runs write(tmp) with a temporary path beside `path` (same extension, so OpenImageIO picks the
// same format), then renames it to `path`. The parent directory is created when missing. If
// write throws, the temporary file is removed and the exception passes on; `path` is untouched.
void write_file_atomically(const std::string& path,
                           const std::function<void(const std::string& tmp_path)>& write);

// Writes `text` to `path` atomically (used for JSON reports).
void write_text_file(const std::string& path, const std::string& text);

// RGB8 as PNG (or any 8-bit format OpenImageIO knows by the extension).
void write_rgb8(const std::string& path, const Rgb8Image& image);
// Float image (EXR); channel names default to R, G, B[, A].
void write_float_image(const std::string& path, const FloatImage& image);
// Reads any image OpenImageIO can open, converting every channel to float (8-bit values map to
// v / 255 exactly as OpenImageIO converts them).
FloatImage read_float_image(const std::string& path);
// Reads an image as 8-bit RGB (channels beyond three are dropped; grey is replicated).
Rgb8Image read_rgb8(const std::string& path);

// Rgb8Image -> FloatImage with values v / 255 (what read_float_image gives for the PNG).
FloatImage to_float_image(const Rgb8Image& image);

// Throws "PATH: no such file" when the file does not exist (a clearer line than the codec's).
void require_readable_file(const std::string& path);

}  // namespace saarcor
