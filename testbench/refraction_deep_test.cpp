// Deep (ctest label "deep"): the functional fp24 model against the float reference with
// refraction, shadow and reflection rays at the 512x384 on every scene with a refractive
// material (docs/compare.md "Refraction"): builtin:glass and BART's kitchen. The default suite runs
// the same comparison at 128x96 (testbench/refraction_test.cpp).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "testbench/compare.h"
#include "testbench/image_io.h"
#include "testbench/render_cmd.h"

namespace saarcor {
namespace {

TEST(Fp24RefractionDeep, PsnrAgainstFloatReferenceAt512x384) {
  const std::string kitchen = std::string(SAARCOR_SHARED_SCENES) + "/BART/kitchen/aff/kitchen.aff";
  for (const auto& [spec, bank_mb] :
       {std::pair<std::string, double>{"builtin:glass", 4.0}, {kitchen, 4.0}}) {
    RenderSettings s;
    s.res = {512, 384};
    s.shadows = true;
    s.depth = 3;
    s.bank_mb = bank_mb;
    const PreparedScene prep = prepare_scene(spec, s, ff::kFp24);
    const FrameResult ref = render_model(parse_model("float"), prep, s);
    const FrameResult fp24 = render_model(parse_model("fp24"), prep, s);
    const CompareResult img = compare_images(to_float_image(fp24.image), to_float_image(ref.image));
    std::printf("fp24 vs float with refraction at 512x384, %s: PSNR %.2f dB\n", spec.c_str(),
                *img.psnr_db);
    EXPECT_GE(*img.psnr_db, 35.0) << spec << ": largest difference at --pixel " << img.worst_pixel.x
                                  << "," << img.worst_pixel.y;
  }
}

}  // namespace
}  // namespace saarcor
