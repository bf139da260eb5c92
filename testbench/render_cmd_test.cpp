// `saarcor render`: argument parsing, both models on small scenes, the hit records' contract
// (glTF node ids, exact binary32 conversion, --pixel equals the frame), the written files, and
// the real binary end to end with its one-line errors.
#include "testbench/render_cmd.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "testbench/compare.h"
#include "testbench/hit_exr.h"
#include "testbench/image_io.h"
#include "testbench/testing.h"

namespace saarcor {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
  return test_support::scratch_dir("render");
}

using test_support::error_of;

std::uint32_t bits(float f) {
  std::uint32_t b;
  std::memcpy(&b, &f, 4);
  return b;
}

TEST(RenderArgs, Resolution) {
  EXPECT_EQ(parse_resolution("64x48").width, 64);
  EXPECT_EQ(parse_resolution("64x48").height, 48);
  EXPECT_EQ(parse_resolution("1x1").width, 1);
  for (const char* bad :
       {"64", "x48", "64x", "0x48", "64x0", "axb", "64x48x2", "-1x5", "99999x1", "64 x48", ""}) {
    const std::string e = error_of([&] { parse_resolution(bad); });
    EXPECT_EQ(e.rfind(std::string("bad --res '") + bad + "'", 0), 0u) << e;
  }
}

TEST(RenderArgs, OutputPrefix) {
  EXPECT_EQ(output_prefix("out/render", {".png", ".exr"}), "out/render");
  EXPECT_EQ(output_prefix("out/frame.png", {".png", ".exr"}), "out/frame");
  EXPECT_EQ(output_prefix("frame.exr", {".png", ".exr"}), "frame");
  EXPECT_EQ(output_prefix("frame.json", {".png", ".exr"}), "frame.json");  // not one it writes
  EXPECT_EQ(output_prefix("frame.png.png", {".png"}), "frame.png");
  for (const char* bad : {"", ".png"}) {
    EXPECT_EQ(error_of([&] {
                output_prefix(bad, {".png", ".exr"});
              }),
              std::string("bad --out '") + bad + "': expected a file prefix");
  }
}

TEST(RenderArgs, Pixel) {
  const Resolution r{64, 48};
  EXPECT_EQ(parse_pixel("10,20", r).x, 10);
  EXPECT_EQ(parse_pixel("63,47", r).y, 47);
  EXPECT_EQ(error_of([&] { parse_pixel("64,0", r); }),
            "bad --pixel '64,0': outside the 64x48 frame");
  EXPECT_EQ(error_of([&] { parse_pixel("1;2", r); }),
            "bad --pixel '1;2': expected x,y, e.g. 10,20");
  EXPECT_NE(error_of([&] { parse_pixel("-1,2", r); }), "(no error)");
}

TEST(RenderArgs, Models) {
  EXPECT_EQ(parse_model("float").kind, ModelKind::kFloat);
  EXPECT_EQ(parse_model("fp24").kind, ModelKind::kFunctional);
  EXPECT_EQ(parse_model("fp24").mantissa, 16);
  EXPECT_EQ(parse_model("e7m12").mantissa, 12);
  EXPECT_EQ(parse_model("e7m23").mantissa, 23);
  EXPECT_EQ(parse_model("cycle").kind, ModelKind::kCycle);  // landed with the cycle model
  EXPECT_EQ(parse_model("cycle").mantissa, 16);
  EXPECT_EQ(parse_model("cycle-e7m23").kind, ModelKind::kCycle);  // the width study
  EXPECT_EQ(parse_model("cycle-e7m23").mantissa, 23);
  EXPECT_EQ(error_of([] { parse_model("fp16"); }),
            "unknown model 'fp16': expected float, fp24, e7m10..e7m23, cycle or cycle-e7m23");
  EXPECT_NE(error_of([] { parse_model("cycle-e7m20"); }).find("unknown model"), std::string::npos);
  EXPECT_NE(error_of([] { parse_model("e7m9"); }).find("unknown model 'e7m9'"), std::string::npos);
  EXPECT_NE(error_of([] { parse_model("e7m24"); }).find("unknown model"), std::string::npos);
}

