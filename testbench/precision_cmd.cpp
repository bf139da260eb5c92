// `saarcor precision`: Float<7, m> against the float reference for a range of m, as a table, a
// JSON file and a PNG plot drawn by a small rasteriser of our own (docs/compare.md).
#include "testbench/precision_cmd.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include "host/tree_settings.h"
#include "testbench/heartbeat.h"
#include "testbench/image_io.h"
#include "testbench/report.h"

namespace saarcor {
namespace {

bool parse_uint(const std::string& s, int& out) {
  if (s.empty() || s.size() > 4) return false;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
  }
  out = std::stoi(s);
  return true;
}

// ---- a tiny rasteriser: lines, rectangles, 5x7 text ---------------------------------------------

struct Rgb {
  std::uint8_t r, g, b;
};

// 5x7 glyphs, one string of 35 bits per character (rows top to bottom, '#' = ink).
struct Glyph {
  char c;
  const char* rows;
};
constexpr Glyph kFont[] = {
    {'0', ".###.#...##..###.#.###..##...#.###."}, {'1', "..#...##....#....#....#....#...###."},
    {'2', ".###.#...#....#...#...#...#...#####"}, {'3', "#####...#...#.....#.....##...#.###."},
    {'4', "...#...##..#.#.#..#.#####...#....#."}, {'5', "######....####.....#....##...#.###."},
    {'6', "..##..#...#....####.#...##...#.###."}, {'7', "#####....#...#...#...#....#....#..."},
    {'8', ".###.#...##...#.###.#...##...#.###."}, {'9', ".###.#...##...#.####....#...#..##.."},
    {'A', ".###.#...##...##...#######...##...#"}, {'B', "####.#...##...#####.#...##...#####."},
    {'C', ".###.#...##....#....#....#...#.###."}, {'D', "###..#..#.#...##...##...##..#.###.."},
    {'E', "######....#....####.#....#....#####"}, {'F', "######....#....####.#....#....#...."},
    {'G', ".###.#...##....#.####...##...#.####"}, {'H', "#...##...##...#######...##...##...#"},
    {'I', ".###...#....#....#....#....#...###."}, {'J', "..###...#....#....#....#.#..#..##.."},
    {'K', "#...##..#.#.#..##...#.#..#..#.#...#"}, {'L', "#....#....#....#....#....#....#####"},
    {'M', "#...###.###.#.##.#.##...##...##...#"}, {'N', "#...##...###..##.#.##..###...##...#"},
    {'O', ".###.#...##...##...##...##...#.###."}, {'P', "####.#...##...#####.#....#....#...."},
    {'Q', ".###.#...##...##...##.#.##..#..##.#"}, {'R', "####.#...##...#####.#.#..#..#.#...#"},
    {'S', ".#####....#.....###.....#....#####."}, {'T', "#####..#....#....#....#....#....#.."},
    {'U', "#...##...##...##...##...##...#.###."}, {'V', "#...##...##...##...##...#.#.#...#.."},
    {'W', "#...##...##...##.#.##.#.##.#.#.#.#."}, {'X', "#...##...#.#.#...#...#.#.#...##...#"},
    {'Y', "#...##...##...#.#.#...#....#....#.."}, {'Z', "#####....#...#...#...#...#....#####"},
    {'%', "##...##..#...#...#...#...#..##...##"}, {'.', "..........................##...##.."},
    {'-', "...............#####..............."}, {':', "......##...##........##...##......."},
    {'(', "...#...#...#....#....#.....#.....#."}, {')', ".#.....#.....#....#....#...#...#..."},
    {',', ".....................##....#...#..."}, {'/', ".........#...#...#...#...#........."},
    {'=', "..........#####.....#####.........."}, {'>', ".#.....#.....#.....#...#...#...#..."},
    {'<', "...#...#...#...#.....#.....#.....#."}, {'+', ".......#....#..#####..#....#......."},
    {' ', "..................................."},
};

const char* glyph_rows(char c) {
  if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
  for (const Glyph& g : kFont) {
    if (g.c == c) return g.rows;
  }
  return nullptr;
}

class Canvas {
 public:
  Canvas(int w, int h, Rgb bg) {
    img_.width = w;
    img_.height = h;
    img_.rgb.resize(static_cast<std::size_t>(w) * h * 3);
    for (std::size_t p = 0; p < static_cast<std::size_t>(w) * h; ++p)
      set_index(p, bg);
  }
  void pixel(int x, int y, Rgb c) {
    if (x < 0 || y < 0 || x >= img_.width || y >= img_.height) return;
    set_index(static_cast<std::size_t>(y) * img_.width + x, c);
  }
  void rect(int x0, int y0, int x1, int y1, Rgb c) {
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x)
        pixel(x, y, c);
    }
  }
  // Bresenham with a square brush of `width` pixels; dash > 0 draws dash on, dash off.
  void line(int x0, int y0, int x1, int y1, Rgb c, int width = 1, int dash = 0) {
    const int dx = std::abs(x1 - x0), sx = x0 < x1 ? 1 : -1;
    const int dy = -std::abs(y1 - y0), sy = y0 < y1 ? 1 : -1;
    int err = dx + dy, step = 0;
    while (true) {
      if (dash == 0 || (step / dash) % 2 == 0) rect(x0, y0, x0 + width - 1, y0 + width - 1, c);
      ++step;
      if (x0 == x1 && y0 == y1) break;
      const int e2 = 2 * err;
      if (e2 >= dy) {
        err += dy;
        x0 += sx;
      }
      if (e2 <= dx) {
        err += dx;
        y0 += sy;
      }
    }
  }
  // Text with glyphs scaled by `scale`; returns the width drawn.
  int text(int x, int y, const std::string& s, Rgb c, int scale = 2) {
    int cx = x;
    for (char ch : s) {
      const char* rows = glyph_rows(ch);
      if (rows) {
        for (int r = 0; r < 7; ++r) {
          for (int col = 0; col < 5; ++col) {
            if (rows[r * 5 + col] == '#') {
              rect(cx + col * scale, y + r * scale, cx + col * scale + scale - 1,
                   y + r * scale + scale - 1, c);
            }
          }
        }
      }
      cx += 6 * scale;
    }
    return cx - x;
  }
  static int text_width(const std::string& s, int scale = 2) {
    return static_cast<int>(s.size()) * 6 * scale;
  }
  Rgb8Image take() { return std::move(img_); }

 private:
  void set_index(std::size_t p, Rgb c) {
    img_.rgb[p * 3] = c.r;
    img_.rgb[p * 3 + 1] = c.g;
    img_.rgb[p * 3 + 2] = c.b;
  }
  Rgb8Image img_;
};

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

}  // namespace

