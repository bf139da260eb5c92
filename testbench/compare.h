// Golden-model comparison (docs/compare.md): hit records of two models, or two images, and
// the metrics `saarcor compare` prints and writes as JSON (classes and thresholds in
// docs/compare.md). B is the reference: relative errors are taken against B.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "testbench/hit_buffer.h"
#include "testbench/image_io.h"

namespace saarcor {

struct CompareParams {
  // A mismatch is an edge-or-vertex tie when min(u, v, 1-u-v) of either record is below this.
  double bary_tolerance = 1e-3;
  // A mismatch is at a grazing angle when |cos| / |D| of either record is below this (cos = D'z
  // = D.N with N the unit normal; exact for instances without scaling).
  double grazing_cos = 1e-2;
};

struct MismatchCounts {
  std::uint64_t hit_vs_miss = 0;
  std::uint64_t hit_vs_miss_near_edge = 0;  // of hit_vs_miss: the hit lies within the tolerance
  std::uint64_t edge_tie = 0;
  std::uint64_t grazing = 0;
  std::uint64_t other = 0;
  std::uint64_t total() const { return hit_vs_miss + edge_tie + grazing + other; }
};

enum class MismatchClass { kNone, kHitVsMiss, kEdgeTie, kGrazing, kOther };
const char* mismatch_class_name(MismatchClass c);

struct PixelRef {
  int x = -1;
  int y = -1;
  bool valid() const { return x >= 0; }
};

struct CompareResult {
  bool hit_records = false;  // true: two hit EXRs; false: two images
  int width = 0;
  int height = 0;
  std::uint64_t pixels = 0;
  bool bit_identical = false;
  // Hit records.
  std::uint64_t same_triangle = 0;  // pixels whose (instance, triangle) agree (both misses count)
  double same_triangle_pct = 0.0;
  MismatchCounts mismatches;
  std::uint64_t t_compared = 0;  // pixels where both hit the same triangle
  std::optional<double> t_rel_err_max;
  std::optional<double> t_rel_err_median;
  PixelRef worst_t;            // pixel of the largest relative t error
  PixelRef first_mismatch[5];  // first pixel (row-major) of each MismatchClass
  // Images.
  int channels = 0;
  bool eight_bit = false;                  // both 8-bit: max_channel_diff is in levels 0..255
  std::uint64_t differing_pixels = 0;      // pixels with any channel different
  std::optional<double> psnr_db;           // empty for hit records; +inf when identical
  std::optional<double> max_channel_diff;  // empty for hit records
  PixelRef worst_pixel;                    // pixel of the largest channel difference
};

// Classifies one pixel (kNone when the two records hit the same triangle or both miss).
MismatchClass classify_mismatch(const PixelHit& a, const PixelHit& b, const CompareParams& p);

// `diff`, when given, receives the false-colour difference image (docs/compare.md).
CompareResult compare_hits(const HitBuffer& a, const HitBuffer& b, const CompareParams& params = {},
                           Rgb8Image* diff = nullptr);
CompareResult compare_images(const FloatImage& a, const FloatImage& b, Rgb8Image* diff = nullptr);

// PSNR in dB of two 8-bit images over all channels (peak 255); +inf when identical.
double psnr_rgb8(const Rgb8Image& a, const Rgb8Image& b);

// The JSON report is testbench/report.h's compare_report_json.
// The lines `saarcor compare` prints.
std::string compare_summary(const CompareResult& r);

struct CompareOptions {
  std::string a;
  std::string b;
  std::string report;  // JSON file, optional
  std::string diff;    // false-colour PNG, optional
  CompareParams params;
};

// Loads A and B (both hit EXRs or both images), compares, prints, writes the outputs asked for.
// Returns 0; throws std::runtime_error with one line on bad input.
int run_compare(const CompareOptions& opts);

}  // namespace saarcor
