// Comparison metrics on constructed buffers and images whose answers are known by hand.
#include "testbench/compare.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "testbench/hit_exr.h"
#include "testbench/report.h"
#include "testbench/testing.h"

namespace saarcor {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
  return test_support::scratch_dir("compare");
}

// 10x10 frame: left half misses, right half hits triangle (instance 3, triangle x+10y) at the
// centre of the triangle, head-on (cos = -1 with |D| = 1), t = 1 + x.
HitBuffer frame() {
  HitBuffer hb;
  hb.width = 10;
  hb.height = 10;
  hb.pixels.resize(100);
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 10; ++x) {
      PixelHit& p = hb.at(x, y);
      p.dz = -1.0f;
      p.oz = 5.0f;
      if (x < 5) continue;
      p.t = 1.0f + x;
      p.u = 1.0f / 3;
      p.v = 1.0f / 3;
      p.cos = -1.0f;
      p.instance = 3;
      p.triangle = static_cast<std::uint32_t>(x + 10 * y);
    }
  }
  return hb;
}

TEST(CompareHits, IdenticalBuffers) {
  const HitBuffer a = frame();
  Rgb8Image diff;
  const CompareResult r = compare_hits(a, a, {}, &diff);
  EXPECT_TRUE(r.bit_identical);
  EXPECT_EQ(r.pixels, 100u);
  EXPECT_DOUBLE_EQ(r.same_triangle_pct, 100.0);
  EXPECT_EQ(r.mismatches.total(), 0u);
  EXPECT_EQ(r.t_compared, 50u);
  EXPECT_EQ(*r.t_rel_err_max, 0.0);
  EXPECT_EQ(*r.t_rel_err_median, 0.0);
  EXPECT_EQ(diff.width, 10);
  EXPECT_EQ(diff.rgb[0], 0);         // miss/miss: black
  EXPECT_EQ(diff.rgb[(5) * 3], 48);  // same hit, same t: grey
  const nlohmann::json j = compare_report_json(r);
  EXPECT_EQ(j["bit_identical"], true);
  EXPECT_EQ(j["pixels"], 100);
  EXPECT_EQ(j["same_triangle_pct"], 100.0);
  EXPECT_EQ(j["mismatches"]["total"], 0);
  EXPECT_TRUE(j["psnr_db"].is_null());
}

TEST(CompareHits, OneRayComponentDifferenceBreaksBitIdentity) {
  const HitBuffer a = frame();
  HitBuffer b = a;
  b.at(0, 0).dx = std::nextafter(0.0f, 1.0f);  // a miss pixel: only its ray differs
  const CompareResult r = compare_hits(a, b);
  EXPECT_FALSE(r.bit_identical);
  EXPECT_DOUBLE_EQ(r.same_triangle_pct, 100.0);
}