std::pair<int, int> parse_mantissa_range(const std::string& text) {
  const auto dots = text.find("..");
  int lo = 0, hi = 0;
  const bool ok = dots == std::string::npos ? parse_uint(text, lo) && (hi = lo, true)
                                            : parse_uint(text.substr(0, dots), lo) &&
                                                  parse_uint(text.substr(dots + 2), hi);
  if (!ok) {
    throw std::runtime_error("bad --mantissa '" + text + "': expected M or A..B, e.g. 10..23");
  }
  if (lo < kMinMantissa || hi > kMaxMantissa || lo > hi) {
    throw std::runtime_error("bad --mantissa '" + text + "': mantissa bits must lie in " +
                             std::to_string(kMinMantissa) + ".." + std::to_string(kMaxMantissa) +
                             " with A <= B");
  }
  return {lo, hi};
}

std::vector<PrecisionRow> run_precision_study(const std::string& scene,
                                              const RenderSettings& settings, int lo, int hi,
                                              bool heartbeat) {
  if (lo < kMinMantissa || hi > kMaxMantissa || lo > hi) {
    throw std::runtime_error("bad mantissa range " + std::to_string(lo) + ".." +
                             std::to_string(hi));
  }
  // The float reference reads the image's trees and binary64 matrices; its hits do not depend on
  // the image format (split planes are exact for the stored value), so one reference serves all m.
  PreparedScene prep = prepare_scene(scene, settings, ff::kFp24);
  progress("rendering the float reference");
  const FrameResult ref = render_model(parse_model("float"), prep, settings);
  // One heartbeat for the study: formats done / total (the frames' own stay quiet under it).
  Heartbeat beat("precision", heartbeat && heartbeat_enabled());
  RenderSettings quiet = settings;
  quiet.heartbeat = false;
  const int formats = hi - lo + 1;
  const FloatImage ref_image = to_float_image(ref.image);
  std::vector<PrecisionRow> rows;
  for (int m = lo; m <= hi; ++m) {
    const ff::Format format{7, m};
    if (!(prep.built.params.format == format)) build_prepared_image(prep, settings, format);
    beat.beat("formats " + std::to_string(m - lo) + " / " + std::to_string(formats) +
              ", rendering Float<7," + std::to_string(m) + ">");
    ModelSpec model;
    model.kind = ModelKind::kFunctional;
    model.mantissa = m;
    model.name = ff::format_name(format);
    const FrameResult f = render_model(model, prep, quiet);
    const CompareResult hits = compare_hits(f.hits, ref.hits);
    const CompareResult img = compare_images(to_float_image(f.image), ref_image);
    PrecisionRow row;
    row.mantissa = m;
    row.same_triangle_pct = hits.same_triangle_pct;
    row.psnr_db = *img.psnr_db;
    row.t_rel_err_median = hits.t_rel_err_median;
    row.t_rel_err_max = hits.t_rel_err_max;
    row.mismatches = hits.mismatches;
    row.seconds = f.seconds;
    rows.push_back(row);
  }
  beat.finish("formats " + std::to_string(formats) + " / " + std::to_string(formats));
  return rows;
}

