// libFuzzer harness of the AFF (BART) loader (host/aff_loader.h; docs/fuzzing.md): the input is an
// .aff file, loaded the way `saarcor` loads a scene (load_scene), evaluated at the middle of its
// animation, and, when it is small, built into a memory image that must decode. Bad input may only
// end in one std::runtime_error line (fuzz::documented_errors_only); crashes, sanitizer reports,
// other exceptions, hangs and allocations beyond -rss_limit_mb are findings.
//
// The input is written to aff/input.aff in a scratch folder laid out as BART's scenes are: aff/
// links the BART .aff files of at most 64 KiB (includes of larger ones are "not found": they make
// an execution slow), TextureFiles/ every texture, so `i`, `tt` and `m ... texturecoords` resolve.
#include <cstddef>
#include <cstdint>

#include "host/fuzz_support.h"

namespace {

namespace fs = std::filesystem;
using saarcor::fuzz::ScratchDir;

ScratchDir* scratch = nullptr;

constexpr std::uintmax_t kIncludeBytes = 65536;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  static ScratchDir dir("aff");
  const fs::path bart = fs::path(SAARCOR_SHARED_SCENES) / "BART";
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(bart, ec)) {
    dir.link_files(e.path() / "aff", "aff", [](const fs::path& p) {
      std::error_code size_ec;
      return p.extension() == ".aff" && fs::file_size(p, size_ec) <= kIncludeBytes;
    });
    dir.link_files(e.path() / "TextureFiles", "TextureFiles", [](const fs::path&) { return true; });
  }
  scratch = &dir;
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = scratch->write("aff/input.aff", data, size);
  saarcor::fuzz::documented_errors_only([&] { saarcor::fuzz::exercise_scene_file(path); });
  return 0;
}
