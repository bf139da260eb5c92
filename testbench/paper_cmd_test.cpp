// `saarcor paper` (testbench/paper_cmd.h): the paper's rows, the model's rows beside them, the
// ratios, the reference models, the outputs and bad input.
#include "testbench/paper_cmd.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "testbench/cycle_render.h"
#include "testbench/report.h"
#include "testbench/testing.h"

namespace saarcor {
namespace {

using test_support::error_of;

TEST(Paper, TablesHoldThePapersFigures) {
  const Table3Row* s6 = paper_table3_row("Scene6");
  ASSERT_NE(s6, nullptr);
  EXPECT_EQ(s6->saarcor_fps, 60.8);
  EXPECT_EQ(s6->openrt_fps, 12.9);
  ASSERT_NE(paper_table3_row("SunCOR"), nullptr);
  EXPECT_EQ(paper_table3_row("SunCOR")->objects, 5622);
  EXPECT_EQ(paper_table3_row("Nope"), nullptr);
  // Table 4's Scene6 at 1024x768: 15.3 fps, so 90 MHz / (15.3 * 1024 * 768 / 4) = 29.92 cycles per
  // packet and 12.0 Mrays/s, the calibration figures.
  nlohmann::json cycle = {
      {"fps", 30.6},
      {"usage", {{"traversal", 1}, {"list", 2}, {"transformation", 3}, {"intersection", 4}}},
      {"cache_hit", {{"traversal", 5}, {"list", 6}, {"transformation", 7}}},
      {"bandwidth_mb_s", {{"dynrtc", 16}, {"shading", 200}, {"frame_buffer", 40}, {"total", 256}}},
      {"rgs", {{"shading_bytes_per_pixel", 33.5}}},
      {"cycles_per_packet", 30.0},
      {"rays_per_s", 12e6}};
  const std::vector<PaperFigure> f = paper_figures(4, "Scene6", cycle, 1024, 768);
  ASSERT_EQ(f.size(), 14u);
  EXPECT_STREQ(f[9].key, "mb_s_shading");
  EXPECT_EQ(f[9].model, 240);  // shading reads + frame-buffer writes, as the paper's column
  EXPECT_EQ(f[9].paper, 218);
  // 218 MB/s at 15.3 fps of 1024x768 pixels: 19.0 bytes per pixel.
  EXPECT_STREQ(f[13].key, "shading_bytes_per_pixel");
  EXPECT_EQ(f[13].model, 33.5);
  EXPECT_NEAR(f[13].paper, 218.0 * 1048576.0 / (15.3 * 1024 * 768), 1e-9);
  EXPECT_STREQ(f[0].key, "fps");
  EXPECT_DOUBLE_EQ(f[0].model, 30.6);  // at the table's resolution: 30.6 * 786432 / 786432
  EXPECT_EQ(f[0].paper, 15.3);
  EXPECT_STREQ(f[2].key, "usage_list");
  EXPECT_EQ(f[2].paper, 16);
  EXPECT_STREQ(f[8].key, "mb_s_dynrtc");
  EXPECT_EQ(f[8].paper, 8);
  EXPECT_STREQ(f[11].key, "cycles_per_packet");
  EXPECT_NEAR(f[11].paper, 29.92, 0.01);
  EXPECT_NEAR(f[12].paper, 12.03, 0.01);
  const std::vector<PaperFigure> t3 = paper_figures(3, "Scene6", cycle, 512, 384);
  ASSERT_EQ(t3.size(), 3u);
  EXPECT_EQ(t3[0].paper, 60.8);
  EXPECT_NEAR(t3[1].paper, 30.1, 0.05);
}

TEST(Paper, StandInsAndReferenceModels) {
  const std::vector<PaperScene> none = paper_scenes("");
  ASSERT_EQ(none.size(), 3u);
  EXPECT_EQ(none[0].paper, "Scene6");
  EXPECT_EQ(none[0].spec, "builtin:room");
  EXPECT_EQ(none[2].spec, "builtin:suncor");
  for (const PaperScene& s : none)
    EXPECT_FALSE(s.reference);
  const std::vector<PaperScene> all = paper_scenes(SAARCOR_SHARED_SCENES);
  ASSERT_EQ(all.size(), 6u);
  EXPECT_EQ(all[3].paper, "Office");
  EXPECT_TRUE(all[3].reference);
  EXPECT_TRUE(std::filesystem::exists(all[5].spec)) << all[5].spec;
  // render prints the Scene6 row for the room however it is named.
  EXPECT_NE(paper_row_for("builtin:room"), nullptr);
  EXPECT_NE(paper_row_for("scenes/room.glb"), nullptr);
  EXPECT_NE(paper_row_for("/somewhere/else/room.glb"), nullptr);
  EXPECT_EQ(paper_row_for("scenes/roomy.glb"), nullptr);
}

// The room at 1/16 of both tables' resolutions: the model's rows, the paper's and the ratios.
TEST(Paper, RoomRowsBesideThePapers) {
  PaperOptions o;
  o.scale = 16;
  o.scenes = {"Scene6"};
  const nlohmann::json r = run_paper_tables(o);
  ASSERT_EQ(r["entries"].size(), 2u);
  const nlohmann::json& t3 = r["entries"][0];
  const nlohmann::json& t4 = r["entries"][1];
  EXPECT_EQ(t3["table"], 3);
  EXPECT_EQ(t3["resolution"], "32x24");
  EXPECT_EQ(t4["resolution"], "64x48");
  EXPECT_EQ(t4["kind"], "stand-in");
  // fps at the paper's resolution: the frame's fps over 16 * 16.
  const double fps = t4["report"]["fps"].get<double>() / 256.0;
  EXPECT_DOUBLE_EQ(t4["figures"]["fps"]["model"].get<double>(), fps);
  EXPECT_DOUBLE_EQ(t4["figures"]["fps"]["ratio"].get<double>(), fps / 15.3);
  EXPECT_EQ(t4["figures"]["usage_transformation"]["paper"], 85.0);
  EXPECT_DOUBLE_EQ(t4["figures"]["usage_traversal"]["model"].get<double>(),
                   t4["report"]["usage"]["traversal"].get<double>());
  EXPECT_GT(t4["figures"]["cycles_per_packet"]["model"].get<double>(), 20.0);
  const std::string text = paper_text(r);
  EXPECT_NE(text.find("Table 3 (paper: 512x384"), std::string::npos) << text;
  EXPECT_NE(text.find("  model builtin:room"), std::string::npos) << text;
  EXPECT_NE(text.find("  ratio model/paper"), std::string::npos) << text;
  const std::string csv = paper_csv(r);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 3 + 14);
  // The paper's setting for Scene6: textures unfiltered, listed in the entry's configuration.
  EXPECT_EQ(t3["configuration"][0], "image.bilinear=0");
  EXPECT_NE(text.find("Scene6, unfiltered"), std::string::npos) << text;
  EXPECT_GT(t4["figures"]["shading_bytes_per_pixel"]["model"].get<double>(), 16.0);
  EXPECT_NE(csv.find("4,Scene6,builtin:room,stand-in,64x48,usage_list,"), std::string::npos);
}

// Scenes (and thread counts) rendered at once give the rows a serial run gives, in its order.
TEST(Paper, RowsAreTheSameOnAnyNumberOfJobs) {
  PaperOptions o;
  o.scale = 16;
  o.references = SAARCOR_SHARED_SCENES;
  o.scenes = {"Scene6", "Office"};
  o.jobs = 1;
  const nlohmann::json serial = run_paper_tables(o);
  o.jobs = 2;
  const nlohmann::json parallel = run_paper_tables(o);
  ASSERT_EQ(serial["entries"].size(), 4u);
  ASSERT_EQ(parallel["entries"].size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const nlohmann::json& a = serial["entries"][i];
    const nlohmann::json& b = parallel["entries"][i];
    EXPECT_EQ(a["scene"], b["scene"]) << i;
    EXPECT_EQ(a["table"], b["table"]) << i;
    EXPECT_EQ(a["figures"], b["figures"]) << i;
    EXPECT_EQ(a["report"]["cycles"], b["report"]["cycles"]) << i;
  }
  EXPECT_EQ(serial["entries"][2]["kind"], "reference");
  EXPECT_EQ(paper_text(serial), paper_text(parallel));
  EXPECT_EQ(paper_csv(serial), paper_csv(parallel));
  o.jobs = 1;
  const nlohmann::json curve = run_thread_curve(o);
  o.jobs = 3;
  EXPECT_EQ(thread_curve_text(curve), thread_curve_text(run_thread_curve(o)));
  o.jobs = -1;
  EXPECT_EQ(error_of([&] { run_paper_tables(o); }), "bad --jobs -1: 1 or more");
}

// The paper's filters: "all scenes use bilinear filtered textures, Scene6 and Office were rendered
// with unfiltered textures"; a filter the user sets wins for every scene.
TEST(Paper, EachSceneRendersWithThePapersTextureFilter) {
  PaperOptions o;
  o.set = {"threads=32"};
  EXPECT_EQ(paper_settings(o, "Scene6"),
            (std::vector<std::string>{"image.bilinear=0", "threads=32"}));
  EXPECT_EQ(paper_settings(o, "Office"),
            (std::vector<std::string>{"image.bilinear=0", "threads=32"}));
  EXPECT_EQ(paper_settings(o, "Terrain"),
            (std::vector<std::string>{"image.bilinear=1", "threads=32"}));
  EXPECT_EQ(paper_settings(o, "SunCOR"),
            (std::vector<std::string>{"image.bilinear=1", "threads=32"}));
  o.set = {"image.bilinear=0"};
  EXPECT_EQ(paper_settings(o, "Terrain"), (std::vector<std::string>{"image.bilinear=0"}));
}

// The thread curve: seven frames, speed-ups over one thread, and the paper's doubling steps.
TEST(Paper, ThreadCurveBesideThePapers) {
  PaperOptions o;
  o.scale = 16;
  const nlohmann::json c = run_thread_curve(o);
  ASSERT_EQ(c["rows"].size(), 7u);
  EXPECT_EQ(c["resolution"], "32x24");
  const nlohmann::json& rows = c["rows"];
  EXPECT_EQ(rows[0]["speedup"], 1.0);
  // One thread to two: latency-bound, so close to twice as fast.
  EXPECT_GT(rows[1]["step"].get<double>(), 1.8);
  EXPECT_EQ(rows[5]["paper_step"], 2.0);   // 16 -> 32 threads
  EXPECT_EQ(rows[6]["paper_step"], 1.10);  // 32 -> 64
  EXPECT_DOUBLE_EQ(rows[6]["ratio"].get<double>(), rows[6]["step"].get<double>() / 1.10);
  EXPECT_DOUBLE_EQ(rows[6]["speedup"].get<double>(),
                   rows[6]["fps"].get<double>() / rows[0]["fps"].get<double>());
  const std::string text = thread_curve_text(c);
  EXPECT_NE(text.find("nearly linear speed-up up to 32 threads"), std::string::npos) << text;
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2 + 7);
}