std::string precision_table(const std::vector<PrecisionRow>& rows) {
  std::string s =
      "   m  same triangle      PSNR   t rel err median       max   mismatches: hit/miss  edge  "
      "grazing  other\n";
  for (const PrecisionRow& r : rows) {
    char buf[256];
    std::snprintf(
        buf, sizeof buf, "  %2d  %12.4f%%  %8s  %16s  %8s   %19llu  %4llu  %7llu  %5llu%s\n",
        r.mantissa, r.same_triangle_pct,
        std::isfinite(r.psnr_db) ? fmt("%.2f", r.psnr_db).c_str() : "inf",
        r.t_rel_err_median ? fmt("%.3g", *r.t_rel_err_median).c_str() : "-",
        r.t_rel_err_max ? fmt("%.3g", *r.t_rel_err_max).c_str() : "-",
        static_cast<unsigned long long>(r.mismatches.hit_vs_miss),
        static_cast<unsigned long long>(r.mismatches.edge_tie),
        static_cast<unsigned long long>(r.mismatches.grazing),
        static_cast<unsigned long long>(r.mismatches.other), r.mantissa == 16 ? "   <- fp24" : "");
    s += buf;
  }
  return s;
}

namespace {

constexpr int kW = 720, kH = 440;
constexpr int kLeft = 80, kRight = kW - 80, kTop = 60, kBottom = kH - 70;
const Rgb kWhite{255, 255, 255}, kBlack{0, 0, 0}, kGrey{170, 170, 170};
const Rgb kBlue{kSameColour[0], kSameColour[1], kSameColour[2]};
const Rgb kRed{kPsnrColour[0], kPsnrColour[1], kPsnrColour[2]};

// Ranges. x: the mantissas (padded when there is one). Left: share, from a round floor below
// the smallest value (and below the 99 % guide) to 100. Right: PSNR from 0 to a round ceiling;
// identical images (infinite PSNR) are drawn at the top and labelled.
struct PlotAxes {
  int mlo = 0, mhi = 0;
  double sstep = 0.1, slo = 0.0;
  double pstep = 20.0, phi = 0.0;
  bool any_inf = false;

