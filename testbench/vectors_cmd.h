// `saarcor vectors`: unit transaction vectors for RTL verification (units/unit_vectors.h,
// docs/unit-vectors.md). Writes a sample of one unit's transactions from a real frame of the
// functional fp24 model as a text file, one transaction per line (inputs then outputs, fp24
// encodings in hex, flags 0/1), or checks such a file, e.g. one an RTL simulation filled in,
// against the datapath line by line.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "testbench/vector_file.h"
#include "units/unit_vectors.h"

namespace saarcor {

struct VectorsOptions {
  std::string scene;  // generate: glTF path or builtin:NAME
  std::string unit;   // traversal | transformation | intersection
  std::size_t count = 1000;
  std::uint64_t seed = 1;
  std::string res = "128x96";
  double time = 0.0;
  double bank_mb = 4.0;
  bool shadows = false;  // the frame's shadow rays (their generation steps, their traversal)
  int depth = 0;         // secondary rays (reflection, transparency) up to this depth
  std::string out;       // generate: the vector file
  std::string check;     // check this vector file instead of generating
};

// Returns 0, or 2 when `--check` finds vectors whose outputs differ from the datapath's (they are
// listed on stdout); throws std::runtime_error with one line on bad input, before writing anything.
int run_vectors(const VectorsOptions& opts);

}  // namespace saarcor
