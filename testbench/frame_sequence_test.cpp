// Frame sequences (docs/frames.md): per-frame top-level rebuilds, uploads over the host bus while
// the previous frame renders, frame-buffer swaps, every cycle-model frame bit for bit the
// functional model's (run_sequence throws otherwise), and the command's bad input.
#include "testbench/frame_sequence.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "host/frame_upload.h"
#include "testbench/testing.h"

namespace saarcor {
namespace {

namespace fs = std::filesystem;
using test_support::error_of;
using test_support::expect_one_line_error;
using test_support::run_saarcor;
using test_support::scratch_dir;

std::string shared(const std::string& rel) {
  return std::string(SAARCOR_SHARED_SCENES) + "/" + rel;
}

RenderSettings small(int w, int h) {
  RenderSettings s;
  s.res = {w, h};
  s.heartbeat = false;
  return s;
}

SequenceOptions frames(int n) {
  SequenceOptions o;
  o.frames = n;
  return o;
}

// What holds for every sequence: banks and copies alternate as documented, the timeline adds up,
// bottom-level trees are built for frame 0 only, and an upload is its SRAM words plus the
// registers.
void expect_sequence_invariants(const SequenceResult& r, bool checked = true) {
  const std::uint64_t registers = sizeof(memif::FrameRegisters) + sizeof(memif::SceneRegions);
  for (std::size_t k = 0; k < r.frames.size(); ++k) {
    const SequenceFrame& f = r.frames[k];
    SCOPED_TRACE("frame " + std::to_string(k));
    EXPECT_EQ(f.index, static_cast<int>(k));
    EXPECT_EQ(f.frame_bank, k % 2 == 0 ? memif::kFrameBank0 : memif::kFrameBank1);
    if (r.cycle) {
      EXPECT_EQ(f.checked, checked);
    }
    if (k == 0) {
      EXPECT_EQ(f.top_level_builds, 1u);
      EXPECT_GT(f.bottom_level_builds, 0u);
      continue;
    }
    EXPECT_EQ(f.bottom_level_builds, 0u);
    EXPECT_EQ(f.top_level_builds, f.top_rebuilt ? 1u : 0u);
    EXPECT_EQ(f.upload_bytes, 4 * f.upload_words + registers);
    const SequenceFrame& p = r.frames[k - 1];
    if (!r.frame_gap) {
      EXPECT_EQ(f.top_copy, f.top_rebuilt ? 1 - p.top_copy : p.top_copy);
    }
    if (!r.cycle) continue;
    EXPECT_EQ(f.start_cycle, p.start_cycle + std::max(p.cycles, f.upload_cycles));
    EXPECT_EQ(f.stall_cycles, f.start_cycle - p.start_cycle - p.cycles);
    EXPECT_EQ(f.hidden, !f.gap && f.upload_cycles <= p.cycles);
    EXPECT_GT(f.upload_cycles, 0u);
  }
}

TEST(FrameSequence, DynamicSceneUploadsDuringThePreviousFrame) {
  const SequenceResult r =
      run_sequence("builtin:dynamic", parse_model("cycle"), small(32, 24), frames(4));
  expect_sequence_invariants(r);
  ASSERT_EQ(r.frames.size(), 4u);
  EXPECT_EQ(r.dynamic_instances, 16u);
  EXPECT_NEAR(r.dt, 10.0 / 4, 1e-12);  // the animation's 10 s spread over the frames
  std::set<std::uint64_t> digests;
  for (const SequenceFrame& f : r.frames) {
    digests.insert(f.digest);
    if (f.index == 0) continue;
    EXPECT_EQ(f.moved_instances, 16u);
    EXPECT_TRUE(f.top_rebuilt);
    EXPECT_FALSE(f.gap);
    EXPECT_TRUE(f.hidden);  // ~1.5 KB at 132 MB/s: about a thousand cycles of a 50K-cycle frame
    EXPECT_EQ(f.stall_cycles, 0u);
    EXPECT_GT(f.upload_words, 100u);
    EXPECT_LT(f.upload_bytes, 4000u);
    EXPECT_EQ(f.top_copy, f.index % 2);
  }
  EXPECT_EQ(digests.size(), 4u);  // the movers move
  EXPECT_EQ(r.hidden_uploads(), 3);
  EXPECT_EQ(r.total_cycles(), r.frames[3].start_cycle + r.frames[3].cycles);
  EXPECT_NEAR(r.fps(), r.render_fps(), 1e-9);  // nothing stalled
  EXPECT_GT(r.initial_load_bytes, 2u << 20);   // the 2.5 MB of scene data plus shading
  EXPECT_GT(r.initial_load_cycles, 0u);
  // The same frames from the functional model: the images do not depend on the timing.
  const SequenceResult f =
      run_sequence("builtin:dynamic", parse_model("fp24"), small(32, 24), frames(4));
  expect_sequence_invariants(f);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(f.frames[k].digest, r.frames[k].digest);
    EXPECT_EQ(f.frames[k].upload_bytes, r.frames[k].upload_bytes);
  }
}

// The animated glTF models over 30 frames; BoxAnimated's first top level is one leaf, so
// its reserved slots overflow when the box lifts off: that frame's upload is a relayout and waits
// for the frame in flight (a gap), the others are hidden.
TEST(FrameSequence, AnimatedGltfModelsThirtyFrames) {
  struct Case {
    const char* file;
    int gaps;
  };
  for (const Case& c :
       {Case{"BoxAnimated/BoxAnimated.gltf", 1}, Case{"AnimatedCube/AnimatedCube.gltf", 0},
        Case{"CesiumMilkTruck/CesiumMilkTruck.gltf", 0}}) {
    SCOPED_TRACE(c.file);
    const SequenceResult r =
        run_sequence(shared(c.file), parse_model("cycle"), small(16, 12), frames(30));
    expect_sequence_invariants(r);
    EXPECT_EQ(r.gaps(), c.gaps);
    EXPECT_EQ(r.hidden_uploads(), 29 - c.gaps);
    std::set<std::uint64_t> digests;
    for (const SequenceFrame& f : r.frames) {
      digests.insert(f.digest);
      if (f.index > 0) {
        EXPECT_GT(f.moved_instances, 0u);
      }
    }
    EXPECT_GT(digests.size(), 10u);  // visibly moving
  }
}

// Frame k after k incremental uploads into alternating top-level copies is the frame a fresh
// image built at t_k gives (primary rays: the epsilon a sequence keeps from frame 0 plays no part).
TEST(FrameSequence, EachFrameEqualsAFreshRenderAtItsTime) {
  std::vector<Rgb8Image> images;
  const SequenceResult r =
      run_sequence("builtin:dynamic", parse_model("fp24"), small(32, 24), frames(4),
                   [&](const SequenceFrame&, const Rgb8Image& image) { images.push_back(image); });
  ASSERT_EQ(images.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    RenderSettings s = small(32, 24);
    s.time = r.frames[k].time;
    const FrameResult fresh =
        render_model(parse_model("fp24"), prepare_scene("builtin:dynamic", s), s);
    EXPECT_EQ(fresh.image.rgb, images[k].rgb) << "frame " << k;
  }
}

// Every one of SunCOR's 5,622 instances moves every frame: the whole top level and every matrix
// change, and the frames stay bit for bit the functional model's (this is where suncor-wind's
// cycle-model frames are checked in CI; DynRtc's scene cases leave it to this test).
TEST(FrameSequence, SuncorWindEveryInstanceMovesEveryFrame) {
  const SequenceResult r =
      run_sequence("builtin:suncor-wind", parse_model("cycle"), small(16, 12), frames(3));
  expect_sequence_invariants(r);
  for (std::size_t k = 1; k < 3; ++k) {
    EXPECT_EQ(r.frames[k].moved_instances, 5622u);
    EXPECT_GT(r.frames[k].upload_words * 4, 5622u * 36u);  // every matrix and the tree
  }
  EXPECT_GT(r.top_copy_bytes, 1u << 20);
}

TEST(FrameSequence, StaticSceneUploadsOnlyTheRegisters) {
  const SequenceResult r =
      run_sequence("builtin:room", parse_model("cycle"), small(16, 12), frames(3));
  expect_sequence_invariants(r);
  for (const SequenceFrame& f : r.frames) {
    EXPECT_EQ(f.digest, r.frames[0].digest);
    EXPECT_EQ(f.top_copy, 0);
    if (f.index == 0) continue;
    EXPECT_FALSE(f.top_rebuilt);
    EXPECT_EQ(f.upload_words, 0u);
    EXPECT_EQ(f.moved_instances, 0u);
  }
}

TEST(FrameSequence, FrameGapModeDelaysEveryFrameAndChangesNoImage) {
  SequenceOptions o = frames(3);
  const SequenceResult two =
      run_sequence("builtin:dynamic", parse_model("cycle"), small(32, 24), o);
  o.frame_gap = true;
  const SequenceResult one =
      run_sequence("builtin:dynamic", parse_model("cycle"), small(32, 24), o);
  expect_sequence_invariants(one);
  EXPECT_EQ(one.gaps(), 2);
  EXPECT_EQ(one.hidden_uploads(), 0);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(one.frames[k].digest, two.frames[k].digest);
    EXPECT_EQ(one.frames[k].top_copy, 0);
    if (k > 0) {
      EXPECT_GT(one.frames[k].stall_cycles, 0u);
    }
  }
  // The gaps add the stalls to the sequence; the frames' render times themselves differ between
  // one top-level copy and two (the copy's place in the scene banks changes the caches' hits:
  // up to 6 % per frame at 32x24, more than the stalls since the node bound reshaped the arena's
  // tree), so the time outside rendering is compared.
  auto idle = [](const SequenceResult& r) {
    std::uint64_t render = 0;
    for (const SequenceFrame& f : r.frames)
      render += f.cycles;
    return r.total_cycles() - render;
  };
  EXPECT_EQ(idle(two), 0u);
  EXPECT_GT(idle(one), 0u);
}

