// The example virtual platform (saarcor-vp) against `saarcor render --frames 2` of the same scene
// and resolution, both run here as a user runs them: the same images, byte for byte and pixel for
// pixel, the same cycles, rays, uploads and initial load, and each frame's SystemC times at the
// modelled clock.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "testbench/image_io.h"

namespace saarcor::vp {
namespace {

namespace fs = std::filesystem;

fs::path scratch_path(const std::string& tag) {
  return fs::temp_directory_path() / ("saarcor_vp_" + tag + "_" + std::to_string(getpid()));
}

fs::path scratch(const std::string& tag) {
  const fs::path d = scratch_path(tag);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

struct CliRun {
  int status = -1;
  std::string out, err;
};

// `bin ARGS` from the build's bin/, stdout and stderr captured (SystemC's banner left out).
CliRun run(const std::string& bin, const std::string& args, const fs::path& dir) {
  const std::string cmd = "SYSTEMC_DISABLE_COPYRIGHT_MESSAGE=1 " + std::string(SAARCOR_BIN_DIR) +
                          "/" + bin + " " + args + " >" + (dir / "stdout.txt").string() + " 2>" +
                          (dir / "stderr.txt").string() + " </dev/null";
  const int rc = std::system(cmd.c_str());
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, slurp(dir / "stdout.txt"),
          slurp(dir / "stderr.txt")};
}

// FNV-1a over the pixels.
std::uint64_t pixel_hash(const Rgb8Image& im) {
  std::uint64_t h = 1469598103934665603ull;
  for (std::uint8_t c : im.rgb) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

// cycles at 90 MHz in ps, rounded as SystemC rounds to its 1 ps resolution.
std::uint64_t ps(std::uint64_t cycles) {
  return static_cast<std::uint64_t>(std::llround(static_cast<double>(cycles) * 1e6 / 90.0));
}

// `saarcor render ARGS --model cycle` and `saarcor-vp ARGS`, frame by frame.
void expect_same_frames(const std::string& tag, const std::string& args, std::size_t frames) {
  const fs::path d = scratch(tag);
  const CliRun r =
      run("saarcor", "render " + args + " --model cycle --out-dir " + (d / "render").string(), d);
  ASSERT_EQ(r.status, 0) << r.err;
  const CliRun v = run("saarcor-vp", args + " --out-dir " + (d / "vp").string(), d);
  ASSERT_EQ(v.status, 0) << v.err;
  const nlohmann::json render = nlohmann::json::parse(slurp(d / "render" / "report.json"));
  const nlohmann::json vp = nlohmann::json::parse(slurp(d / "vp" / "platform.json"));
  ASSERT_EQ(render["per_frame"].size(), frames);
  ASSERT_EQ(vp["frames"].size(), frames);
  EXPECT_EQ(vp["clock_mhz"].get<double>(), 90.0);
  EXPECT_EQ(vp["initial_load"]["bytes"], render["initial_load"]["bytes"]);
  EXPECT_EQ(vp["initial_load"]["cycles"], render["initial_load"]["cycles"]);
  const std::uint64_t start0 = vp["frames"][0]["start_ps"];
  // Frame 0 begins once the initial load is stored: START at 0 + its cycles at the clock.
  EXPECT_EQ(start0, vp["frames"][0]["start_written_ps"].get<std::uint64_t>() +
                        ps(render["initial_load"]["cycles"].get<std::uint64_t>()));
  for (std::size_t k = 0; k < frames; ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const nlohmann::json& a = render["per_frame"][k];
    const nlohmann::json& b = vp["frames"][k];
    EXPECT_EQ(b["cycles"], a["cycles"]);
    EXPECT_EQ(b["rays"], a["rays"]);
    EXPECT_EQ(b["upload_cycles"], a["upload_cycles"]);
    EXPECT_EQ(b["upload_in_gap"], a["upload_in_gap"]);
    if (k > 0) {
      EXPECT_EQ(b["upload_bytes"], a["upload_bytes"]);
    }
    // The frame ends cycles / clock_mhz after it begins, and the host sees it then; it begins
    // where `render --frames` places it on the sequence's clock.
    const std::uint64_t start = b["start_ps"], end = b["end_ps"];
    EXPECT_EQ(end - start, ps(a["cycles"].get<std::uint64_t>()));
    EXPECT_EQ(b["end_seen_ps"].get<std::uint64_t>(), end);
    EXPECT_EQ(start - start0, ps(a["start_cycle"].get<std::uint64_t>()));
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04zu.png", k);
    EXPECT_EQ(slurp(d / "vp" / name), slurp(d / "render" / name));  // the file, byte for byte
    const Rgb8Image ri = read_rgb8((d / "render" / name).string());
    const Rgb8Image vi = read_rgb8((d / "vp" / name).string());
    EXPECT_EQ(vi.rgb, ri.rgb);
    EXPECT_EQ(pixel_hash(vi), pixel_hash(ri));
  }
}

TEST(VirtualPlatform, TwoFramesEqualRenderFramesTwoAtTheModelledTime) {
  expect_same_frames("frames", "builtin:dynamic --res 64x48 --frames 2", 2);
  // Frame 1's upload (16 instances moved) went beside frame 0 and was stored before its end.
  const nlohmann::json vp =
      nlohmann::json::parse(slurp(scratch_path("frames") / "vp" / "platform.json"));
  EXPECT_FALSE(vp["frames"][1]["upload_in_gap"].get<bool>());
  EXPECT_GT(vp["frames"][1]["upload_bytes"].get<std::uint64_t>(), 0u);
  EXPECT_LT(vp["frames"][1]["upload_cycles"].get<std::uint64_t>(),
            vp["frames"][0]["cycles"].get<std::uint64_t>());
}

// One top-level copy: every upload waits for the frame's end and is stored before the next
// START's frame begins (render --frame-gap's timeline).
TEST(VirtualPlatform, FrameGapUploadsEqualRenderFrameGap) {
  expect_same_frames("gap", "builtin:dynamic --res 32x24 --frames 3 --frame-gap", 3);
  const nlohmann::json vp =
      nlohmann::json::parse(slurp(scratch_path("gap") / "vp" / "platform.json"));
  EXPECT_TRUE(vp["frames"][1]["upload_in_gap"].get<bool>());
  // In a gap the upload takes the frame before and then its own time alone (LOAD cycles).
  EXPECT_EQ(vp["frames"][1]["upload_cycles"].get<std::uint64_t>(),
            vp["frames"][0]["cycles"].get<std::uint64_t>() +
                vp["frames"][1]["load_cycles"].get<std::uint64_t>());
}

TEST(VirtualPlatform, BadInputIsOneLineAndExitOne) {
  const fs::path d = scratch("bad");
  for (const std::string& args :
       {std::string("--frames 0"), std::string("--res 0x4"), std::string("--bogus"),
        std::string("builtin:nosuch --res 16x12"), std::string("--set threads=0 --res 16x12")}) {
    SCOPED_TRACE(args);
    const CliRun v = run("saarcor-vp", args + " --out-dir " + (d / "out").string(), d);
    EXPECT_EQ(v.status, 1);
    EXPECT_EQ(v.err.rfind("saarcor-vp: ", 0), 0u) << v.err;
    EXPECT_EQ(v.err.find('\n'), v.err.size() - 1) << v.err;  // one line
  }
}

}  // namespace
}  // namespace saarcor::vp
