// libFuzzer harness of the unit vector file reader (`saarcor vectors --check FILE`,
// testbench/vector_file.h; docs/fuzzing.md): the input is a vector file's text, checked line by
// line against the datapath. A file that is read must give consistent counts; bad input may only
// end in one std::runtime_error line naming the line (fuzz::documented_errors_only); anything else
// is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "host/fuzz_support.h"
#include "testbench/vector_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  saarcor::fuzz::documented_errors_only([&] {
    const saarcor::VectorCheck r = saarcor::check_vector_text(text);
    if (r.differing > r.vectors || r.first_differences.size() > 5 ||
        (r.differing > 0) != !r.first_differences.empty())
      saarcor::fuzz::finding("inconsistent check: " + std::to_string(r.vectors) + " vectors, " +
                             std::to_string(r.differing) + " differing, " +
                             std::to_string(r.first_differences.size()) + " listed");
  });
  return 0;
}
