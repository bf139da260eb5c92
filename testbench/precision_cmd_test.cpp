// `saarcor precision`: the mantissa range argument, the plot drawn by our rasteriser, and a small
// study whose end points are known (Float<7,23> reproduces the float reference exactly).
#include "testbench/precision_cmd.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "testbench/image_io.h"
#include "testbench/testing.h"

namespace saarcor {
namespace {

namespace fs = std::filesystem;

using test_support::error_of;

TEST(PrecisionArgs, MantissaRange) {
  EXPECT_EQ(parse_mantissa_range("16"), (std::pair<int, int>{16, 16}));
  EXPECT_EQ(parse_mantissa_range("10..23"), (std::pair<int, int>{10, 23}));
  EXPECT_EQ(parse_mantissa_range("12..14"), (std::pair<int, int>{12, 14}));
  for (const char* bad : {"9..23", "10..24", "20..12", "abc", "10..", "..12", "10-12", ""}) {
    EXPECT_EQ(error_of([&] {
                parse_mantissa_range(bad);
              }).rfind(std::string("bad --mantissa '") + bad + "'", 0),
              0u)
        << bad;
  }
}

std::array<int, 3> colour_at(const Rgb8Image& img, PixelCoord p) {
  const std::size_t i = (static_cast<std::size_t>(p.y) * img.width + p.x) * 3;
  return {img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]};
}

TEST(PrecisionPlot, MarkersSitWhereTheValuesAre) {
  std::vector<PrecisionRow> rows;
  const double same[] = {97.0, 98.5, 99.5, 100.0};
  const double psnr[] = {30.0, 42.0, 55.0, std::numeric_limits<double>::infinity()};
  for (int i = 0; i < 4; ++i) {
    PrecisionRow r;
    r.mantissa = 14 + i;
    r.same_triangle_pct = same[i];
    r.psnr_db = psnr[i];
    rows.push_back(r);
  }
  const PrecisionPlot plot = plot_precision(rows, "test");
  ASSERT_EQ(plot.image.width, 720);
  ASSERT_EQ(plot.image.height, 440);
  ASSERT_EQ(plot.same_points.size(), 4u);
  const std::array<int, 3> blue{kSameColour[0], kSameColour[1], kSameColour[2]};
  const std::array<int, 3> red{kPsnrColour[0], kPsnrColour[1], kPsnrColour[2]};
  for (int i = 0; i < 4; ++i) {
    // Markers: blue drawn over red where they meet; the PSNR marker of m=14 is far from the
    // share marker, so both colours are checked where they do not overlap.
    EXPECT_EQ(colour_at(plot.image, plot.same_points[i]), blue) << i;
    if (i > 0) {
      EXPECT_LT(plot.same_points[i].y, plot.same_points[i - 1].y);  // larger share, higher
      EXPECT_LT(plot.psnr_points[i].y, plot.psnr_points[i - 1].y);  // larger PSNR, higher
      EXPECT_GT(plot.same_points[i].x, plot.same_points[i - 1].x);  // more bits, further right
    }
  }
  EXPECT_EQ(colour_at(plot.image, plot.psnr_points[0]), red);
  // 100 % sits on the top of the plot area; infinite PSNR at the top of the right axis.
  EXPECT_EQ(plot.same_points[3].y, plot.psnr_points[3].y);
  // The corner is background, the left axis is black.
  EXPECT_EQ(colour_at(plot.image, {0, plot.image.height - 1}), (std::array<int, 3>{255, 255, 255}));
  EXPECT_EQ(colour_at(plot.image, {80, 200}), (std::array<int, 3>{0, 0, 0}));
  EXPECT_THROW(plot_precision({}, "empty"), std::runtime_error);
}

TEST(PrecisionStudy, EndPointsAndFiles) {
  RenderSettings s;
  s.res = {32, 24};
  const std::vector<PrecisionRow> rows = run_precision_study("builtin:cube", s, 22, 23);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].mantissa, 22);
  // Float<7,23> has binary32's precision and the same op order: the golden reference's binary64
  // step into the cube's instance leaves only the last bits of t (bit-identity with the binary32
  // step is RenderModels.Mantissa23ReproducesTheFloatReferenceBitForBit).
  EXPECT_DOUBLE_EQ(rows[1].same_triangle_pct, 100.0);
  EXPECT_TRUE(std::isinf(rows[1].psnr_db));
  EXPECT_LT(*rows[1].t_rel_err_max, 1e-6);
  EXPECT_LT(*rows[1].t_rel_err_max, *rows[0].t_rel_err_max);
  // One bit fewer: t differs somewhere, but stays within a few 2^-23 units.
  EXPECT_GT(*rows[0].t_rel_err_max, 0.0);
  EXPECT_LT(*rows[0].t_rel_err_median, 1e-5);
  const std::string table = precision_table(rows);
  EXPECT_NE(table.find("  23      100.0000%"), std::string::npos) << table;

  const fs::path d = fs::temp_directory_path() / ("saarcor_precision_" + std::to_string(getpid()));
  PrecisionOptions o;
  o.scene = "builtin:cube";
  o.mantissa = "16";
  o.res = "16x12";
  o.out = (d / "p").string();
  ASSERT_EQ(run_precision(o), 0);
  EXPECT_EQ(read_rgb8(o.out + ".png").width, 720);
  std::ifstream f(o.out + ".json");
  const nlohmann::json j = nlohmann::json::parse(f);
  ASSERT_EQ(j["rows"].size(), 1u);
  EXPECT_EQ(j["rows"][0]["mantissa"], 16);
  EXPECT_EQ(j["rows"][0]["format"], "e7m16");
  EXPECT_GE(j["rows"][0]["same_triangle_pct"].get<double>(), 90.0);
}

TEST(PrecisionStudy, BadInput) {
  PrecisionOptions o;
  o.scene = "builtin:nosuchscene";
  o.mantissa = "16";
  o.res = "8x8";
  EXPECT_NE(error_of([&] { run_precision(o); }).find("nosuchscene"), std::string::npos);
  o.scene = "builtin:cube";
  o.res = "8";
  EXPECT_EQ(error_of([&] { run_precision(o); }).rfind("bad --res '8'", 0), 0u);
}

}  // namespace
}  // namespace saarcor
