// The SystemVerilog unit datapaths (rtl/intersection_unit.sv, transform_unit.sv,
// traversal_unit.sv) against units/datapath.h, bit for bit, on unit vectors that `saarcor vectors`
// captures from real frames (docs/unit-vectors.md): the room (20,000 per unit) and glTF models
// of ../shared/scenes. Every output must also equal the file's (the functional model's), the
// latency must be the cycle model's unit depth (units/cycle_params.h), the acceptance rule
// (accepts, with the tie rule) must match, and saarcor-rtl check must report what it finds.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "fixedfloat/float.h"
#include "rtl/rtl_units.h"
#include "rtl/units_testing.h"
#include "rtl/vector_file.h"
#include "units/cycle_params.h"
#include "units/datapath.h"

namespace saarcor::rtl::testing {
namespace {

using F = ff::fp24;

TEST(RtlUnits, LatencyIsTheCycleModelsDepth) {
  EXPECT_EQ(model_depth(VectorUnit::kIntersection), 18);
  EXPECT_EQ(model_depth(VectorUnit::kTransformation), 9);
  EXPECT_EQ(model_depth(VectorUnit::kTraversal), 12);
  for (const VectorUnit u : kUnits) {
    // One transaction into an idle pipeline, then a burst back to back.
    const std::vector<std::uint32_t> in(units::vector_inputs(u).size(), 0x3F0000);
    const RtlRun one = run_unit(u, {in});
    EXPECT_EQ(one.latency_min, model_depth(u)) << units::vector_unit_name(u);
    const RtlRun burst = run_unit(u, std::vector<std::vector<std::uint32_t>>(50, in));
    EXPECT_EQ(burst.latency_min, model_depth(u)) << units::vector_unit_name(u);
    EXPECT_EQ(burst.latency_max, model_depth(u)) << units::vector_unit_name(u);
    EXPECT_EQ(burst.stray_outputs, 0u) << units::vector_unit_name(u);
    // 50 transactions back to back: the last leaves depth cycles after it entered.
    EXPECT_EQ(burst.cycles, 50u + static_cast<unsigned>(model_depth(u)) - 1u + 64u);
  }
}

TEST(RtlUnits, RoomVectors) {
  for (const VectorUnit u : kUnits) {
    const std::size_t count = kSanitized ? 2000 : 20000;
    const std::string path = generate("builtin:room", u, count);
    EXPECT_EQ(check_file(path, std::string("builtin:room ") + units::vector_unit_name(u)), count);
    std::filesystem::remove(path);
  }
}

// The dynamic scene's instances (object transformations) with shadow and secondary rays.
TEST(RtlUnits, DynamicSceneWithShadowsAndSecondaryRays) {
  for (const VectorUnit u : kUnits) {
    const std::size_t count = kSanitized ? 1000 : 5000;
    const std::string path = generate("builtin:dynamic", u, count, "--shadows --depth 2");
    EXPECT_EQ(check_file(path, std::string("builtin:dynamic ") + units::vector_unit_name(u)),
              count);
    std::filesystem::remove(path);
  }
}

class RtlUnitsOnModels : public ::testing::TestWithParam<const char*> {};

TEST_P(RtlUnitsOnModels, VectorsMatchTheDatapath) {
  const std::string scene = std::string(SAARCOR_SHARED_SCENES) + "/" + GetParam();
  if (!std::filesystem::exists(scene)) GTEST_SKIP() << scene << " not present";
  for (const VectorUnit u : kUnits) {
    const std::size_t count = kSanitized ? 1000 : 5000;
    const std::string path = generate(scene, u, count);
    EXPECT_EQ(check_file(path, std::string(GetParam()) + " " + units::vector_unit_name(u)), count);
    std::filesystem::remove(path);
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, RtlUnitsOnModels,
                         ::testing::Values("Duck/Duck.gltf", "CesiumMilkTruck/CesiumMilkTruck.gltf",
                                           "DamagedHelmet/DamagedHelmet.gltf",
                                           "2CylinderEngine/2CylinderEngine.gltf",
                                           "SpheresScaledInstances/spheres_scaled_instances.gltf",
                                           "BoxAnimated/BoxAnimated.gltf",
                                           "RiggedSimple/RiggedSimple.gltf",
                                           "CesiumMan/CesiumMan.gltf"),
                         [](const ::testing::TestParamInfo<const char*>& i) {
                           std::string n = i.param;
                           return n.substr(0, n.find('/'));
                         });

// The acceptance stage against units::accepts: rays without a hit, closest hits just before, at
// and after the candidate's t (ties broken by instance, then triangle), and random ones.
TEST(RtlUnits, AcceptanceIsTheDatapathsRule) {
  const std::string path = generate("builtin:room", VectorUnit::kIntersection, 4000);
  const VectorFile f = read_vector_file(path);
  std::filesystem::remove(path);
  const ff::FpUnit<F> fp;
  std::mt19937_64 rng(11);
  std::vector<std::vector<std::uint32_t>> inputs;
  std::vector<AcceptInputs> acc;
  std::vector<bool> want;
  int accepted = 0;
  for (const auto& v : f.vectors) {
    units::Ray<F> ray;
    for (int i = 0; i < 3; ++i) {
      ray.o[i] = F::from_bits(v.in[static_cast<std::size_t>(i)]);
      ray.d[i] = F::from_bits(v.in[static_cast<std::size_t>(i + 3)]);
    }
    const units::Candidate<F> c = units::intersect_unit_triangle(fp, ray);
    for (int kind = 0; kind < 6; ++kind) {
      AcceptInputs a;
      a.instance = static_cast<std::uint32_t>(rng() % 4);
      a.triangle = static_cast<std::uint32_t>(rng() % 4);
      if (kind > 0) {
        a.best_instance = static_cast<std::uint32_t>(rng() % 4);
        a.best_triangle = static_cast<std::uint32_t>(rng() % 4);
      }
      const std::uint32_t mag = c.t.bits & 0x7FFFFF;
      switch (kind) {
        case 1:
          a.best_t = c.t.bits;  // a tie: the ids decide
          break;
        case 2:
          a.best_t = mag + 1;
          break;
        case 3:
          a.best_t = mag == 0 ? 0 : mag - 1;
          break;
        case 4:
          a.best_t = static_cast<std::uint32_t>(rng()) & 0x7FFFFF;
          break;
        case 5:
          a.best_t = 0;
          break;
        default:
          break;
      }
      units::HitRecord<F> best;
      best.t = F::from_bits(a.best_t);
      best.instance = a.best_instance;
      best.triangle = a.best_triangle;
      const bool w = units::accepts(c, a.instance, a.triangle, best);
      accepted += w ? 1 : 0;
      inputs.push_back(v.in);
      acc.push_back(a);
      want.push_back(w);
    }
  }
  const RtlRun run = run_unit(VectorUnit::kIntersection, inputs, {}, acc);
  std::size_t bad = 0;
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    if ((run.outputs[k][5] != 0) != want[k] && ++bad <= 5) {
      ADD_FAILURE() << "inputs " << hex_list(inputs[k]) << ", instance " << acc[k].instance
                    << " triangle " << acc[k].triangle << ", best t " << std::hex << acc[k].best_t
                    << std::dec << " instance " << acc[k].best_instance << " triangle "
                    << acc[k].best_triangle << ": accepts gives " << want[k];
    }
  }
  EXPECT_EQ(bad, 0u);
  EXPECT_GT(accepted, 100);  // the cases exercise both answers
  EXPECT_LT(static_cast<std::size_t>(accepted), inputs.size() / 2);
}

// saarcor-rtl check on a scene no other RTL test uses: exit 0 on a file the RTL reproduces, 2
// with the differing line listed when an output is changed, 1 for a malformed file; --out writes
// the RTL's outputs.
TEST(RtlUnits, SaarcorRtlCheck) {
  const std::string path =
      generate(std::string(SAARCOR_SHARED_SCENES) + "/AnimatedCube/AnimatedCube.gltf",
               VectorUnit::kTransformation, 300);
  const std::string bin = std::string(SAARCOR_BIN_DIR) + "/saarcor-rtl";
  const std::string out = temp_path("check_out.txt");
  auto run = [&](const std::string& file, std::string* output) {
    const std::string cmd = bin + " check '" + file + "' --out '" + out + "' 2>&1";
    FILE* p = ::popen(cmd.c_str(), "r");
    std::string s;
    char buf[512];
    while (p && std::fgets(buf, sizeof buf, p))
      s += buf;
    const int status = p ? ::pclose(p) : -1;
    if (output) *output = s;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  std::string text;
  EXPECT_EQ(run(path, &text), 0) << text;
  EXPECT_NE(text.find("300 vectors"), std::string::npos) << text;
  EXPECT_NE(text.find("0 differ"), std::string::npos) << text;
  // The RTL's outputs written back are the file itself.
  std::ifstream a(path), b(out);
  std::stringstream sa, sb;
  sa << a.rdbuf();
  sb << b.rdbuf();
  EXPECT_EQ(sa.str(), sb.str());

  // Change the last field of vector 7 (ry's last hex digit is the field before rz).
  VectorFile f = read_vector_file(path);
  std::vector<std::vector<std::uint32_t>> outs;
  for (const auto& v : f.vectors)
    outs.push_back(v.out);
  outs[7][2] ^= 1u;
  const std::string bad = temp_path("check_bad.txt");
  std::ofstream(bad) << format_vector_file(f, outs);
  EXPECT_EQ(run(bad, &text), 2) << text;
  EXPECT_NE(text.find("line " + std::to_string(f.vectors[7].line) + ": rz is"), std::string::npos)
      << text;
  EXPECT_NE(text.find("1 differ"), std::string::npos) << text;

  std::ofstream(bad) << "# saarcor unit vectors 1\n# unit: transformation\n3f0000 1\n";
  EXPECT_EQ(run(bad, &text), 1) << text;
  EXPECT_NE(text.find("line 3"), std::string::npos) << text;
  for (const auto& p : {path, out, bad})
    std::filesystem::remove(p);
}

TEST(RtlVectorFile, ParsesAndRejects) {
  const VectorFile f = parse_vector_text(
      "# saarcor unit vectors 1\n# unit: traversal\n\n3f0000 3e0000 3f0000 0 7f0000 1 1 3f0000 "
      "3e8000\n",
      "t");
  ASSERT_EQ(f.vectors.size(), 1u);
  EXPECT_EQ(f.unit, VectorUnit::kTraversal);
  EXPECT_EQ(f.vectors[0].line, 4u);
  EXPECT_EQ(f.vectors[0].in,
            (std::vector<std::uint32_t>{0x3F0000, 0x3E0000, 0x3F0000, 0, 0x7F0000}));
  EXPECT_EQ(f.vectors[0].out, (std::vector<std::uint32_t>{1, 1, 0x3F0000, 0x3E8000}));
  EXPECT_THROW(parse_vector_text("3f0000\n", "t"), std::runtime_error);
  EXPECT_THROW(parse_vector_text("# unit: traversal\n1 2 3 4 5 2 1 3 4\n", "t"),
               std::runtime_error);
  EXPECT_THROW(parse_vector_text("# unit: traversal\n1 2 3 4 5 1 1 3 1000000\n", "t"),
               std::runtime_error);
  EXPECT_THROW(parse_vector_text("# unit: traversal\n1 2 3 4 5 1 1 3 xyz\n", "t"),
               std::runtime_error);
  EXPECT_THROW(parse_vector_text("# unit: nothing\n", "t"), std::runtime_error);
}

}  // namespace
}  // namespace saarcor::rtl::testing
