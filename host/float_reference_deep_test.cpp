// Float reference against Embree on the built-in scenes too large for the default run (
// docs/compare.md): SunCOR (187M triangles through 5,622 instances) and the terrain (10.5M
// triangles through 264 objects). Flattening them into world space would take gigabytes, so Embree
// gets the same objects and instances as instance geometries (it then transforms the ray itself).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "host/embree_oracle.h"
#include "host/float_reference.h"
#include "host/image_builder.h"
#include "host/scene.h"

namespace saarcor::host {
namespace {

void check_instanced(const std::string& spec) {
  SCOPED_TRACE(spec);
  const Scene scene = load_scene(spec);
  const BuiltImage image = build_fitting_image(scene, 64, 48);
  const FloatScene fs(image);
  FloatParams fp;
  fp.shade = false;
  const FloatFrame frame = render_float(fs, image, scene, fp);
  const EmbreeOracle embree(scene, image, EmbreeOracle::Mode::kInstanced);
  const EmbreeAgreement a = compare_with_embree(frame, embree);
  std::printf(
      "[ embree   ] %s: %llu triangles, %d rays, %d hits, same triangle %.3f%%, edge cases %d, "
      "mismatches %d, t rel err max %.2e (Embree instanced)\n",
      spec.c_str(), static_cast<unsigned long long>(scene.instanced_triangles()), a.rays, a.hits(),
      a.same_pct(), a.edge_ignored, a.mismatches, a.t_rel_err_max);
  EXPECT_GT(a.hits(), 0);
  EXPECT_GE(a.same_pct(), 99.9) << "first mismatch at --pixel " << a.first_mismatch % 64 << ","
                                << a.first_mismatch / 64;
  EXPECT_LT(a.t_rel_err_max, 1e-5);
}

TEST(FloatVsEmbreeDeep, SunCor) {
  check_instanced("builtin:suncor");
}
TEST(FloatVsEmbreeDeep, Terrain) {
  check_instanced("builtin:terrain");
}

}  // namespace
}  // namespace saarcor::host
