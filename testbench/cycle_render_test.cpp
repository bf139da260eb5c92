// `saarcor render --model cycle` (testbench/cycle_render.h): the report's keys and figures, the
// VCD, the Table 4 printout, hit records equal to the fp24 model's, and every class of bad input.
#include "testbench/cycle_render.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "testbench/render_cmd.h"
#include "testbench/testing.h"

namespace saarcor {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
  return test_support::scratch_dir("cycle");
}

std::string read(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

void expect_error(const RenderOptions& o, const std::string& needle) {
  try {
    run_render(o);
    ADD_FAILURE() << "accepted; expected an error with '" << needle << "'";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(needle), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

// The room at 32x24 through the cycle model, image and report as d/name.png, d/name.json.
RenderOptions room_cycle(const fs::path& d, const std::string& name) {
  RenderOptions o;
  o.scene = "builtin:room";
  o.model = "cycle";
  o.res = "32x24";
  o.out = (d / name).string();
  o.report = (d / (name + ".json")).string();
  return o;
}

TEST(CycleRender, ReportVcdAndTable) {
  const fs::path d = temp_dir();
  RenderOptions o = room_cycle(d, "room");
  o.cycle.set = {"threads=16", "lat.div=12"};
  o.cycle.interval = 2000;
  o.cycle.vcd = (d / "room.vcd").string();
  o.cycle.vcd_from = 100;
  o.cycle.vcd_to = 200;
  o.cycle.host_threads = 1;  // the programs on the simulation's thread (the report says so)
  testing::internal::CaptureStdout();
  EXPECT_EQ(run_render(o), 0);
  const std::string out = testing::internal::GetCapturedStdout();
  EXPECT_NE(out.find("paper Scene6"), std::string::npos) << out;
  EXPECT_NE(out.find("the paper's fps scaled to this frame's"), std::string::npos) << out;
  EXPECT_NE(out.find("model builtin:room"), std::string::npos) << out;
  const auto j = nlohmann::json::parse(read(d / "room.json"));
  for (const char* k : {"cycles", "fps", "rays", "rays_per_s", "usage", "cache_hit",
                        "bandwidth_mb_s", "per_ray", "simd_efficiency", "host", "time_series"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["rays"].get<int>(), 32 * 24);
  EXPECT_GT(j["cycles"].get<double>(), 0);
  EXPECT_NEAR(j["fps"].get<double>(), 90e6 / j["cycles"].get<double>(), 1e-6);
  for (const char* u : {"traversal", "list", "transformation", "intersection"}) {
    EXPECT_GT(j["usage"][u].get<double>(), 0.0) << u;
    EXPECT_LE(j["usage"][u].get<double>(), 100.0) << u;
  }
  EXPECT_EQ(j["configuration"]["cycle"]["threads"]["value"].get<int>(), 16);
  EXPECT_EQ(j["configuration"]["cycle"]["lat.div"]["value"].get<int>(), 12);
  EXPECT_EQ(j["configuration"]["cycle"]["depth.traversal"].get<int>(), 3 + 12 + 1);
  EXPECT_GE(j["time_series"].size(), 2u);
  EXPECT_EQ(j["host"]["threads"].get<int>(), 1);
  EXPECT_EQ(j["host"]["programs"].get<std::string>(), "packet-first");
  EXPECT_EQ(j["stats"]["dynrtp0.transformation.issue_cycles"]["value"].get<double>(),
            j["units"]["transformation"]["issue_cycles"].get<double>());
  EXPECT_TRUE(j["stats"].contains("dynrtp0.node_cache.hit_rate_with_merges"));
  const std::string vcd = read(d / "room.vcd");
  EXPECT_NE(vcd.find("$enddefinitions"), std::string::npos);
  EXPECT_NE(vcd.find("path_a"), std::string::npos);
  EXPECT_NE(vcd.find("#100"), std::string::npos);
  fs::remove_all(d);
}

// --preset standard: four DynRTPs; the report lists each with its packets and usage, the
// top-level usage is their mean, the printout says how the packets spread.
TEST(CycleRender, StandardPresetReportsEveryPipeline) {
  const fs::path d = temp_dir();
  RenderOptions o = room_cycle(d, "std");
  o.cycle.preset = "standard";
  testing::internal::CaptureStdout();
  EXPECT_EQ(run_render(o), 0);
  const std::string out = testing::internal::GetCapturedStdout();
  EXPECT_NE(out.find("4 DynRTPs (usage: the mean over them"), std::string::npos) << out;
  const auto j = nlohmann::json::parse(read(d / "std.json"));
  EXPECT_EQ(j["configuration"]["cycle"]["pipelines"]["value"].get<int>(), 4);
  ASSERT_EQ(j["pipelines"].size(), 4u);
  double packets = 0, traversal = 0;
  for (const auto& p : j["pipelines"]) {
    EXPECT_GT(p["packets"].get<double>(), 0.0);
    packets += p["packets"].get<double>();
    traversal += p["usage"]["traversal"].get<double>();
  }
  EXPECT_EQ(packets, j["packets"].get<double>());
  EXPECT_NEAR(traversal / 4, j["usage"]["traversal"].get<double>(), 1e-9);
  EXPECT_TRUE(j["stats"].contains("dynrtp3.node_cache.hit_rate_with_merges"));
  fs::remove_all(d);
}

// --model cycle-e7m23 builds the image in e7m23 and equals the functional model in e7m23.
TEST(CycleRender, WideModelHitsEqualTheE7m23Model) {
  RenderSettings s;
  s.res = {24, 16};
  const PreparedScene prep = prepare_scene("builtin:dynamic", s, ff::Format{7, 23});
  const FrameResult c = render_model(parse_model("cycle-e7m23"), prep, s);
  const FrameResult f = render_model(parse_model("e7m23"), prep, s);
  EXPECT_EQ(c.hits.pixels, f.hits.pixels);
  EXPECT_EQ(c.image.rgb, f.image.rgb);
  EXPECT_EQ(test_support::error_of([&] {
              render_model(parse_model("cycle"), prep, s);
            }).rfind("model cycle needs", 0),
            0u);
}

TEST(CycleRender, HitsEqualTheFp24Model) {
  RenderSettings s;
  s.res = {24, 16};
  const PreparedScene prep = prepare_scene("builtin:cube", s);
  s.cycle.set = {"threads=3", "packet=16"};
  const FrameResult c = render_model(parse_model("cycle"), prep, s);
  const FrameResult f = render_model(parse_model("fp24"), prep, s);
  EXPECT_EQ(c.hits.pixels, f.hits.pixels);
  EXPECT_EQ(c.image.rgb, f.image.rgb);
  EXPECT_EQ(trace_pixel(parse_model("cycle"), prep, s, {5, 7}), f.hits.pixels[7 * 24 + 5]);
}

TEST(CycleRender, BadInput) {
  const fs::path d = temp_dir();
  RenderOptions o;
  o.scene = "builtin:cube";
  o.model = "cycle";
  o.res = "16x12";
  o.out = (d / "x").string();
  RenderOptions bad = o;
  bad.cycle.set = {"threads=0"};
  expect_error(bad, "threads");
  bad = o;
  bad.cycle.set = {"cache.traversal.items=12"};
  expect_error(bad, "cache.traversal.items");
  bad = o;
  bad.cycle.set = {"warp=9"};
  expect_error(bad, "unknown --set key 'warp'");
  bad = o;
  bad.cycle.preset = "asic";
  expect_error(bad, "unknown --preset 'asic'");
  bad = o;
  bad.model = "fp24";
  bad.cycle.set = {"threads=4"};
  expect_error(bad, "--model cycle only");
  bad = o;
  bad.cycle.vcd = (d / "t.vcd").string();
  bad.cycle.vcd_from = 50;
  bad.cycle.vcd_to = 10;
  expect_error(bad, "--vcd-to");
  bad = o;
  bad.cycle.host_threads = 3;
  expect_error(bad, "bad --host-threads 3");
  bad = o;
  bad.model = "fp24";
  bad.cycle.host_threads = 1;
  expect_error(bad, "--model cycle only");
  bad = o;
  bad.cycle.vcd = (d / "no" / "such" / "dir" / "t.vcd").string();
  expect_error(bad, "cannot write --vcd");
  // A watchdog stop leaves no partial VCD.
  bad = o;
  bad.cycle.vcd = (d / "w.vcd").string();
  bad.cycle.set = {"watchdog=5", "mem.latency=300"};
  try {
    run_render(bad);
    ADD_FAILURE() << "the watchdog did not fire";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("watchdog"), std::string::npos);
  }
  EXPECT_FALSE(fs::exists(d / "w.vcd"));
  fs::remove_all(d);
}

}  // namespace
}  // namespace saarcor