TEST(CompareHits, EachMismatchClassIsDetected) {
  const HitBuffer b = frame();
  HitBuffer a = b;
  // hit vs miss, deep inside the triangle.
  a.at(2, 0).t = 4.0f;
  a.at(2, 0).instance = 3;
  a.at(2, 0).triangle = 999;
  a.at(2, 0).u = a.at(2, 0).v = 0.3f;
  // hit vs miss, the hit 1e-4 from an edge.
  a.at(6, 0) = PixelHit{};
  b.at(6, 0);  // B hits there
  HitBuffer bb = b;
  bb.at(6, 0).u = 0.5f;
  bb.at(6, 0).v = 0.4999f;  // 1-u-v = 1e-4
  // edge tie: both hit, different triangles, A's u tiny.
  a.at(7, 1).triangle = 1234;
  a.at(7, 1).u = 5e-4f;
  // grazing: both hit, central barycentrics, |cos| = 0.005 of |D| = 1.
  a.at(8, 2).triangle = 555;
  a.at(8, 2).cos = 0.005f;
  // other: both hit, central, head-on.
  a.at(9, 3).triangle = 777;
  // t errors on same-triangle pixels: 1e-3 relative at (5,5), 1e-6 at (6,5).
  a.at(5, 5).t = bb.at(5, 5).t * (1.0f + 1e-3f);
  a.at(6, 5).t = bb.at(6, 5).t * (1.0f + 1e-6f);

  Rgb8Image diff;
  const CompareResult r = compare_hits(a, bb, {}, &diff);
  EXPECT_FALSE(r.bit_identical);
  EXPECT_EQ(r.mismatches.hit_vs_miss, 2u);
  EXPECT_EQ(r.mismatches.hit_vs_miss_near_edge, 1u);
  EXPECT_EQ(r.mismatches.edge_tie, 1u);
  EXPECT_EQ(r.mismatches.grazing, 1u);
  EXPECT_EQ(r.mismatches.other, 1u);
  EXPECT_EQ(r.same_triangle, 95u);
  EXPECT_DOUBLE_EQ(r.same_triangle_pct, 95.0);
  EXPECT_EQ(r.first_mismatch[static_cast<int>(MismatchClass::kEdgeTie)].x, 7);
  EXPECT_EQ(r.first_mismatch[static_cast<int>(MismatchClass::kEdgeTie)].y, 1);
  // 50 hit pixels in B, four of them mismatched (6,0), (7,1), (8,2), (9,3): 46 compared.
  EXPECT_EQ(r.t_compared, 46u);
  const double want_max = std::abs(double(a.at(5, 5).t) - bb.at(5, 5).t) / bb.at(5, 5).t;
  EXPECT_DOUBLE_EQ(*r.t_rel_err_max, want_max);
  EXPECT_NEAR(*r.t_rel_err_max, 1e-3, 1e-6);
  EXPECT_EQ(r.worst_t.x, 5);
  EXPECT_EQ(r.worst_t.y, 5);
  EXPECT_EQ(*r.t_rel_err_median, 0.0);  // 44 of 46 are exact
  // Colours: red hit/miss, yellow edge tie, cyan grazing, magenta other.
  auto px = [&](int x, int y) {
    const std::size_t p = (static_cast<std::size_t>(y) * 10 + x) * 3;
    return std::array<int, 3>{diff.rgb[p], diff.rgb[p + 1], diff.rgb[p + 2]};
  };
  EXPECT_EQ(px(2, 0), (std::array<int, 3>{255, 0, 0}));
  EXPECT_EQ(px(7, 1), (std::array<int, 3>{255, 255, 0}));
  EXPECT_EQ(px(8, 2), (std::array<int, 3>{0, 255, 255}));
  EXPECT_EQ(px(9, 3), (std::array<int, 3>{255, 0, 255}));
  EXPECT_GT(px(5, 5)[1], px(6, 5)[1]);  // larger t error, brighter green
  const nlohmann::json j = compare_report_json(r);
  EXPECT_EQ(j["mismatches"]["hit_vs_miss"], 2);
  EXPECT_EQ(j["mismatches"]["edge_tie"], 1);
  EXPECT_EQ(j["mismatches"]["grazing"], 1);
  EXPECT_EQ(j["mismatches"]["other"], 1);
  EXPECT_DOUBLE_EQ(j["t_rel_err_max"].get<double>(), want_max);
}

TEST(CompareHits, MedianOverSameTrianglePixels) {
  HitBuffer b = frame();
  HitBuffer a = b;
  // Relative errors 1e-2 on 30 of the 50 hits: the median is 1e-2-ish.
  int n = 0;
  for (auto& p : a.pixels) {
    if (p.hit() && n++ < 30) p.t = p.t * 1.01f;
  }
  const CompareResult r = compare_hits(a, b);
  EXPECT_NEAR(*r.t_rel_err_median, 0.01, 1e-6);
  EXPECT_NEAR(*r.t_rel_err_max, 0.01, 1e-6);
}

TEST(CompareHits, ThresholdsAreParameters) {
  PixelHit a, b;
  a.t = b.t = 1.0f;
  a.instance = b.instance = 0;
  a.triangle = 1;
  b.triangle = 2;
  a.u = b.u = 0.01f;
  a.v = b.v = 0.3f;
  a.cos = b.cos = 0.5f;
  a.dz = b.dz = 1.0f;
  EXPECT_EQ(classify_mismatch(a, b, {}), MismatchClass::kOther);
  EXPECT_EQ(classify_mismatch(a, b, {.bary_tolerance = 0.02, .grazing_cos = 1e-2}),
            MismatchClass::kEdgeTie);
  EXPECT_EQ(classify_mismatch(a, b, {.bary_tolerance = 1e-3, .grazing_cos = 0.6}),
            MismatchClass::kGrazing);
  // |cos| relative to |D|: D of length 100 makes cos = 0.5 a grazing 0.005.
  a.dz = 100.0f;
  EXPECT_EQ(classify_mismatch(a, b, {}), MismatchClass::kGrazing);
  b.triangle = 1;
  EXPECT_EQ(classify_mismatch(a, b, {}), MismatchClass::kNone);
}

FloatImage constant_image(int w, int h, std::uint8_t v) {
  Rgb8Image img;
  img.width = w;
  img.height = h;
  img.rgb.assign(static_cast<std::size_t>(w) * h * 3, v);
  return to_float_image(img);
}

