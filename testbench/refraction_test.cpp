// Refraction rays in the three models (docs/shading.md and docs/compare.md; docs/shading.md section
// 7; decisions D12, D37): the functional fp24 model against the float reference on every scene with
// a refractive material (builtin:glass; BART's kitchen, whose glasses, bowl and dragon are glass),
// Float<7,23> against the binary32 reference bit for bit with refraction, shadow and reflection
// rays (both models run the RGS's op order), and total internal reflection in both models on a
// glass quad seen from inside at 60 degrees. The cycle model's bit-exactness with refraction is in
// testbench/dynrtc_test.cpp (DynRtc.RefractionOnGlass*).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "host/float_reference.h"
#include "host/image_builder.h"
#include "host/scene.h"
#include "testbench/compare.h"
#include "testbench/image_io.h"
#include "testbench/render_cmd.h"
#include "units/functional_model.h"

namespace saarcor {
namespace {

constexpr double kPsnrDb = 35.0;  // the threshold for fp24 against binary32

std::string kitchen() {
  return std::string(SAARCOR_SHARED_SCENES) + "/BART/kitchen/aff/kitchen.aff";
}

// Shadows and secondary rays (reflection, transparency, refraction) to the default depth, 3.
RenderSettings shaded(int w, int h, double bank_mb) {
  RenderSettings s;
  s.res = {w, h};
  s.shadows = true;
  s.depth = 3;
  s.bank_mb = bank_mb;
  return s;
}

struct RefractiveScene {
  std::string spec;
  double bank_mb;
};

class Fp24Refraction : public ::testing::TestWithParam<RefractiveScene> {};

// At 128x96 (the precision study's figures at 512x384 are the deep test's): PSNR of the shaded
// images at least 35 dB, and refraction rays were traced.
TEST_P(Fp24Refraction, PsnrAgainstFloatReference) {
  const RenderSettings s = shaded(128, 96, GetParam().bank_mb);
  const PreparedScene prep = prepare_scene(GetParam().spec, s, ff::kFp24);
  const FrameResult ref = render_model(parse_model("float"), prep, s);
  const FrameResult fp24 = render_model(parse_model("fp24"), prep, s);
  const CompareResult img = compare_images(to_float_image(fp24.image), to_float_image(ref.image));
  const auto refracted = fp24.counters["per_ray"]["refraction"]["rays_issued"].get<std::uint64_t>();
  std::printf("fp24 vs float with refraction %s: PSNR %.2f dB, %llu refraction rays\n",
              GetParam().spec.c_str(), *img.psnr_db, static_cast<unsigned long long>(refracted));
  EXPECT_GE(*img.psnr_db, kPsnrDb)
      << "largest difference at --pixel " << img.worst_pixel.x << "," << img.worst_pixel.y;
  EXPECT_GT(refracted, static_cast<std::uint64_t>(s.res.width * s.res.height / 50));
}

INSTANTIATE_TEST_SUITE_P(Scenes, Fp24Refraction,
                         ::testing::Values(RefractiveScene{"builtin:glass", 4.0},
                                           RefractiveScene{kitchen(), 4.0}),
                         [](const auto& info) {
                           return info.param.spec == "builtin:glass" ? std::string("glass")
                                                                     : std::string("kitchen");
                         });

// Float<7,23> has binary32's precision: with the reference's instance step in binary32 both
// models run the same op order everywhere, the RGS's refraction factor included, so their hit
// records and images are identical; refraction, total internal reflection (the crystal block's
// bottom and sides), reflection (the mirror) and shadows are all in this frame.
TEST(Refraction, Mantissa23ReproducesTheFloatReferenceBitForBit) {
  RenderSettings s = shaded(64, 48, 4.0);
  s.float_instance_step = host::InstanceStep::kBinary32;
  // Both read e and eta from one image: Float<7,23> values are binary32 values.
  const PreparedScene prep = prepare_scene("builtin:glass", s, ff::Format{7, 23});
  const FrameResult ref = render_model(parse_model("float"), prep, s);
  const FrameResult m23 = render_model(parse_model("e7m23"), prep, s);
  const CompareResult c = compare_hits(m23.hits, ref.hits);
  EXPECT_TRUE(c.bit_identical) << compare_summary(c);
  EXPECT_EQ(m23.image.rgb, ref.image.rgb);
  const auto& kinds = m23.counters["per_ray"];
  EXPECT_GT(kinds["refraction"]["rays_issued"].get<std::uint64_t>(), 500u);
  EXPECT_GT(kinds["reflection"]["rays_issued"].get<std::uint64_t>(), 100u);
  EXPECT_GT(kinds["shadow"]["rays_issued"].get<std::uint64_t>(), 1000u);
}

// A glass quad (ior 1.5, refraction weight 0.6) in the plane z = 0, seen at 60 degrees from the
// quad's normal through a 3x3 image; `back`: its winding reversed, so every ray hits its back and
// leaves glass (eta = 1.5), beyond the critical angle of 41.8 degrees.
host::Scene glass_quad(bool back) {
  host::Scene scene;
  host::Object quad;
  quad.name = "glass";
  quad.positions = {{-4, -4, 0}, {4, -4, 0}, {4, 4, 0}, {-4, 4, 0}};
  quad.triangles = back ? std::vector<glm::uvec3>{{0, 2, 1}, {0, 3, 2}}
                        : std::vector<glm::uvec3>{{0, 1, 2}, {0, 2, 3}};
  quad.material = {0, 0};
  host::mark_degenerate_triangles(quad);
  scene.objects = {quad};
  scene.instances.push_back(host::Instance{});
  host::Material m;
  m.name = "glass";
  m.refraction = 0.6f;
  m.ior = 1.5f;
  scene.materials = {m};
  host::Light l;
  l.position = {0, 0, 4};
  scene.lights.push_back(l);
  host::Camera c;
  c.position = {0.0f, -2.0f * std::sqrt(3.0f), 2.0f};
  c.forward = -glm::normalize(c.position);
  c.up = glm::normalize(glm::cross(glm::cross(c.forward, glm::vec3(0, 0, 1)), c.forward));
  c.yfov = 0.1f;  // every pixel's ray within a degree of 60 degrees
  scene.cameras.push_back(c);
  return scene;
}

// docs/shading.md section 7, both models: entering, each hit spawns a refraction ray; leaving
// beyond the critical angle, none, and a reflection ray carries the refraction weight instead.
TEST(Refraction, TotalInternalReflectionTurnsTheRayIntoAReflection) {
  for (const bool back : {false, true}) {
    SCOPED_TRACE(back ? "leaving glass" : "entering glass");
    const host::Scene scene = glass_quad(back);
    host::ImageParams ip;
    ip.width = 3;
    ip.height = 3;
    ip.background_rgb = 0x808080u;
    const host::BuiltImage image = host::build_image(scene, ip);
    units::FunctionalParams p;
    p.secondary = true;
    const units::FunctionalFrame fp24 = units::run_functional(image.image, p);
    const auto kind = [&](units::RayKind k) {
      return fp24.rays_issued[static_cast<std::size_t>(k)];
    };
    EXPECT_EQ(kind(units::RayKind::kPrimary), 9u);
    EXPECT_EQ(kind(units::RayKind::kRefraction), back ? 0u : 9u);
    EXPECT_EQ(kind(units::RayKind::kReflection), back ? 9u : 0u);
    host::FloatParams fp;
    fp.secondary = true;
    const host::FloatFrame ref = host::render_float(image, scene, fp);
    ASSERT_EQ(fp24.rgb.size(), ref.rgb.size());
    for (std::size_t i = 0; i < ref.rgb.size(); ++i)  // the cosines' last bit may differ
      EXPECT_NEAR(fp24.rgb[i], ref.rgb[i], 1) << "byte " << i;
  }
}

}  // namespace
}  // namespace saarcor
