// Test-only helpers of the cycle model tests (testbench/dynrtc_test.cpp, dynrtc_deep_test.cpp,
// unit_vectors_test.cpp): the covering design's configurations and scenes, and the bit-exactness
// check against the functional fp24 model with conservation of rays and threads.
#pragma once

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "host/builtin_scenes.h"
#include "host/image_builder.h"
#include "host/scene.h"
#include "testbench/chip.h"
#include "testbench/covering_design.h"

namespace saarcor::units::testing {

#ifdef SAARCOR_SANITIZED
constexpr bool kSanitized = true;  // the ASan/UBSan build: smaller frames, fewer runs
#else
constexpr bool kSanitized = false;
#endif

inline host::BuiltImage build(const std::string& spec, int w, int h, std::uint32_t bank_mb = 4,
                              bool bilinear = true) {
  const host::Scene scene = host::load_scene(spec);
  host::ImageParams ip;
  ip.width = w;
  ip.height = h;
  ip.bank_words = bank_mb * 262144u;
  ip.bilinear = bilinear;
  return host::build_image(scene, ip);
}

inline std::string shared(const std::string& rel) {
  return std::string(SAARCOR_SHARED_SCENES) + "/" + rel;
}

// The covering design's configurations (testbench/covering_design.h).
using saarcor::covering::Config;
using saarcor::covering::configs;
using saarcor::covering::params_of;
using saarcor::covering::shading_of;

inline FunctionalParams functional_of(const Config& c, const CycleParams& p) {
  return functional_params(p, shading_of(c));
}

inline bool same_record(const FrameSink::Pixel& a, const FrameSink::Pixel& b) {
  return a.t == b.t && a.u == b.u && a.v == b.v && a.cos == b.cos && a.instance == b.instance &&
         a.triangle == b.triangle && a.o == b.o && a.d == b.d && a.counters == b.counters;
}

// The cycle model against the functional model on one image and configuration: every hit record
// (and per-ray counter) bit for bit, the image, the op counts; conservation of rays and threads.
inline void expect_bit_exact(const host::BuiltImage& b, const Config& c, const std::string& what) {
  const CycleParams p = params_of(c);
  CycleRunOptions o;
  o.shading = shading_of(c);
  const CycleFrame cy = run_cycle(b.image, p, o);
  const FunctionalFrame fn = run_functional(b.image, functional_of(c, p));
  ASSERT_EQ(cy.frame.pixels.size(), fn.pixels.size()) << what;
  int bad = 0;
  for (std::size_t i = 0; i < fn.pixels.size(); ++i)
    if (!same_record(cy.frame.pixels[i], fn.pixels[i]) && ++bad <= 3)
      ADD_FAILURE() << what << ": pixel " << i % static_cast<std::size_t>(fn.width) << ","
                    << i / static_cast<std::size_t>(fn.width) << " differs";
  EXPECT_EQ(bad, 0) << what;
  EXPECT_EQ(cy.frame.rgb, fn.rgb) << what;
  // The same work, whatever the timing.
  EXPECT_EQ(cy.frame.units.traversal_ops, fn.units.traversal_ops) << what;
  EXPECT_EQ(cy.frame.units.transformation_ops, fn.units.transformation_ops) << what;
  EXPECT_EQ(cy.frame.units.intersection_ops, fn.units.intersection_ops) << what;
  EXPECT_EQ(cy.frame.units.requests, fn.units.requests) << what;
  // Conservation: every ray issued returns exactly once, every packet frees its thread.
  for (int k = 0; k < kRayKinds; ++k) {
    EXPECT_EQ(cy.frame.rays_issued[static_cast<std::size_t>(k)],
              cy.frame.rays_returned[static_cast<std::size_t>(k)])
        << what << " " << ray_kind_name(static_cast<RayKind>(k));
    EXPECT_EQ(cy.frame.rays_issued[static_cast<std::size_t>(k)],
              fn.rays_issued[static_cast<std::size_t>(k)])
        << what;
  }
  EXPECT_EQ(cy.frame.rays_issued[0],
            static_cast<std::uint64_t>(fn.width) * static_cast<std::uint64_t>(fn.height))
      << what;
  EXPECT_EQ(cy.packets_retired, cy.packets) << what;
  EXPECT_GT(cy.cycles, 0u);
}

// Scenes and the configurations each runs: every scene runs the prototype and two others, in
// rotation, so every configuration meets many scenes (the full cross product is the deep test).
struct SceneCase {
  std::string spec;
  int w, h;
  std::uint32_t bank_mb = 4;  // the prototype's 4 MB banks; larger scenes need more
};
inline std::vector<SceneCase> scene_cases() {
  std::vector<SceneCase> s;
  for (const std::string& n : host::builtin_scene_names()) {
    // SunCOR's object under swaying transforms: builtin:suncor covers its geometry here, and the
    // frame-sequence tests check its frames bit for bit (FrameSequence.SuncorWindEveryInstance...).
    if (n == "suncor-wind") continue;
    s.push_back({"builtin:" + n, 32, 24, n == "terrain" ? 32u : 4u});
  }
  for (const char* m : {"Triangle/Triangle.gltf",
                        "TriangleWithoutIndices/TriangleWithoutIndices.gltf",
                        "Box/Box.gltf",
                        "Box/Box.glb",
                        "SimpleMeshes/SimpleMeshes.gltf",
                        "Cameras/Cameras.gltf",
                        "BoxTextured/BoxTextured.gltf",
                        "Duck/Duck.gltf",
                        "AnimatedTriangle/AnimatedTriangle.gltf",
                        "BoxAnimated/BoxAnimated.gltf",
                        "AnimatedCube/AnimatedCube.gltf",
                        "InterpolationTest/InterpolationTest.gltf",
                        "CesiumMilkTruck/CesiumMilkTruck.gltf",
                        "SpheresScaledInstances/spheres_scaled_instances.gltf",
                        "RiggedSimple/RiggedSimple.gltf",
                        "CesiumMan/CesiumMan.gltf",
                        "AnimatedMorphCube/AnimatedMorphCube.gltf",
                        "DamagedHelmet/DamagedHelmet.gltf",
                        "VC/VC.gltf",
                        "2CylinderEngine/2CylinderEngine.gltf",
                        "ReciprocatingSaw/ReciprocatingSaw.gltf"})
    // The prototype's 4 MB banks; the two largest models need more.
    s.push_back(
        {shared(m), 32, 24,
         std::string(m).rfind("Recip", 0) == 0 || std::string(m).rfind("2Cyl", 0) == 0 ? 8u : 4u});
  return s;
}

}  // namespace saarcor::units::testing