RenderSettings small() {
  RenderSettings s;
  s.res = {32, 24};
  return s;
}

TEST(RenderModels, FloatAndFp24OnBuiltinCube) {
  const RenderSettings s = small();
  const PreparedScene prep = prepare_scene("builtin:cube", s);
  std::set<std::uint32_t> ids;
  for (const auto& inst : prep.built.instances)
    ids.insert(inst.id);
  for (const char* name : {"float", "fp24"}) {
    const FrameResult f = render_model(parse_model(name), prep, s);
    ASSERT_EQ(f.hits.width, 32);
    ASSERT_EQ(f.hits.height, 24);
    ASSERT_EQ(f.image.rgb.size(), 32u * 24 * 3);
    EXPECT_EQ(f.rays, 32u * 24);
    int hits = 0;
    for (const PixelHit& h : f.hits.pixels) {
      if (!h.hit()) {
        EXPECT_TRUE(std::isinf(h.t));
        EXPECT_EQ(h.triangle, 0xFFFFFFFFu);
        continue;
      }
      ++hits;
      EXPECT_TRUE(ids.count(h.instance)) << name << " instance " << h.instance;
      EXPECT_GT(h.t, 0.0f);
      EXPECT_GE(h.u, 0.0f);
      EXPECT_GE(h.v, 0.0f);
      if (std::string(name) == "fp24") {
        // fp24 values converted exactly: the 7 low mantissa bits of binary32 are zero.
        for (float v : {h.t, h.u, h.v, h.cos, h.dx, h.dy, h.dz}) {
          EXPECT_EQ(bits(v) & 0x7Fu, 0u) << v;
        }
      }
    }
    EXPECT_GT(hits, 32 * 24 / 10) << name << ": the cube should cover part of the frame";
    EXPECT_GT(f.counters["per_ray"].size(), 0u);
  }
}

TEST(RenderModels, Mantissa23ReproducesTheFloatReferenceBitForBit) {
  // Float<7,23> has binary32's precision; with the same op order the functional model must give
  // the float reference's hit records and image exactly (a check of both models). The golden
  // reference takes rays into instances in binary64; in binary32 it is the datapath exactly.
  // builtin:dynamic has 17 instances with rotations, scales and translations.
  for (const char* scene : {"builtin:room", "builtin:dynamic", "builtin:cube"}) {
    SCOPED_TRACE(scene);
    RenderSettings s = small();
    s.float_instance_step = host::InstanceStep::kBinary32;
    PreparedScene prep = prepare_scene(scene, s);
    const FrameResult ref = render_model(parse_model("float"), prep, s);
    build_prepared_image(prep, s, ff::Format{7, 23});
    const FrameResult m23 = render_model(parse_model("e7m23"), prep, s);
    const CompareResult c = compare_hits(m23.hits, ref.hits);
    EXPECT_TRUE(c.bit_identical) << compare_summary(c);
    EXPECT_EQ(m23.image.rgb, ref.image.rgb);
    // The golden reference differs from it only in the last bits of t.
    s.float_instance_step = host::InstanceStep::kBinary64;
    const FrameResult golden = render_model(parse_model("float"), prep, s);
    const CompareResult g = compare_hits(m23.hits, golden.hits);
    EXPECT_DOUBLE_EQ(g.same_triangle_pct, 100.0) << compare_summary(g);
    EXPECT_LT(g.t_rel_err_max.value_or(0.0), 1e-6) << compare_summary(g);
  }
}

TEST(RenderModels, FunctionalModelNeedsItsImageFormat) {
  const RenderSettings s = small();
  const PreparedScene prep = prepare_scene("builtin:triangle", s);  // fp24 image
  EXPECT_NE(error_of([&] {
              render_model(parse_model("e7m12"), prep, s);
            }).find("needs a memory image in Float<7,12>"),
            std::string::npos);
}

