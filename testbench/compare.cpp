// `saarcor compare`: hit-record and image metrics between two models (docs/compare.md; the
// precision study of functional fp24 against the float reference). Classes: docs/compare.md.
#include "testbench/compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <vector>

#include "testbench/hit_exr.h"
#include "testbench/report.h"

namespace saarcor {
namespace {

bool same_triangle(const PixelHit& a, const PixelHit& b) {
  return a.instance == b.instance && a.triangle == b.triangle;
}

bool bits_equal(float a, float b) {
  std::uint32_t x, y;
  std::memcpy(&x, &a, 4);
  std::memcpy(&y, &b, 4);
  return x == y;
}

bool records_bit_identical(const PixelHit& a, const PixelHit& b) {
  return bits_equal(a.t, b.t) && bits_equal(a.u, b.u) && bits_equal(a.v, b.v) &&
         bits_equal(a.cos, b.cos) && a.instance == b.instance && a.triangle == b.triangle &&
         bits_equal(a.ox, b.ox) && bits_equal(a.oy, b.oy) && bits_equal(a.oz, b.oz) &&
         bits_equal(a.dx, b.dx) && bits_equal(a.dy, b.dy) && bits_equal(a.dz, b.dz);
}

// Distance to the nearest edge in barycentric terms (the third coordinate is 1 - u - v).
double edge_distance(const PixelHit& h) {
  const double u = h.u, v = h.v;
  return std::min({u, v, 1.0 - u - v});
}

double cosine(const PixelHit& h) {
  const double len = std::sqrt(double(h.dx) * h.dx + double(h.dy) * h.dy + double(h.dz) * h.dz);
  if (!(len > 0.0)) return std::abs(double(h.cos));
  return std::abs(double(h.cos)) / len;
}

double median_of(std::vector<double> v) {
  const std::size_t n = v.size();
  std::nth_element(v.begin(), v.begin() + n / 2, v.end());
  const double hi = v[n / 2];
  if (n % 2 == 1) return hi;
  const double lo = *std::max_element(v.begin(), v.begin() + n / 2);
  return 0.5 * (lo + hi);
}

struct Colour {
  std::uint8_t r, g, b;
};

void put(Rgb8Image& img, std::size_t p, Colour c) {
  img.rgb[p * 3 + 0] = c.r;
  img.rgb[p * 3 + 1] = c.g;
  img.rgb[p * 3 + 2] = c.b;
}

// Black -> blue -> red -> yellow -> white for s in [0, 1].
Colour heat(double s) {
  s = std::clamp(s, 0.0, 1.0);
  const double k[5][3] = {{0, 0, 0}, {0, 0, 255}, {255, 0, 0}, {255, 255, 0}, {255, 255, 255}};
  const double f = s * 4.0;
  const int i = std::min(3, static_cast<int>(f));
  const double w = f - i;
  auto mix = [&](int c) {
    return static_cast<std::uint8_t>(std::lround(k[i][c] * (1.0 - w) + k[i + 1][c] * w));
  };
  return {mix(0), mix(1), mix(2)};
}

void check_same_size(int wa, int ha, int wb, int hb) {
  if (wa != wb || ha != hb) {
    throw std::runtime_error("sizes differ: A is " + std::to_string(wa) + "x" + std::to_string(ha) +
                             ", B is " + std::to_string(wb) + "x" + std::to_string(hb));
  }
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// Both runs hit the same triangle: the relative error of t, B taken as the reference.
void count_t_error(const PixelHit& ha, const PixelHit& hb, PixelRef at, std::size_t p,
                   CompareResult& r, std::vector<double>& t_err, double& worst, Rgb8Image* diff) {
  const double tb = hb.t, ta = ha.t;
  double e = ta == tb ? 0.0 : std::abs(ta - tb) / std::abs(tb);
  if (std::isnan(e)) e = std::numeric_limits<double>::infinity();
  t_err.push_back(e);
  if (e > worst) {
    worst = e;
    r.worst_t = at;
  }
  if (diff) {
    // Same triangle: grey when t agrees bit for bit, else green brighter with the error.
    if (e == 0.0) {
      put(*diff, p, {48, 48, 48});
    } else {
      const double s = std::clamp((std::log10(e) + 9.0) / 7.0, 0.0, 1.0);
      put(*diff, p, {0, static_cast<std::uint8_t>(80 + std::lround(175 * s)), 0});
    }
  }
}

void count_mismatch(MismatchClass c, const PixelHit& ha, const PixelHit& hb,
                    const CompareParams& params, PixelRef at, std::size_t p, CompareResult& r,
                    Rgb8Image* diff) {
  PixelRef& first = r.first_mismatch[static_cast<int>(c)];
  if (!first.valid()) first = at;
  switch (c) {
    case MismatchClass::kHitVsMiss: {
      ++r.mismatches.hit_vs_miss;
      const PixelHit& h = ha.hit() ? ha : hb;
      if (edge_distance(h) < params.bary_tolerance) ++r.mismatches.hit_vs_miss_near_edge;
      if (diff) put(*diff, p, {255, 0, 0});
      break;
    }
    case MismatchClass::kEdgeTie:
      ++r.mismatches.edge_tie;
      if (diff) put(*diff, p, {255, 255, 0});
      break;
    case MismatchClass::kGrazing:
      ++r.mismatches.grazing;
      if (diff) put(*diff, p, {0, 255, 255});
      break;
    default:
      ++r.mismatches.other;
      if (diff) put(*diff, p, {255, 0, 255});
      break;
  }
}

}  // namespace

const char* mismatch_class_name(MismatchClass c) {
  switch (c) {
    case MismatchClass::kNone:
      return "none";
    case MismatchClass::kHitVsMiss:
      return "hit_vs_miss";
    case MismatchClass::kEdgeTie:
      return "edge_tie";
    case MismatchClass::kGrazing:
      return "grazing";
    case MismatchClass::kOther:
      return "other";
  }
  return "?";
}

MismatchClass classify_mismatch(const PixelHit& a, const PixelHit& b, const CompareParams& p) {
  if (same_triangle(a, b)) return MismatchClass::kNone;
  if (a.hit() != b.hit()) return MismatchClass::kHitVsMiss;
  if (edge_distance(a) < p.bary_tolerance || edge_distance(b) < p.bary_tolerance) {
    return MismatchClass::kEdgeTie;
  }
  if (cosine(a) < p.grazing_cos || cosine(b) < p.grazing_cos) return MismatchClass::kGrazing;
  return MismatchClass::kOther;
}

CompareResult compare_hits(const HitBuffer& a, const HitBuffer& b, const CompareParams& params,
                           Rgb8Image* diff) {
  check_same_size(a.width, a.height, b.width, b.height);
  CompareResult r;
  r.hit_records = true;
  r.width = a.width;
  r.height = a.height;
  r.pixels = a.pixels.size();
  r.bit_identical = true;
  if (diff) {
    diff->width = a.width;
    diff->height = a.height;
    diff->rgb.assign(a.pixels.size() * 3, 0);
  }
  std::vector<double> t_err;
  double worst = -1.0;
  for (std::size_t p = 0; p < a.pixels.size(); ++p) {
    const PixelHit& ha = a.pixels[p];
    const PixelHit& hb = b.pixels[p];
    const PixelRef at{static_cast<int>(p % a.width), static_cast<int>(p / a.width)};
    if (!records_bit_identical(ha, hb)) r.bit_identical = false;
    const MismatchClass c = classify_mismatch(ha, hb, params);
    if (c == MismatchClass::kNone) {
      ++r.same_triangle;
      if (ha.hit()) count_t_error(ha, hb, at, p, r, t_err, worst, diff);
      continue;
    }
    count_mismatch(c, ha, hb, params, at, p, r, diff);
  }
  r.same_triangle_pct = r.pixels ? 100.0 * double(r.same_triangle) / double(r.pixels) : 100.0;
  r.t_compared = t_err.size();
  if (!t_err.empty()) {
    r.t_rel_err_max = worst;
    r.t_rel_err_median = median_of(std::move(t_err));
  }
  return r;
}

CompareResult compare_images(const FloatImage& a, const FloatImage& b, Rgb8Image* diff) {
  check_same_size(a.width, a.height, b.width, b.height);
  if (a.channels != b.channels) {
    throw std::runtime_error("channel counts differ: A has " + std::to_string(a.channels) +
                             ", B has " + std::to_string(b.channels));
  }
  CompareResult r;
  r.hit_records = false;
  r.width = a.width;
  r.height = a.height;
  r.channels = a.channels;
  r.pixels = static_cast<std::uint64_t>(a.width) * a.height;
  r.eight_bit = a.eight_bit && b.eight_bit;
  r.bit_identical = true;
  const double scale = r.eight_bit ? 255.0 : 1.0;
  double sq = 0.0, max_diff = 0.0;
  std::vector<double> pixel_diff(r.pixels, 0.0);
  for (std::size_t p = 0; p < r.pixels; ++p) {
    bool differs = false;
    for (int c = 0; c < a.channels; ++c) {
      const float va = a.data[p * a.channels + c], vb = b.data[p * b.channels + c];
      if (!bits_equal(va, vb)) {
        differs = true;
        r.bit_identical = false;
      }
      // 8-bit values go back to integer levels so the figures are exact.
      double d = r.eight_bit
                     ? double(std::lround(double(va) * 255.0) - std::lround(double(vb) * 255.0))
                     : double(va) - double(vb);
      if (std::isnan(d)) d = std::numeric_limits<double>::infinity();
      d = std::abs(d);
      sq += (d / scale) * (d / scale);
      pixel_diff[p] = std::max(pixel_diff[p], d);
      if (d > max_diff) {
        max_diff = d;
        r.worst_pixel = {static_cast<int>(p % a.width), static_cast<int>(p / a.width)};
      }
    }
    if (differs) ++r.differing_pixels;
  }
  const double mse = sq / (double(r.pixels) * a.channels);
  r.psnr_db = mse == 0.0 ? std::numeric_limits<double>::infinity() : 10.0 * std::log10(1.0 / mse);
  r.max_channel_diff = max_diff;
  if (diff) {
    diff->width = a.width;
    diff->height = a.height;
    diff->rgb.assign(r.pixels * 3, 0);
    if (max_diff > 0.0 && std::isfinite(max_diff)) {
      for (std::size_t p = 0; p < r.pixels; ++p) {
        if (pixel_diff[p] > 0.0) put(*diff, p, heat(0.1 + 0.9 * pixel_diff[p] / max_diff));
      }
    } else if (max_diff > 0.0) {
      for (std::size_t p = 0; p < r.pixels; ++p) {
        if (pixel_diff[p] > 0.0) put(*diff, p, {255, 255, 255});
      }
    }
  }
  return r;
}

double psnr_rgb8(const Rgb8Image& a, const Rgb8Image& b) {
  check_same_size(a.width, a.height, b.width, b.height);
  double sq = 0.0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    const double d = double(a.rgb[i]) - double(b.rgb[i]);
    sq += d * d;
  }
  if (sq == 0.0) return std::numeric_limits<double>::infinity();
  const double mse = sq / double(a.rgb.size());
  return 10.0 * std::log10(255.0 * 255.0 / mse);
}

std::string compare_summary(const CompareResult& r) {
  std::string s;
  auto line = [&](const std::string& k, const std::string& v) { s += "  " + k + v + "\n"; };
  auto pix = [](PixelRef p) { return std::to_string(p.x) + "," + std::to_string(p.y); };
  line("kind:             ", r.hit_records ? "hit records" : "images");
  line("pixels:           ",
       std::to_string(r.width) + "x" + std::to_string(r.height) + " = " + std::to_string(r.pixels));
  line("bit identical:    ", r.bit_identical ? "yes" : "no");
  if (r.hit_records) {
    line("same triangle:    ",
         fmt("%.4f%%", r.same_triangle_pct) + " (" + std::to_string(r.same_triangle) + " pixels)");
    const auto& m = r.mismatches;
    line("mismatches:       ",
         std::to_string(m.total()) + " (hit vs miss " + std::to_string(m.hit_vs_miss) + " [" +
             std::to_string(m.hit_vs_miss_near_edge) + " near an edge], edge tie " +
             std::to_string(m.edge_tie) + ", grazing " + std::to_string(m.grazing) + ", other " +
             std::to_string(m.other) + ")");
    for (int c = 1; c < 5; ++c) {
      if (r.first_mismatch[c].valid()) {
        line("  first " + std::string(mismatch_class_name(static_cast<MismatchClass>(c))) + ": ",
             "--pixel " + pix(r.first_mismatch[c]));
      }
    }
    if (r.t_rel_err_max) {
      line("t rel. error:     ",
           "max " + fmt("%.3g", *r.t_rel_err_max) +
               (*r.t_rel_err_max > 0 ? " (--pixel " + pix(r.worst_t) + ")" : std::string()) +
               ", median " + fmt("%.3g", *r.t_rel_err_median) + " over " +
               std::to_string(r.t_compared) + " pixels");
    } else {
      line("t rel. error:     ", "no pixel hits the same triangle in both");
    }
  } else {
    line("differing pixels: ", std::to_string(r.differing_pixels));
    line("PSNR:             ",
         std::isfinite(*r.psnr_db) ? fmt("%.2f dB", *r.psnr_db) : std::string("inf (identical)"));
    line("max channel diff: ",
         fmt("%.6g", *r.max_channel_diff) + (r.eight_bit ? " (8-bit levels)" : "") +
             (r.worst_pixel.valid() ? " at --pixel " + pix(r.worst_pixel) : ""));
  }
  return s;
}

int run_compare(const CompareOptions& opts) {
  require_readable_file(opts.a);
  require_readable_file(opts.b);
  const bool ha = is_hit_exr(opts.a);
  const bool hb = is_hit_exr(opts.b);
  if (ha != hb) {
    throw std::runtime_error("cannot compare a hit EXR with an image: " + (ha ? opts.a : opts.b) +
                             " holds hit records, " + (ha ? opts.b : opts.a) + " is an image");
  }
  Rgb8Image diff;
  Rgb8Image* diff_ptr = opts.diff.empty() ? nullptr : &diff;
  CompareResult r;
  try {
    if (ha) {
      r = compare_hits(read_hit_exr(opts.a), read_hit_exr(opts.b), opts.params, diff_ptr);
    } else {
      r = compare_images(read_float_image(opts.a), read_float_image(opts.b), diff_ptr);
    }
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    // Size and channel errors do not know the file names: add them.
    if (what.rfind("sizes differ", 0) == 0 || what.rfind("channel counts differ", 0) == 0) {
      throw std::runtime_error(what + " (A = " + opts.a + ", B = " + opts.b + ")");
    }
    throw;
  }
  std::printf("saarcor compare: A = %s, B = %s (reference)\n%s", opts.a.c_str(), opts.b.c_str(),
              compare_summary(r).c_str());
  if (diff_ptr) {
    write_rgb8(opts.diff, diff);
    std::printf("  difference image: %s\n", opts.diff.c_str());
  }
  if (!opts.report.empty()) {
    write_text_file(opts.report, compare_report_json(r).dump(2) + "\n");
    std::printf("  report:           %s\n", opts.report.c_str());
  }
  return 0;
}

}  // namespace saarcor
