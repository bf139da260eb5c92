// Test-only helpers of the libFuzzer harnesses (foo_fuzz.cpp; cmake/fuzz.cmake, docs/fuzzing.md):
// the rule that separates the documented error path from a finding, and a scratch folder that
// holds the input as a file beside the files it may refer to. Standard library only.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

#include "host/image_builder.h"
#include "host/scene.h"

namespace saarcor::fuzz {

// A finding the sanitizers cannot see (a broken promise of the code under test): printed, then
// abort(), which libFuzzer reports as a crash and saves the input for.
[[noreturn]] inline void finding(const std::string& what) {
  std::fprintf(stderr, "saarcor fuzz finding: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

// Runs f. Bad input may end it the documented way: a std::runtime_error with one line (not
// empty, no '\n', and no '\r' unless `allow_cr`: a command-line argument the message quotes is the
// user's own text, a file's bytes are not). Any other exception escapes to libFuzzer as a crash; a
// message of several lines is a finding.
template <class F>
void documented_errors_only(F&& f, bool allow_cr = false) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    if (m.empty() || m.find('\n') != std::string::npos ||
        (!allow_cr && m.find('\r') != std::string::npos))
      finding("error message is not one line: '" + m + "'");
  }
}

// <tmp>/saarcor_fuzz_<tag>_<pid>, removed at exit (links are removed, never what they point to).
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& tag)
      : dir_(std::filesystem::temp_directory_path() /
             ("saarcor_fuzz_" + tag + "_" + std::to_string(getpid()))) {
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const std::filesystem::path& path() const { return dir_; }

  // Symbolic links in <dir>/<sub> to the regular files of `from` (not recursive) that `keep`
  // accepts; a name already there keeps its first link. A missing `from` links nothing. Images
  // (by extension) link to a 2x2 PNG stand-in instead: decoding and resampling the scenes' real
  // textures (up to 2048x2048) would make an execution take seconds; the loaders tell an image's
  // format by its bytes, so the stand-in decodes under any of these names.
  template <class Keep>
  void link_files(const std::filesystem::path& from, const std::string& sub, Keep keep) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path to = dir_ / sub;
    fs::create_directories(to);
    for (const fs::directory_entry& e : fs::directory_iterator(from, ec)) {
      if (!e.is_regular_file(ec) || !keep(e.path())) continue;
      const fs::path link = to / e.path().filename();
      if (!fs::exists(fs::symlink_status(link, ec)))
        fs::create_symlink(is_image(e.path()) ? stand_in_image() : e.path(), link, ec);
    }
  }

  // Writes the input as <dir>/<name> and returns its path.
  std::string write(const std::string& name, const unsigned char* data, std::size_t size) const {
    const std::filesystem::path p = dir_ / name;
    std::ofstream f(p, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    f.close();
    if (!f) finding("cannot write the input to " + p.string());
    return p.string();
  }

 private:
  static bool is_image(const std::filesystem::path& p) {
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    for (const char* e :
         {".png", ".jpg", ".jpeg", ".ppm", ".bmp", ".gif", ".tif", ".tiff", ".webp"})
      if (ext == e) return true;
    return false;
  }

  std::filesystem::path stand_in_image() const {
    static constexpr unsigned char kPng[] = {
        0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44,
        0x52, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x02, 0x08, 0x06, 0x00, 0x00, 0x00, 0x72,
        0xb6, 0x0d, 0x24, 0x00, 0x00, 0x00, 0x12, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0xf8,
        0xcf, 0xc0, 0xf0, 0x1f, 0x0c, 0x81, 0x34, 0x18, 0x00, 0x00, 0x49, 0xc8, 0x09, 0xf7, 0xf9,
        0xab, 0xb6, 0x0d, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
    const std::filesystem::path p = dir_ / ".stand_in.png";
    if (!std::filesystem::exists(p)) write(".stand_in.png", kPng, sizeof kPng);
    return p;
  }

  std::filesystem::path dir_;
};

// What `saarcor` does with a scene file, for the loader harnesses: load it (load_scene), evaluate
// its animation at the middle, and for scenes up to 20,000 triangle slots after instancing (a few
// milliseconds each in the instrumented build) build the memory image with 1 MB banks (larger
// scenes take the "does not fit" error path) and decode it: a built image is the contract with
// the hardware, so decoding it must succeed.
inline void exercise_scene_file(const std::string& path) {
  using namespace saarcor::host;
  constexpr std::uint64_t kBuildTriangles = 20000;
  Scene scene = load_scene(path);
  if (scene.animation_seconds > 0.0) scene.set_time(0.5 * scene.animation_seconds);
  if (scene.instanced_triangles() > kBuildTriangles) return;
  ImageParams ip;
  ip.width = 16;
  ip.height = 12;
  ip.bank_words = 1u << 18;
  const BuiltImage built = build_image(scene, ip);
  try {
    const DecodedImage d = decode_image(built.image);
    if (d.instances.size() != built.instances.size())
      finding("decoded image has " + std::to_string(d.instances.size()) +
              " instances, the builder wrote " + std::to_string(built.instances.size()));
  } catch (const std::runtime_error& e) {
    finding(std::string("a built image does not decode: ") + e.what());
  }
}

}  // namespace saarcor::fuzz