TEST(FrameSequence, AWriteIntoTheFrameInFlightIsRefused) {
  RenderSettings s = small(16, 12);
  s.top_level_buffers = 2;
  PreparedScene p = prepare_scene("builtin:dynamic", s);
  memif::MemoryImage board = p.built.image;
  memif::HostUpload u;
  u.frame_reads = host::frame_reads(p.built, memif::kFrameBank0);
  // The root node of the top-level copy the registers name: what every packet reads first.
  const memif::WordLocation root = board.locate(memif::ItemType::kNode, board.registers().top_root);
  u.runs.push_back({root.bank, root.offset, {0xFFFFFFFFu}});
  const std::string e =
      error_of([&] { run_cycle(board, resolve_cycle_params(s.cycle), CycleRunOptions{}, u); });
  EXPECT_NE(e.find("overlaps kd-nodes"), std::string::npos) << e;
  EXPECT_NE(e.find("which the frame in flight reads"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  // The other copy's root is free to write, and the word arrives.
  const memif::WordLocation other = board.locate(memif::ItemType::kNode, p.built.top_node_capacity);
  u.runs = {{other.bank, other.offset, {0x12345678u}}};
  const CycleFrame f = run_cycle(board, resolve_cycle_params(s.cycle), CycleRunOptions{}, u);
  EXPECT_EQ(board.word(other.bank, other.offset), 0x12345678u);
  EXPECT_EQ(f.upload_bytes, 4u);
  EXPECT_GT(f.upload_cycles, 0u);
  EXPECT_LT(f.upload_cycles, f.cycles);
}

TEST(FrameSequence, BusSweepShowsWhereUploadsStopFitting) {
  const std::vector<SequenceResult> points = run_bus_sweep(
      "builtin:dynamic", parse_model("cycle"), small(16, 12), frames(3), {132.0, 0.5, 0.02});
  ASSERT_EQ(points.size(), 3u);
  EXPECT_EQ(points[0].hidden_uploads(), 2);
  EXPECT_EQ(points[2].hidden_uploads(), 0);
  for (std::size_t i = 0; i < points.size(); ++i)  // the first point checked, the others by digest
    expect_sequence_invariants(points[i], i == 0);
  EXPECT_DOUBLE_EQ(points[0].bus_mb_s, 132.0);
  EXPECT_GE(points[0].fps(), points[1].fps());
  EXPECT_GT(points[1].fps(), points[2].fps());
  EXPECT_GT(points[2].frames[1].stall_cycles, 0u);
  // Where they stop fitting agrees with the bytes over the render time.
  const double be = points[0].break_even_mb_s();
  EXPECT_GT(be, 0.02);
  EXPECT_LT(be, 132.0);
  const std::string table = bus_sweep_table(points);
  EXPECT_NE(table.find("2 of 2"), std::string::npos) << table;
  EXPECT_NE(table.find("0 of 2"), std::string::npos) << table;
  EXPECT_EQ(bus_sweep_json(points).size(), 3u);
}

// The CI version of the BART runs (docs/bart.md has the 20 frames at 512x384): a few frames at a
// small resolution, every one bit for bit the functional model's. (At 32x24 the kitchen's second
// upload, 49 KB, no longer fits behind a 22K-cycle frame: docs/bart.md.)
TEST(FrameSequence, BartKitchenAndRobotsFewFrames) {
  struct Case {
    const char* file;
    std::uint32_t moving;
  };
  for (const Case& c :
       {Case{"BART/kitchen/aff/kitchen.aff", 86}, Case{"BART/robot/aff/Robot.aff", 220}}) {
    SCOPED_TRACE(c.file);
    const SequenceResult r =
        run_sequence(shared(c.file), parse_model("cycle"), small(64, 48), frames(3));
    expect_sequence_invariants(r);
    EXPECT_EQ(r.hidden_uploads(), 2);
    for (std::size_t k = 1; k < 3; ++k) {
      EXPECT_EQ(r.frames[k].moved_instances, c.moving);
    }
  }
}

TEST(FrameSequenceArgs, BusSweepList) {
  EXPECT_EQ(parse_bus_sweep("1,8.5,132"), (std::vector<double>{1.0, 8.5, 132.0}));
  for (const char* bad : {"", "1,,2", "1,", "x", "0", "-3", "1e7", "2,2", "nan"})
    EXPECT_NE(error_of([&] { parse_bus_sweep(bad); }).find("bad --bus-sweep"), std::string::npos)
        << bad;
}

TEST(FrameSequenceArgs, BadOptionsAreOneLineErrors) {
  const std::string dyn = "render builtin:dynamic --res 8x6 ";
  expect_one_line_error(run_saarcor(dyn + "--frames 0"), "bad --frames 0: expected 1..10000");
  expect_one_line_error(run_saarcor(dyn + "--frames 20000"), "bad --frames 20000");
  expect_one_line_error(run_saarcor(dyn + "--frames 2 --fps 30 --dt 0.1"),
                        "give --fps or --dt, not both");
  expect_one_line_error(run_saarcor(dyn + "--frames 2 --fps 0"), "bad --fps");
  expect_one_line_error(run_saarcor(dyn + "--frames 2 --dt -1"), "bad --dt");
  expect_one_line_error(run_saarcor(dyn + "--frames 2 --model float"),
                        "--frames needs a model that reads the memory image");
  expect_one_line_error(run_saarcor(dyn + "--frames 2 --bus-sweep 1,2"),
                        "--bus-sweep needs --model cycle");
  expect_one_line_error(run_saarcor(dyn + "--frames 2 --model cycle --bus-sweep 1,x"),
                        "bad --bus-sweep '1,x'");
  expect_one_line_error(run_saarcor(dyn + "--frames 2 --pixel 1,1"), "--pixel traces one frame");
  expect_one_line_error(run_saarcor(dyn + "--frames 2 --exr"), "--exr and --hits");
  expect_one_line_error(run_saarcor(dyn + "--fps 30"), "need --frames N");
  expect_one_line_error(run_saarcor(dyn + "--frame-gap"), "need --frames N");
  expect_one_line_error(run_saarcor(dyn + "--frames 2 --model cycle --set hostbus.mb_s=0"),
                        "hostbus.mb_s");
  expect_one_line_error(run_saarcor(dyn + "--frames 2 --time -1"), "bad --time");
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// A bus sweep's run folder holds the files every run folder holds; its stats.txt has one block
// per bandwidth.
TEST(FrameSequenceCommand, BusSweepRunFolderHasItsStatistics) {
  const fs::path d = scratch_dir("frames_bus");
  fs::remove_all(d);
  const auto r = run_saarcor(
      "render builtin:dynamic --model cycle --res 16x12 --frames 2 --bus-sweep 1,132 --out-dir " +
      d.string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"report.json", "stats.txt", "config.json", "command.txt", "host.json"})
    EXPECT_TRUE(fs::exists(d / f)) << f;
  const std::string stats = slurp(d / "stats.txt");
  EXPECT_NE(stats.find("# host bus 1 MB/s\n"), std::string::npos) << stats.substr(0, 300);
  EXPECT_NE(stats.find("# host bus 132 MB/s\n"), std::string::npos);
  EXPECT_NE(stats.find("\nsequence.uploads_hidden "), std::string::npos);
  fs::remove_all(d);
}

TEST(FrameSequenceCommand, RunFolderHasNumberedFramesAndRerunsGiveTheSameBytes) {
  const fs::path d = scratch_dir("frames");
  const std::string args = "render builtin:dynamic --model cycle --res 16x12 --frames 3 ";
  const auto a = run_saarcor(args + "--out-dir " + (d / "a").string());
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_TRUE(a.err.empty()) << a.err;  // stderr is no terminal: no heartbeat
  EXPECT_NE(a.out.find("uploads hidden behind the previous frame: 2 of 2"), std::string::npos)
      << a.out;
  const auto b = run_saarcor(args + "--out-dir " + (d / "b").string());
  ASSERT_EQ(b.status, 0) << b.err;
  for (const char* f : {"frame_0000.png", "frame_0001.png", "frame_0002.png", "report.json",
                        "frames.csv", "stats.txt", "config.json"}) {
    ASSERT_TRUE(fs::exists(d / "a" / f)) << f;
    EXPECT_EQ(slurp(d / "a" / f), slurp(d / "b" / f)) << f;
  }
  EXPECT_FALSE(fs::exists(d / "a" / "frame_0003.png"));
  const nlohmann::json j = nlohmann::json::parse(slurp(d / "a" / "report.json"));
  ASSERT_EQ(j["per_frame"].size(), 3u);
  EXPECT_EQ(j["per_frame"][1]["frame_bank"], 1);
  EXPECT_EQ(j["per_frame"][2]["frame_bank"], 0);
  EXPECT_EQ(j["per_frame"][1]["bit_identical_to_functional_model"], true);
  EXPECT_EQ(j["summary"]["bottom_level_rebuilds"], 0);
  EXPECT_EQ(j["summary"]["uploads_hidden"], 2);
  EXPECT_FALSE(j.contains("host"));
  EXPECT_TRUE(nlohmann::json::parse(slurp(d / "a" / "host.json")).contains("per_frame"));
  // One row model (testbench/report.cpp kRowColumns): the JSON row, the CSV header and
  // stats.txt name the same columns; the RGS's bandwidth (reads plus frame-buffer writes) is
  // bandwidth_mb_s.rgs, the name units/figures.h gives it, never the render report's "shading"
  // (the reads alone).
  const nlohmann::json& row = j["per_frame"][1];
  EXPECT_TRUE(row["bandwidth_mb_s"].contains("rgs"));
  EXPECT_FALSE(row["bandwidth_mb_s"].contains("shading"));
  const std::string csv = slurp(d / "a" / "frames.csv");
  const std::string header = csv.substr(0, csv.find('\n'));
  EXPECT_NE(header.find(",bandwidth_mb_s_rgs,"), std::string::npos) << header;
  const std::string stats = slurp(d / "a" / "stats.txt");
  std::size_t columns = 0;
  for (const auto& [key, value] : row.items())
    columns += value.is_object() ? value.size() : 1;
  std::size_t frame1_lines = 0;
  std::istringstream in(stats);
  for (std::string line; std::getline(in, line);) {
    if (!line.starts_with("frame1.")) continue;
    ++frame1_lines;
    // Every line: "name  value  # description (unit)", both from the column's declaration.
    EXPECT_NE(line.find("  # "), std::string::npos) << line;
    EXPECT_EQ(line.back(), ')') << line;
  }
  EXPECT_EQ(frame1_lines, columns);
  EXPECT_NE(stats.find("\nframe1.bandwidth_mb_s.rgs "), std::string::npos);
  EXPECT_NE(stats.find("\nsequence.uploads_hidden "), std::string::npos);
  // --out PREFIX and --report without a folder; the fp24 model.
  const auto c = run_saarcor("render builtin:dynamic --res 8x6 --frames 2 --dt 0.5 --out " +
                             (d / "seq").string() + " --report " + (d / "seq.json").string());
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_TRUE(fs::exists(d / "seq_0000.png"));
  EXPECT_TRUE(fs::exists(d / "seq_0001.png"));
  const nlohmann::json k = nlohmann::json::parse(slurp(d / "seq.json"));
  EXPECT_DOUBLE_EQ(k["per_frame"][1]["time"].get<double>(), 0.5);
  EXPECT_FALSE(k["per_frame"][1].contains("cycles"));
  fs::remove_all(d);
}

}  // namespace
}  // namespace saarcor