TEST(Paper, BadInputFailsBeforeAnyFrame) {
  PaperOptions o;
  o.table = 5;
  EXPECT_EQ(error_of([&] { run_paper_tables(o); }), "bad --table 5: 3 or 4");
  o = {};
  o.scale = 0;
  EXPECT_EQ(error_of([&] { run_paper_tables(o); }), "bad --scale 0: 1..64");
  o = {};
  o.references = "";
  o.scenes = {"Castle"};
  EXPECT_EQ(error_of([&] { run_paper_tables(o); }),
            "bad --scene Castle: the paper scenes shown are Scene6, Terrain, SunCOR");
  o = {};
  o.csv = "rows.txt";
  EXPECT_EQ(error_of([&] { run_paper_tables(o); }),
            "bad --csv 'rows.txt': expected a .csv file name");
  o = {};
  o.set = {"threads=0"};
  EXPECT_NE(error_of([&] { run_paper_tables(o); }).find("threads"), std::string::npos);
}

TEST(Paper, TheCommandWritesItsFiles) {
  const std::filesystem::path d = test_support::scratch_dir("paper");
  const std::string csv = (d / "rows.csv").string(), json = (d / "rows.json").string();
  const test_support::CliRun r = test_support::run_saarcor(
      "paper --table 4 --scale 16 --scene Scene6 --csv " + csv + " --json " + json);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;  // no progress when stderr is not a terminal
  EXPECT_NE(r.out.find("Table 4 (paper: 1024x768"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("Table 3"), std::string::npos) << r.out;
  std::ifstream f(json);
  const nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_EQ(j["entries"].size(), 1u);
  test_support::expect_one_line_error(test_support::run_saarcor("paper --scale 100"),
                                      "bad --scale 100");
}

}  // namespace
}  // namespace saarcor
