// libFuzzer harness of the glTF loader (host/gltf_loader.h; docs/fuzzing.md): the input is a .gltf
// (JSON) or .glb file (the loader tells them apart by the "glTF" magic), loaded the way `saarcor`
// loads a scene (load_scene: the loader, the time-0 evaluation, the default light), evaluated at
// the middle of its animation, and, when it is small, built into a memory image that must decode.
// Bad input may only end in one std::runtime_error line (fuzz::documented_errors_only); crashes,
// sanitizer reports, other exceptions, hangs and allocations beyond -rss_limit_mb are findings.
//
// The input is written to input.gltf in a scratch folder that links every file of the shared
// scenes' folders (buffers and images): a seed's "uri": "Duck0.bin" resolves, so mutations reach
// the loader's accessor, mesh, node and animation code, not only tinygltf's JSON parser.
#include <cstddef>
#include <cstdint>

#include "host/fuzz_support.h"

namespace {

namespace fs = std::filesystem;
using saarcor::fuzz::ScratchDir;

ScratchDir* scratch = nullptr;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  static ScratchDir dir("gltf");
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(SAARCOR_SHARED_SCENES, ec))
    if (e.is_directory(ec))
      dir.link_files(e.path(), ".", [](const fs::path& p) {
        return p.extension() != ".gltf" && p.extension() != ".glb";
      });
  scratch = &dir;
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = scratch->write("input.gltf", data, size);
  saarcor::fuzz::documented_errors_only([&] { saarcor::fuzz::exercise_scene_file(path); });
  return 0;
}