TEST(RenderModels, PixelReplayEqualsTheFrame) {
  const RenderSettings s = small();
  const PreparedScene prep = prepare_scene("builtin:dynamic", s);
  for (const char* name : {"float", "fp24"}) {
    const ModelSpec m = parse_model(name);
    const FrameResult f = render_model(m, prep, s);
    for (PixelCoord p :
         {PixelCoord{0, 0}, PixelCoord{16, 12}, PixelCoord{31, 23}, PixelCoord{5, 19}}) {
      const PixelHit one = trace_pixel(m, prep, s, p);
      EXPECT_EQ(std::memcmp(&one, &f.hits.at(p.x, p.y), sizeof(PixelHit)), 0)
          << name << " pixel " << p.x << "," << p.y << "\n"
          << format_pixel_hit(p, one) << format_pixel_hit(p, f.hits.at(p.x, p.y));
    }
  }
}

TEST(RenderModels, GltfHitsReportNodeIndices) {
  // SimpleMeshes: one mesh used by two nodes; hit.instance is the glTF node index.
  const RenderSettings s = small();
  const PreparedScene prep =
      prepare_scene(std::string(SAARCOR_SHARED_SCENES) + "/SimpleMeshes/SimpleMeshes.gltf", s);
  ASSERT_EQ(prep.scene.instances.size(), 2u);
  std::set<std::uint32_t> want;
  for (const auto& inst : prep.scene.instances)
    want.insert(inst.id);
  const FrameResult f = render_model(parse_model("fp24"), prep, s);
  std::set<std::uint32_t> seen;
  for (const PixelHit& h : f.hits.pixels) {
    if (!h.hit()) continue;
    seen.insert(h.instance);
    EXPECT_LT(h.triangle, prep.scene.objects[0].triangles.size());
  }
  EXPECT_EQ(seen, want);
}

TEST(RenderModels, BadSettings) {
  RenderSettings s = small();
  s.depth = -1;
  EXPECT_EQ(error_of([&] { prepare_scene("builtin:cube", s); }), "bad --depth -1: expected 0..16");
  s = small();
  s.time = -2;
  EXPECT_NE(error_of([&] { prepare_scene("builtin:cube", s); }).find("bad --time"),
            std::string::npos);
  s = small();
  s.bank_mb = 0;
  EXPECT_NE(error_of([&] { prepare_scene("builtin:cube", s); }).find("bad --bank-mb"),
            std::string::npos);
  EXPECT_NE(error_of([&] { prepare_scene("/nonexistent/scene.gltf", small()); }), "(no error)");
}

TEST(RunRender, WritesEveryOutput) {
  const fs::path d = temp_dir() / "run";
  RenderOptions o;
  o.scene = "builtin:cube";
  o.model = "fp24";
  o.res = "32x24";
  o.out = (d / "img").string();
  o.exr = true;
  o.hits = (d / "hits.exr").string();
  o.report = (d / "report.json").string();
  ASSERT_EQ(run_render(o), 0);
  const Rgb8Image png = read_rgb8(o.out + ".png");
  EXPECT_EQ(png.width, 32);
  const FloatImage exr = read_float_image(o.out + ".exr");
  EXPECT_EQ(exr.channels, 3);
  EXPECT_EQ(exr.data, to_float_image(png).data);
  // The hit EXR holds exactly what the model returns.
  const RenderSettings s = small();
  const PreparedScene prep = prepare_scene("builtin:cube", s);
  const FrameResult f = render_model(parse_model("fp24"), prep, s);
  EXPECT_TRUE(compare_hits(read_hit_exr(o.hits), f.hits).bit_identical);
  EXPECT_EQ(png.rgb, f.image.rgb);
  std::ifstream rf(o.report);
  const nlohmann::json j = nlohmann::json::parse(rf);
  EXPECT_EQ(j["scene"], "builtin:cube");
  EXPECT_EQ(j["model"], "fp24");
  EXPECT_EQ(j["resolution"]["width"], 32);
  EXPECT_EQ(j["rays"], 32 * 24);
  EXPECT_GT(j["rays_per_second"].get<double>(), 0.0);
  EXPECT_TRUE(j["counters"]["per_ray"]["primary"].contains("traversal_steps"));
  EXPECT_GT(j["counters"]["ops"]["intersection"]["div"].get<std::uint64_t>(), 0u);
  EXPECT_EQ(j["configuration"]["image_format"], "Float<7,16> (e7m16)");
}

