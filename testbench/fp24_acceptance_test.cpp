// Acceptance of the functional fp24 model against the float reference (docs/compare.md)
// on every glTF model in the shared scenes and every built-in scene, at the 512x384: the
// same closest triangle for at least 99 % of the primary rays and a shaded image within 35 dB
// PSNR. Every scene prints its figures, so the test output is the precision report. The
// resolution matters for PSNR: rays that graze an edge (ties the two models break differently)
// grow with the width, pixels with its square; at 64x48 one flipped full-contrast pixel alone
// costs 10 log10(3072) = 34.9 dB, and the single-triangle scenes, whose default camera centres on
// the hypotenuse, scored 27.9 dB there (37.3 dB at 512x384).
//
// Known deviations (measured, explained in docs/compare.md "fp24 acceptance"): scenes listed in
// kKnown miss an issue threshold for a reason that is a property of the fp24 format or of the
// metric, not a model error. For them the test asserts the measured figure as a floor
// (a regression guard) and prints the reason; every other scene must meet the thresholds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "host/builtin_scenes.h"
#include "testbench/compare.h"
#include "testbench/image_io.h"
#include "testbench/render_cmd.h"

namespace saarcor {
namespace {

namespace fs = std::filesystem;

constexpr double kSameTrianglePct = 99.0;
constexpr double kPsnrDb = 35.0;

struct KnownDeviation {
  const char* scene;  // matched against the end of the spec
  double same_floor;
  double psnr_floor;
  const char* reason;
};

constexpr KnownDeviation kKnown[] = {
    // 33K-triangle objects of ~1 unit seen from ~50 units: in unit-triangle space |O'| ~ 5e3,
    // where the fp24 ulp is 1/16, so u = O'x + t*D'x cancels to an absolute error ~0.1.
    {"builtin:suncor", 98.6, 33.7,
     "cancellation in u = O'x + t*D'x: tiny triangles far away, |O'| ~ 5e3, fp24 ulp 1/16"},
    // The same field, every sunflower tilted by the wind at t = 0 (98.60 %, 34.03 dB measured).
    {"builtin:suncor-wind", 98.5, 33.7,
     "as builtin:suncor: the same tiny triangles far away, tilted"},
};

const KnownDeviation* known(const std::string& spec) {
  for (const KnownDeviation& k : kKnown) {
    const std::string s = k.scene;
    if (spec.size() >= s.size() && spec.compare(spec.size() - s.size(), s.size(), s) == 0) {
      return &k;
    }
  }
  return nullptr;
}

// Scenes whose memory image exceeds the prototype's 4 MB banks get bigger banks.
double bank_mb_for(const std::string& spec) {
  if (spec.find("ReciprocatingSaw") != std::string::npos) return 8.0;
  if (spec == "builtin:terrain") return 24.0;
  return 4.0;
}

std::vector<std::string> acceptance_scenes() {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& dir : fs::directory_iterator(SAARCOR_SHARED_SCENES, ec)) {
    if (!dir.is_directory()) continue;
    for (const auto& f : fs::directory_iterator(dir.path())) {
      const std::string ext = f.path().extension().string();
      if (ext == ".gltf" || ext == ".glb") files.push_back(f.path().string());
    }
  }
  std::sort(files.begin(), files.end());  // deterministic order
  for (const auto& name : host::builtin_scene_names())
    files.push_back("builtin:" + name);
  return files;
}

std::string short_name(const std::string& spec) {
  if (spec.rfind("builtin:", 0) == 0) return spec;
  const fs::path p(spec);
  return p.parent_path().filename().string() + "/" + p.filename().string();
}

class Fp24Acceptance : public ::testing::TestWithParam<std::string> {};

TEST_P(Fp24Acceptance, SameTriangleAndPsnrAgainstFloatReference) {
  const std::string spec = GetParam();
#ifdef SAARCOR_SANITIZED
  // Under ASan+UBSan the big scenes take minutes; the small ones run the same code.
  for (const char* big : {"ReciprocatingSaw", "2CylinderEngine", "VC/", "builtin:terrain",
                          "builtin:suncor", "DamagedHelmet"}) {
    if (spec.find(big) != std::string::npos) GTEST_SKIP() << "large scene, sanitizer build";
  }
#endif
  RenderSettings settings;
  settings.res = {512, 384};  // the default (render's default too)
  // A scene whose image exceeds the banks (the kd-trees move with the builder's parameters) is
  // retried with banks twice as large: bank size is a parameter, precision is what is tested.
  settings.bank_mb = bank_mb_for(spec);
  PreparedScene prep;
  for (;;) {
    try {
      prep = prepare_scene(spec, settings, ff::kFp24);
      break;
    } catch (const std::runtime_error& e) {
      if (std::string(e.what()).find("does not fit") == std::string::npos ||
          settings.bank_mb >= 64.0)
        throw;
      settings.bank_mb *= 2.0;
    }
  }
  const FrameResult ref = render_model(parse_model("float"), prep, settings);
  const FrameResult fp24 = render_model(parse_model("fp24"), prep, settings);
  const CompareResult hits = compare_hits(fp24.hits, ref.hits);
  const CompareResult img = compare_images(to_float_image(fp24.image), to_float_image(ref.image));
  std::uint64_t hit_pixels = 0;
  for (const auto& p : ref.hits.pixels)
    hit_pixels += p.hit() ? 1 : 0;
  const double psnr = *img.psnr_db;
  const auto& m = hits.mismatches;
  const KnownDeviation* k = known(spec);
  std::printf(
      "fp24 vs float %-50s same triangle %8.4f%%  PSNR %6s dB  hit pixels %4llu  t rel err "
      "median %.2g max %.2g  mismatches: hit/miss %llu (near edge %llu) edge %llu grazing %llu "
      "other %llu%s%s\n",
      short_name(spec).c_str(), hits.same_triangle_pct,
      std::isfinite(psnr) ? std::to_string(psnr).substr(0, 6).c_str() : "inf",
      static_cast<unsigned long long>(hit_pixels), hits.t_rel_err_median.value_or(0.0),
      hits.t_rel_err_max.value_or(0.0), static_cast<unsigned long long>(m.hit_vs_miss),
      static_cast<unsigned long long>(m.hit_vs_miss_near_edge),
      static_cast<unsigned long long>(m.edge_tie), static_cast<unsigned long long>(m.grazing),
      static_cast<unsigned long long>(m.other), k ? "\n  KNOWN DEVIATION: " : "",
      k ? k->reason : "");

  PixelRef first;
  for (int c = 1; c < 5 && !first.valid(); ++c)
    first = hits.first_mismatch[c];
  const double same_floor = k ? k->same_floor : kSameTrianglePct;
  const double psnr_floor = k ? k->psnr_floor : kPsnrDb;
  EXPECT_GE(hits.same_triangle_pct, same_floor)
      << short_name(spec) << ": replay the first mismatch with `saarcor render " << spec
      << " --model fp24 --res " << settings.res.width << "x" << settings.res.height << " --bank-mb "
      << settings.bank_mb << " --pixel " << first.x << "," << first.y << "` (and --model float)";
  EXPECT_GE(psnr, psnr_floor) << short_name(spec) << ": largest difference at --pixel "
                              << img.worst_pixel.x << "," << img.worst_pixel.y;
  // Same triangle, same ray: the relative t error stays within a few fp24 ulps of the
  // cancellation-free case (2^-17 = 7.6e-6 per rounding) for the median pixel.
  if (hits.t_rel_err_median) {
    EXPECT_LT(*hits.t_rel_err_median, 1e-4) << short_name(spec);
  }
}

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string n = short_name(info.param);
  const auto slash = n.find('/');
  if (slash != std::string::npos) n = n.substr(slash + 1);
  for (char& c : n) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return n;
}

INSTANTIATE_TEST_SUITE_P(Scenes, Fp24Acceptance, ::testing::ValuesIn(acceptance_scenes()),
                         test_name);

}  // namespace
}  // namespace saarcor
