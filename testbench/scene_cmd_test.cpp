// `saarcor scene` as a user runs it (README "Command line"): the JSON keys and values, --time,
// --export then re-load, and one line on stderr with a non-zero exit for each class of bad input.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "host/image_builder.h"
#include "host/scene.h"
#include "host/tree_objective.h"
#include "memif/image_file.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::string kSaarcor = std::string(SAARCOR_BIN_DIR) + "/saarcor";
const std::string kScenes = SAARCOR_SHARED_SCENES;

struct CmdResult {
  int status = -1;
  std::string out;
  std::string err;
};

class SceneCmd : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::temp_directory_path() /
        ("saarcor_scene_cmd_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  CmdResult run(const std::string& args) {
    const std::string err_file = (dir_ / "stderr.txt").string();
    const std::string cmd = kSaarcor + " scene " + args + " 2>" + err_file;
    CmdResult r;
    FILE* p = popen(cmd.c_str(), "r");
    if (p == nullptr) return r;
    std::array<char, 4096> buf{};
    std::size_t n = 0;
    while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0)
      r.out.append(buf.data(), n);
    const int st = pclose(p);
    r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    std::ifstream e(err_file);
    std::stringstream ss;
    ss << e.rdbuf();
    r.err = ss.str();
    return r;
  }

  // Asserts the failure shape every bad input must have: exit 1, one stderr line, nothing on
  // stdout.
  void expect_one_line_error(const std::string& args, const std::string& part) {
    SCOPED_TRACE(args);
    const CmdResult r = run(args);
    EXPECT_EQ(r.status, 1);
    EXPECT_TRUE(r.out.empty()) << r.out;
    ASSERT_FALSE(r.err.empty());
    EXPECT_EQ(r.err.rfind("saarcor: error: ", 0), 0u) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
    EXPECT_NE(r.err.find(part), std::string::npos) << r.err;
  }

  std::string write(const std::string& name, const std::string& text) {
    const std::string p = (dir_ / name).string();
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }

  fs::path dir_;
};

