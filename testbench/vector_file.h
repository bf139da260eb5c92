// The text of a unit vector file (`saarcor vectors`, docs/unit-vectors.md): written from a capture
// of the functional fp24 model, read back and checked line by line against the datapath. Kept apart
// from the command (vectors_cmd.*) so the reader links without the models that write the file
// (testbench/vector_file_fuzz.cpp fuzzes it).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "units/unit_vectors.h"

namespace saarcor {

// The file: '#' header lines (the unit, the field names, the source), then one vector per line.
std::string format_vector_file(units::VectorUnit unit, const units::VectorCapture& capture,
                               const std::string& source);

struct VectorCheck {
  units::VectorUnit unit = units::VectorUnit::kTraversal;
  std::size_t vectors = 0;
  std::size_t differing = 0;
  std::vector<std::string> first_differences;  // "line L: field F is X, the datapath gives Y"
};
// Checks every line of a vector file's text; throws one line naming the line for a malformed one.
VectorCheck check_vector_text(const std::string& text);

}  // namespace saarcor