  int xmap(double m) const {
    return kLeft + static_cast<int>(std::lround((m - mlo) / (mhi - mlo) * (kRight - kLeft)));
  }
  int ys(double v) const {
    return kBottom - static_cast<int>(std::lround((v - slo) / (100.0 - slo) * (kBottom - kTop)));
  }
  int yp(double v) const {
    if (!std::isfinite(v)) v = phi;
    v = std::clamp(v, 0.0, phi);
    return kBottom - static_cast<int>(std::lround(v / phi * (kBottom - kTop)));
  }
};

PlotAxes plot_axes(const std::vector<PrecisionRow>& rows) {
  PlotAxes a;
  a.mlo = rows.front().mantissa;
  a.mhi = rows.back().mantissa;
  if (a.mlo == a.mhi) {
    --a.mlo;
    ++a.mhi;
  }
  double smin = 99.0;
  double pmax = 40.0;
  for (const PrecisionRow& r : rows) {
    smin = std::min(smin, r.same_triangle_pct);
    if (std::isfinite(r.psnr_db)) {
      pmax = std::max(pmax, r.psnr_db);
    } else {
      a.any_inf = true;
    }
  }
  // A tick step from 1-2-5 steps giving at most six intervals.
  for (double st : {0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0}) {
    a.sstep = st;
    if ((100.0 - smin) / st <= 6.0) break;
  }
  a.slo = std::max(0.0, std::floor(smin / a.sstep - 1e-9) * a.sstep);
  a.phi = std::ceil((pmax + (a.any_inf ? 10.0 : 1.0)) / a.pstep) * a.pstep;
  return a;
}

// Axes, ticks and labels.
void draw_axes(Canvas& cv, const PlotAxes& a) {
  cv.line(kLeft, kTop, kLeft, kBottom, kBlack);
  cv.line(kRight, kTop, kRight, kBottom, kBlack);
  cv.line(kLeft, kBottom, kRight, kBottom, kBlack);
  for (int m = a.mlo; m <= a.mhi; ++m) {
    const int x = a.xmap(m);
    cv.line(x, kBottom, x, kBottom + 5, kBlack);
    const std::string l = std::to_string(m);
    cv.text(x - Canvas::text_width(l) / 2, kBottom + 10, l, kBlack);
  }
  const std::string xl = "MANTISSA BITS M  (FLOAT<7,M>)";
  cv.text((kLeft + kRight - Canvas::text_width(xl)) / 2, kBottom + 35, xl, kBlack);
  for (int k = 0; a.slo + k * a.sstep <= 100.0 + 1e-9; ++k) {
    const double v = a.slo + k * a.sstep;
    const int y = a.ys(v);
    cv.line(kLeft - 5, y, kLeft, y, kBlue);
    const std::string l = fmt(a.sstep < 1.0 ? "%.1f" : "%.0f", v);
    cv.text(kLeft - 8 - Canvas::text_width(l), y - 7, l, kBlue);
  }
  for (double v = 0.0; v <= a.phi + 1e-9; v += a.pstep) {
    const int y = a.yp(v);
    cv.line(kRight, y, kRight + 5, y, kRed);
    cv.text(kRight + 8, y - 7, fmt("%.0f", v), kRed);
  }
}

void draw_labels(Canvas& cv, const PlotAxes& a, const std::string& title) {
  cv.text(8, kTop - 26, "SAME TRIANGLE %", kBlue);
  const std::string rl = "PSNR DB";
  cv.text(kW - 8 - Canvas::text_width(rl), kTop - 26, rl, kRed);
  std::string t = title;
  if (t.size() > 56) t = "..." + t.substr(t.size() - 53);
  cv.text((kW - Canvas::text_width(t)) / 2, 6, t, kBlack);
  if (a.any_inf) {
    cv.text(kRight - Canvas::text_width("INF", 1) - 2, a.yp(a.phi) + 4, "INF", kRed, 1);
  }
}

// Curves with square markers.
PrecisionPlot draw_curves(Canvas& cv, const PlotAxes& a, const std::vector<PrecisionRow>& rows) {
  PrecisionPlot plot;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const PixelCoord s{a.xmap(rows[i].mantissa), a.ys(rows[i].same_triangle_pct)};
    const PixelCoord p{a.xmap(rows[i].mantissa), a.yp(rows[i].psnr_db)};
    if (i > 0) {
      cv.line(plot.same_points.back().x, plot.same_points.back().y, s.x, s.y, kBlue, 2);
      cv.line(plot.psnr_points.back().x, plot.psnr_points.back().y, p.x, p.y, kRed, 2);
    }
    plot.same_points.push_back(s);
    plot.psnr_points.push_back(p);
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const PixelCoord s = plot.same_points[i], p = plot.psnr_points[i];
    cv.rect(p.x - 3, p.y - 3, p.x + 3, p.y + 3, kRed);
    cv.rect(s.x - 3, s.y - 3, s.x + 3, s.y + 3, kBlue);
  }
  return plot;
}

}  // namespace

