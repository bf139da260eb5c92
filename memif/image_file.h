// The memory image as a file (docs/memory-image.md "Image file"): what `saarcor scene SCENE
// --write-image FILE` writes and what a reference outside this process (the DPI-C library of
// rtl/dpi/) loads, so a testbench can trace the very words the host would upload. A versioned
// header (the float format, the bank size, the item regions, the frame registers), then each of
// the six SRAM banks up to its last non-zero word, then a checksum over everything before it.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

#include "memif/image_format.h"

namespace saarcor::memif {

inline constexpr char kImageFileMagic[8] = {'S', 'A', 'A', 'R', 'C', 'O', 'R', 'I'};
inline constexpr std::uint32_t kImageFileVersion = 1;

// Writes `image`; throws std::runtime_error with one line when the stream fails.
void write_image_file(const MemoryImage& image, std::ostream& out);
void write_image_file(const MemoryImage& image, const std::string& path);

// Reads an image file. Throws std::runtime_error with one line that names `what` (the path) for a
// file that is not an image file (wrong magic), of another version, truncated, with trailing
// bytes, a checksum that does not match, a float format the model has no operators for, or
// regions and registers that point outside the banks.
MemoryImage read_image_file(std::istream& in, const std::string& what);
MemoryImage read_image_file(const std::string& path);

}  // namespace saarcor::memif