TEST(CompareImages, KnownPsnr) {
  const FloatImage a = constant_image(10, 10, 100);
  // Identical.
  CompareResult r = compare_images(a, a);
  EXPECT_TRUE(r.bit_identical);
  EXPECT_TRUE(std::isinf(*r.psnr_db));
  EXPECT_EQ(*r.max_channel_diff, 0.0);
  // Every channel one level off: PSNR = 20 log10(255) = 48.1308 dB.
  r = compare_images(a, constant_image(10, 10, 101));
  EXPECT_FALSE(r.bit_identical);
  EXPECT_NEAR(*r.psnr_db, 48.1308036, 1e-6);
  EXPECT_EQ(*r.max_channel_diff, 1.0);
  EXPECT_EQ(r.differing_pixels, 100u);
  // One channel of one pixel off by 255 in 300 samples: PSNR = 10 log10(300) = 24.7712 dB.
  FloatImage b = a;
  b.data[3 * 42 + 1] = a.data[3 * 42 + 1] + 155.0f / 255.0f;  // 100 -> 255
  Rgb8Image diff;
  r = compare_images(constant_image(10, 10, 0), constant_image(10, 10, 0), &diff);
  EXPECT_EQ(diff.rgb, std::vector<std::uint8_t>(300, 0));
  FloatImage zero = constant_image(10, 10, 0);
  FloatImage one = zero;
  one.data[3 * 42 + 1] = 1.0f;
  r = compare_images(one, zero, &diff);
  EXPECT_NEAR(*r.psnr_db, 10.0 * std::log10(300.0), 1e-9);
  EXPECT_EQ(*r.max_channel_diff, 255.0);
  EXPECT_EQ(r.worst_pixel.x, 2);
  EXPECT_EQ(r.worst_pixel.y, 4);
  EXPECT_EQ(r.differing_pixels, 1u);
  EXPECT_EQ(diff.rgb[3 * 42], 255);  // the worst pixel is white-hot
  EXPECT_EQ(diff.rgb[0], 0);
  // psnr_rgb8 agrees.
  Rgb8Image x, y;
  x.width = y.width = 10;
  x.height = y.height = 10;
  x.rgb.assign(300, 0);
  y.rgb.assign(300, 0);
  y.rgb[3 * 42 + 1] = 255;
  EXPECT_NEAR(psnr_rgb8(x, y), 10.0 * std::log10(300.0), 1e-9);
}

TEST(CompareImages, FloatImagesUseUnitPeak) {
  FloatImage a;
  a.width = 2;
  a.height = 1;
  a.channels = 1;
  a.data = {0.5f, 0.5f};
  FloatImage b = a;
  b.data = {0.6f, 0.5f};
  const CompareResult r = compare_images(a, b);
  const double d = double(0.6f) - double(0.5f);
  EXPECT_NEAR(*r.psnr_db, 10.0 * std::log10(2.0 / (d * d)), 1e-9);
  EXPECT_DOUBLE_EQ(*r.max_channel_diff, d);
  EXPECT_FALSE(r.eight_bit);
}

TEST(CompareImages, SizeAndChannelMismatchAreErrors) {
  EXPECT_THROW(compare_images(constant_image(10, 10, 0), constant_image(10, 9, 0)),
               std::runtime_error);
  FloatImage g = constant_image(10, 10, 0);
  g.channels = 1;
  g.data.resize(100);
  try {
    compare_images(constant_image(10, 10, 0), g);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "channel counts differ: A has 3, B has 1");
  }
  HitBuffer a = frame(), b = frame();
  b.width = 5;
  b.height = 20;
  try {
    compare_hits(a, b);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "sizes differ: A is 10x10, B is 5x20");
  }
}

TEST(RunCompare, FilesReportAndDiff) {
  const fs::path d = temp_dir();
  const HitBuffer b = frame();
  HitBuffer a = b;
  a.at(9, 3).triangle = 777;
  write_hit_exr((d / "a.exr").string(), a);
  write_hit_exr((d / "b.exr").string(), b);
  CompareOptions o;
  o.a = (d / "a.exr").string();
  o.b = (d / "b.exr").string();
  o.report = (d / "out" / "cmp.json").string();
  o.diff = (d / "out" / "diff.png").string();
  EXPECT_EQ(run_compare(o), 0);
  std::ifstream f(o.report);
  const nlohmann::json j = nlohmann::json::parse(f);
  for (const char* k : {"pixels", "same_triangle_pct", "bit_identical", "t_rel_err_max",
                        "t_rel_err_median", "psnr_db", "max_channel_diff", "mismatches"}) {
    EXPECT_TRUE(j.contains(k)) << k;
  }
  EXPECT_EQ(j["pixels"], 100);
  EXPECT_DOUBLE_EQ(j["same_triangle_pct"].get<double>(), 99.0);
  EXPECT_EQ(j["mismatches"]["other"], 1);
  const Rgb8Image diff = read_rgb8(o.diff);
  EXPECT_EQ(diff.rgb[(3 * 10 + 9) * 3 + 2], 255);

  // Mixing an image with a hit EXR, a missing file: one-line errors.
  Rgb8Image img;
  img.width = 10;
  img.height = 10;
  img.rgb.assign(300, 0);
  write_rgb8((d / "img.png").string(), img);
  o.b = (d / "img.png").string();
  try {
    run_compare(o);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot compare a hit EXR with an image"),
              std::string::npos);
  }
  o.b = (d / "nope.exr").string();
  try {
    run_compare(o);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), o.b + ": no such file");
  }
}

}  // namespace
}  // namespace saarcor
