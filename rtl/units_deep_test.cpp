// Deep runs of the SystemVerilog unit datapaths (label "deep"; ctest --preset deep): every scene
// of the covering design (testbench/dynrtc_testing.h: the seven built-ins and 21 glTF models of
// ../shared/scenes), 20,000 vectors per unit from a frame with shadow rays and secondary rays to
// depth 2, each through the RTL against units/datapath.h and the file, bit for bit.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "rtl/units_testing.h"

namespace saarcor::rtl::testing {
namespace {

struct Scene {
  const char* spec;  // builtin:NAME or a path under ../shared/scenes
  const char* bank_mb;
};

constexpr Scene kScenes[] = {
    {"builtin:triangle", "4"},
    {"builtin:cube", "4"},
    {"builtin:room", "4"},
    {"builtin:suncor", "4"},
    {"builtin:terrain", "32"},
    {"builtin:dynamic", "4"},
    {"builtin:glass", "4"},
    {"Triangle/Triangle.gltf", "4"},
    {"TriangleWithoutIndices/TriangleWithoutIndices.gltf", "4"},
    {"Box/Box.gltf", "4"},
    {"Box/Box.glb", "4"},
    {"SimpleMeshes/SimpleMeshes.gltf", "4"},
    {"Cameras/Cameras.gltf", "4"},
    {"BoxTextured/BoxTextured.gltf", "4"},
    {"Duck/Duck.gltf", "4"},
    {"AnimatedTriangle/AnimatedTriangle.gltf", "4"},
    {"BoxAnimated/BoxAnimated.gltf", "4"},
    {"AnimatedCube/AnimatedCube.gltf", "4"},
    {"InterpolationTest/InterpolationTest.gltf", "4"},
    {"CesiumMilkTruck/CesiumMilkTruck.gltf", "4"},
    {"SpheresScaledInstances/spheres_scaled_instances.gltf", "4"},
    {"RiggedSimple/RiggedSimple.gltf", "4"},
    {"CesiumMan/CesiumMan.gltf", "4"},
    {"AnimatedMorphCube/AnimatedMorphCube.gltf", "4"},
    {"DamagedHelmet/DamagedHelmet.gltf", "4"},
    {"VC/VC.gltf", "4"},
    {"2CylinderEngine/2CylinderEngine.gltf", "8"},
    {"ReciprocatingSaw/ReciprocatingSaw.gltf", "8"},
};

class RtlUnitsDeep : public ::testing::TestWithParam<int> {};

TEST_P(RtlUnitsDeep, TwentyThousandVectorsPerUnit) {
  const Scene& sc = kScenes[GetParam()];
  std::string spec = sc.spec;
  if (spec.rfind("builtin:", 0) != 0) {
    spec = std::string(SAARCOR_SHARED_SCENES) + "/" + spec;
    if (!std::filesystem::exists(spec)) GTEST_SKIP() << spec << " not present";
  }
  for (const VectorUnit u : kUnits) {
    const std::string path =
        generate(spec, u, 20000, std::string("--shadows --depth 2 --bank-mb ") + sc.bank_mb);
    check_file(path, std::string(sc.spec) + " " + units::vector_unit_name(u));
    std::filesystem::remove(path);
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, RtlUnitsDeep,
                         ::testing::Range(0, static_cast<int>(std::size(kScenes))));

}  // namespace
}  // namespace saarcor::rtl::testing