TEST_F(SceneCmd, JsonReportOfTheRoom) {
  const CmdResult r = run("builtin:room --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["triangles"], 806);
  EXPECT_EQ(j["unique_triangles"], 806);
  EXPECT_EQ(j["objects"], 1);
  EXPECT_EQ(j["instances"], 1);
  EXPECT_EQ(j["lights"], 2);
  EXPECT_EQ(j["cameras"], 1);
  EXPECT_EQ(j["animation_seconds"], 0.0);
  EXPECT_EQ(j["dropped_triangles"], 0);
  EXPECT_TRUE(j["image_error"].is_null());
  ASSERT_TRUE(j["kdtree"]["top"].is_object());
  EXPECT_GE(j["kdtree"]["top"]["nodes"].get<int>(), 1);
  EXPECT_EQ(j["kdtree"]["bottom"]["trees"], 1);
  EXPECT_GT(j["kdtree"]["bottom"]["nodes"].get<int>(), 1);
  ASSERT_TRUE(j["bytes_per_bank"].is_array());
  ASSERT_EQ(j["bytes_per_bank"].size(), 6u);
  // Banks 3-5 hold the scene: 806 triangles of 36-byte matrices at least, spread over three.
  std::uint64_t scene_bytes = 0;
  for (int b = 3; b < 6; ++b)
    scene_bytes += j["bytes_per_bank"][b].get<std::uint64_t>();
  EXPECT_GT(scene_bytes, 806u * 36u);
}

// --set kd.KEY=VALUE builds the trees with the builder's keys: dearer traversal steps, fewer
// nodes and more triangle tests per ray; every tree's expectations are printed.
TEST_F(SceneCmd, TreeKeysChangeTheTrees) {
  const CmdResult a = run("builtin:room --json");
  const CmdResult b = run("builtin:room --json --set kd.traversal_cost=60");
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_EQ(b.status, 0) << b.err;
  const json ja = json::parse(a.out)["kdtree"]["bottom"];
  const json jb = json::parse(b.out)["kdtree"]["bottom"];
  EXPECT_LT(jb["nodes"].get<int>() * 2, ja["nodes"].get<int>());
  EXPECT_LT(jb["nodes_per_triangle"].get<double>(), ja["nodes_per_triangle"].get<double>());
  EXPECT_DOUBLE_EQ(ja["nodes_per_triangle"].get<double>(), ja["nodes"].get<double>() / 806.0);
  EXPECT_GT(jb["objects"][0]["expected_item_tests"].get<double>(),
            ja["objects"][0]["expected_item_tests"].get<double>());
  const CmdResult t = run("builtin:room");
  EXPECT_NE(t.out.find("806 triangles, "), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("nodes per triangle, 45 chain links (0 mergeable), depth "),
            std::string::npos)
      << t.out;
  // The room's 45 chain links turn to another axis or side; forbidding chains leaves none.
  EXPECT_EQ(ja["empty_chain_links"].get<int>(), 45);
  EXPECT_EQ(ja["mergeable_chain_links"].get<int>(), 0);
  const CmdResult c = run("builtin:room --json --set kd.empty_chains=2");
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_EQ(json::parse(c.out)["kdtree"]["bottom"]["empty_chain_links"].get<int>(), 0);
  expect_one_line_error("builtin:room --set threads=4", "unknown --set key 'threads'");
  expect_one_line_error("builtin:room --set kd.max_depth=-3", "bad --set kd.max_depth=-3");
}

// Each bottom tree records the K_T it was built with and its expected unit cycles per packet: the
// configured K_T without the objective, a rung of the ladder with it (the room's tree leans to
// the transformation unit, so the walk goes to cheaper steps). The top level keeps the plain SAH
// and has no such record.
TEST_F(SceneCmd, BottomTreesRecordTheObjectivesChoice) {
  const CmdResult a = run("builtin:room --json");
  const CmdResult b = run("builtin:room --json --set kd.objective=1");
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_EQ(b.status, 0) << b.err;
  const json ja = json::parse(a.out)["kdtree"];
  const json jb = json::parse(b.out)["kdtree"];
  EXPECT_FALSE(ja["top"].contains("traversal_cost"));
  EXPECT_FALSE(ja["top"].contains("expected_unit_cycles"));
  const json& oa = ja["bottom"]["objects"][0];
  const json& ob = jb["bottom"]["objects"][0];
  EXPECT_EQ(oa["traversal_cost"].get<double>(), 30.0);
  const json& ua = oa["expected_unit_cycles"];
  EXPECT_GT(ua["transformation"].get<double>(), ua["traversal"].get<double>());
  // P + 1 transformation and P intersection cycles per list entry of a 4-ray packet.
  EXPECT_NEAR(ua["transformation"].get<double>(), 5.0 * ua["list"].get<double>(), 1e-9);
  EXPECT_NEAR(ua["intersection"].get<double>(), 4.0 * ua["list"].get<double>(), 1e-9);
  const double kt = ob["traversal_cost"].get<double>();
  EXPECT_LT(kt, 30.0);
  const std::vector<float> ladder = saarcor::host::kd_objective_ladder(30.0f);
  EXPECT_NE(std::find(ladder.begin(), ladder.end(), static_cast<float>(kt)), ladder.end()) << kt;
  const json& ub = ob["expected_unit_cycles"];
  EXPECT_LT(std::max(ub["traversal"].get<double>(), ub["transformation"].get<double>()),
            ua["transformation"].get<double>());
}

TEST_F(SceneCmd, TextReportNamesEveryFigure) {
  const CmdResult r = run(kScenes + "/SimpleMeshes/SimpleMeshes.gltf");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* line :
       {"triangles           2 after instancing, 1 unique", "objects             1",
        "instances           2 (0 dynamic)", "lights              1 (default light)",
        "cameras             0 (default framing)", "kd-tree top", "kd-tree bottom",
        "bytes per bank"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << "\n" << r.out;
}

TEST_F(SceneCmd, CamerasAreListedByTheIndexImageCameraTakes) {
  const CmdResult text = run("builtin:suncor");
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("cameras             3: 0 field, 1 above, 2 heads\n"), std::string::npos)
      << text.out;
  const CmdResult r = run("builtin:room --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["camera_names"], json::array({"door"}));
}

TEST_F(SceneCmd, TimeMovesTheAnimatedInstances) {
  const std::string box = kScenes + "/BoxAnimated/BoxAnimated.glb";
  const CmdResult r = run(box + " --time 1.875 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_NEAR(j["animation_seconds"].get<double>(), 3.70833, 1e-5);
  EXPECT_EQ(j["time"], 1.875);
  EXPECT_EQ(j["dynamic_instances"], 1);
  EXPECT_EQ(j["triangles"], 254);
}

TEST_F(SceneCmd, ExportThenReload) {
  const std::string out = (dir_ / "dynamic.glb").string();
  const CmdResult a = run("builtin:dynamic --json --export " + out);
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_TRUE(fs::exists(out));
  const CmdResult b = run(out + " --json");
  ASSERT_EQ(b.status, 0) << b.err;
  const json ja = json::parse(a.out), jb = json::parse(b.out);
  for (const char* key :
       {"triangles", "unique_triangles", "objects", "instances", "dynamic_instances", "lights",
        "cameras", "animation_seconds", "dropped_triangles"})
    EXPECT_EQ(ja[key], jb[key]) << key;
  EXPECT_EQ(ja["triangles"], 52790);
  EXPECT_EQ(ja["bytes_per_bank"], jb["bytes_per_bank"]);
  // .gltf with embedded buffers works too.
  const std::string gltf = (dir_ / "room.gltf").string();
  ASSERT_EQ(run("builtin:room --export " + gltf).status, 0);
  const json jr = json::parse(run(gltf + " --json").out);
  EXPECT_EQ(jr["triangles"], 806);
}

TEST_F(SceneCmd, ImageThatDoesNotFitStillReportsTheTrees) {
  const CmdResult r = run("builtin:room --json --bank-mb 0.01");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_TRUE(j["bytes_per_bank"].is_null());
  EXPECT_NE(j["image_error"].get<std::string>().find("does not fit"), std::string::npos)
      << j["image_error"];
  EXPECT_GT(j["kdtree"]["bottom"]["nodes"].get<int>(), 1);
}

// --write-image: the file holds the image build_image makes of the same scene, word for word;
// an image that does not build or a path that cannot be written is one line.
TEST_F(SceneCmd, WriteImageHoldsTheBuiltImage) {
  const std::string path = (dir_ / "room.img").string();
  const CmdResult r = run("builtin:room --write-image " + path);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("image file          " + path), std::string::npos) << r.out;
  const saarcor::memif::MemoryImage read = saarcor::memif::read_image_file(path);
  const saarcor::host::BuiltImage built =
      saarcor::host::build_image(saarcor::host::load_scene("builtin:room"));
  for (int b = 0; b < saarcor::memif::kNumBanks; ++b)
    EXPECT_EQ(read.bank(b), built.image.bank(b)) << "bank " << b;
  EXPECT_EQ(read.regions().count, built.image.regions().count);
  EXPECT_EQ(read.registers().cam_d, built.image.registers().cam_d);
  EXPECT_EQ(read.registers().instance_count, built.image.registers().instance_count);
  expect_one_line_error("builtin:room --bank-mb 0.01 --write-image " + path,
                        "--write-image: the memory image does not build");
  expect_one_line_error("builtin:room --write-image " + (dir_ / "absent" / "x.img").string(),
                        "cannot open for writing");
}

TEST_F(SceneCmd, BadInputsExitNonZeroWithOneLine) {
  expect_one_line_error((dir_ / "absent.gltf").string(), "absent.gltf: no such file");
  expect_one_line_error(write("bad.gltf", "{ \"asset\": "), "cannot load glTF");
  expect_one_line_error(
      write("nobuf.gltf",
            R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":12,"uri":"gone.bin"}]})"),
      "gone.bin");
  expect_one_line_error(
      write("noimg.gltf", R"({"asset":{"version":"2.0"},"images":[{"uri":"gone.png"}]})"),
      "image file missing or unreadable");
  // A triangle whose vertex 1 has y = NaN (the buffer is embedded as base64).
  expect_one_line_error(
      write(
          "nan.gltf",
          R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
          R"("meshes":[{"name":"probe","primitives":[{"attributes":{"POSITION":0}}]}],)"
          R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
          R"("bufferViews":[{"buffer":0,"byteLength":36}],"buffers":[{"byteLength":36,"uri":)"
          R"("data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAwH8AAAAAAAAAAAAAgD8AAAAA"}]})"),
      "mesh 0 'probe': accessor 0 (POSITION) has a non-finite value at vertex 1");
  expect_one_line_error("builtin:nope", "unknown built-in scene");
  expect_one_line_error("builtin:room --time -1", "--time");
  expect_one_line_error("builtin:room --bank-mb 0", "--bank-mb");
  const std::string unwritable = (dir_ / "no_such_dir" / "x.glb").string();
  expect_one_line_error("builtin:cube --export " + unwritable, "cannot write");
  EXPECT_FALSE(fs::exists(unwritable));
  EXPECT_FALSE(fs::exists(unwritable + ".partial"));
}

}  // namespace