TEST(RunRender, OutWithTheImageExtensionNamesTheImage) {
  const fs::path d = temp_dir() / "ext";
  fs::remove_all(d);
  RenderOptions o;
  o.scene = "builtin:cube";
  o.res = "8x8";
  o.out = (d / "frame.png").string();
  o.exr = true;
  ASSERT_EQ(run_render(o), 0);
  EXPECT_EQ(read_rgb8((d / "frame.png").string()).width, 8);
  EXPECT_EQ(read_float_image((d / "frame.exr").string()).width, 8);
  EXPECT_FALSE(fs::exists(d / "frame.png.png"));
}

TEST(RunRender, BadOutputNamesFailBeforeRendering) {
  RenderOptions o;
  o.scene = "builtin:cube";
  o.res = "8x8";
  o.out = (temp_dir() / "never").string();
  o.hits = (temp_dir() / "hits.png").string();
  EXPECT_EQ(error_of([&] { run_render(o); }),
            "bad --hits '" + o.hits + "': a hit EXR file name ends in .exr");
  EXPECT_FALSE(fs::exists(o.out + ".png"));
}

// ---- the real binary ---------------------------------------------------------------------------

using test_support::CliRun;
using test_support::expect_one_line_error;
const auto saarcor = test_support::run_saarcor;

TEST(SaarcorBinary, RenderCompareEndToEnd) {
  const fs::path d = temp_dir() / "e2e";
  fs::remove_all(d);
  const std::string hits_a = (d / "a.exr").string(), hits_b = (d / "b.exr").string();
  CliRun r = saarcor("render builtin:cube --model fp24 --res 24x16 --out " + (d / "fp24").string() +
                     " --hits " + hits_a);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find((d / "fp24.png").string()), std::string::npos) << r.out;
  EXPECT_TRUE(r.err.empty()) << "progress must stay off when stderr is not a terminal: " << r.err;
  r = saarcor("render builtin:cube --model float --res 24x16 --out " + (d / "float").string() +
              " --hits " + hits_b);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string report = (d / "cmp.json").string();
  r = saarcor("compare " + hits_a + " " + hits_b + " --report " + report + " --diff " +
              (d / "diff.png").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("same triangle:"), std::string::npos) << r.out;
  std::ifstream f(report);
  const nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_EQ(j["pixels"], 24 * 16);
  EXPECT_GE(j["same_triangle_pct"].get<double>(), 99.0);
  EXPECT_TRUE(fs::exists(d / "diff.png"));
  r = saarcor("render builtin:cube --model fp24 --res 24x16 --pixel 12,8");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("pixel 12,8: "), std::string::npos) << r.out;
}

TEST(SaarcorBinary, OneLineErrors) {
  const fs::path d = temp_dir();
  expect_one_line_error(saarcor("render /nonexistent/x.gltf --res 8x8"), "/nonexistent/x.gltf");
  expect_one_line_error(saarcor("render builtin:cube --res 8by8"), "bad --res '8by8'");
  expect_one_line_error(saarcor("render builtin:cube --model magic"), "unknown model 'magic'");
  expect_one_line_error(saarcor("render builtin:cube --model fp16"), "unknown model 'fp16'");
  expect_one_line_error(saarcor("compare " + (d / "none.exr").string() + " x.exr"),
                        "none.exr: no such file");
  {
    std::ofstream junk(d / "junk.exr");
    junk << "not an image";
  }
  expect_one_line_error(
      saarcor("compare " + (d / "junk.exr").string() + " " + (d / "junk.exr").string()),
      "junk.exr: cannot read image");
  expect_one_line_error(saarcor("precision builtin:cube --mantissa 8..30"), "bad --mantissa");
  expect_one_line_error(saarcor("render builtin:cube --res 8x8 --set image.camera=1"),
                        "camera 1 does not exist (the scene has 1 cameras)");
}

}  // namespace
}  // namespace saarcor
