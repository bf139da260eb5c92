// Unit vector files (docs/unit-vectors.md) as the RTL testbenches read and write them: the unit
// named in the header, then one transaction per line, the unit's inputs and then its outputs
// (fp24 encodings in hex, flags 0/1).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "units/unit_vectors.h"

namespace saarcor::rtl {

struct VectorLine {
  std::size_t line = 0;  // 1-based line number in the file
  std::vector<std::uint32_t> in, out;
};

struct VectorFile {
  units::VectorUnit unit = units::VectorUnit::kTraversal;
  std::vector<std::string> header;  // the '#' lines, verbatim
  std::vector<VectorLine> vectors;
};

// Parses a vector file's text; throws std::runtime_error "NAME: line N: ..." for a malformed one
// (no "# unit: " line, a wrong field count, a non-hex or too wide encoding, a flag not 0/1).
VectorFile parse_vector_text(const std::string& text, const std::string& name);
// Reads and parses a file; throws std::runtime_error naming it when it cannot be read.
VectorFile read_vector_file(const std::string& path);

// The file again with each vector's outputs replaced by `outputs` (one per vector, in order).
std::string format_vector_file(const VectorFile& file,
                               const std::vector<std::vector<std::uint32_t>>& outputs);

}  // namespace saarcor::rtl