PrecisionPlot plot_precision(const std::vector<PrecisionRow>& rows, const std::string& title) {
  if (rows.empty()) throw std::runtime_error("precision plot: no rows");
  Canvas cv(kW, kH, kWhite);
  const PlotAxes a = plot_axes(rows);
  // Guides first, so curves draw over them.
  cv.line(a.xmap(16), kTop, a.xmap(16), kBottom, kGrey, 1, 4);
  cv.text(a.xmap(16) - Canvas::text_width("FP24", 1) / 2, kTop - 10, "FP24", kGrey, 1);
  cv.line(kLeft, a.ys(99.0), kRight, a.ys(99.0), kBlue, 1, 3);
  cv.line(kLeft, a.yp(35.0), kRight, a.yp(35.0), kRed, 1, 3);
  draw_axes(cv, a);
  draw_labels(cv, a, title);
  PrecisionPlot plot = draw_curves(cv, a, rows);
  plot.image = cv.take();
  return plot;
}

int run_precision(const PrecisionOptions& opts) {
  RenderSettings settings;
  settings.res = parse_resolution(opts.res);
  settings.bank_mb = opts.bank_mb;
  const auto [lo, hi] = parse_mantissa_range(opts.mantissa);
  const bool in_dir = !opts.out_dir.empty();
  if (in_dir) {
    check_out_dir(opts.out_dir);
    if (opts.out_given)
      throw std::runtime_error(
          "--out-dir names every file it writes (precision.png, "
          "report.json): drop --out");
  }
  const std::string out =
      in_dir ? run_file(opts.out_dir, "precision") : output_prefix(opts.out, {".png", ".json"});
  const std::vector<PrecisionRow> rows = run_precision_study(opts.scene, settings, lo, hi);

  const std::string png = out + ".png";
  const std::string json = in_dir ? run_file(opts.out_dir, "report.json") : out + ".json";
  const std::string name = std::filesystem::path(opts.scene).filename().string();
  write_rgb8(png, plot_precision(rows, name + "  " + std::to_string(settings.res.width) + "x" +
                                           std::to_string(settings.res.height))
                      .image);
  write_precision_report(json, opts.out_dir, opts.scene, settings, lo, hi, rows, opts.argv);
  std::printf("saarcor precision: %s, %dx%d, Float<7,m> against the float reference\n%s",
              opts.scene.c_str(), settings.res.width, settings.res.height,
              precision_table(rows).c_str());
  std::printf("  plot:   %s\n  table:  %s\n", png.c_str(), json.c_str());
  if (in_dir)
    std::printf("  run folder: %s (stats.txt, config.json, command.txt, host.json)\n",
                opts.out_dir.c_str());
  return 0;
}

}  // namespace saarcor
