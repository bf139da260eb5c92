// `saarcor sweep`: the --vary grammar, the product of the axes and its checks before any frame
// runs, the frames (every point bit-identical to the functional fp24 model, the timing different),
// the table/CSV/JSON, and the binary end to end with its one-line errors and no partial files.
#include "testbench/sweep_cmd.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "testbench/testing.h"

namespace saarcor {
namespace {

namespace fs = std::filesystem;
using test_support::error_of;

TEST(SweepArgs, Axis) {
  const SweepAxis a = parse_sweep_axis("threads=1,2,64");
  EXPECT_EQ(a.key, "threads");
  EXPECT_EQ(a.values, (std::vector<std::string>{"1", "2", "64"}));
  EXPECT_EQ(parse_sweep_axis("lat.div=12").values, std::vector<std::string>{"12"});
  EXPECT_EQ(error_of([] { parse_sweep_axis("threads"); }),
            "bad --vary 'threads': expected KEY=V1,V2,...");
  EXPECT_EQ(error_of([] { parse_sweep_axis("=1,2"); }),
            "bad --vary '=1,2': expected KEY=V1,V2,...");
  EXPECT_EQ(error_of([] { parse_sweep_axis("threads=1,,2"); }),
            "bad --vary 'threads=1,,2': an empty value");
  EXPECT_EQ(error_of([] { parse_sweep_axis("threads="); }),
            "bad --vary 'threads=': an empty value");
  EXPECT_EQ(error_of([] { parse_sweep_axis("threads=4,8,4"); }),
            "bad --vary 'threads=4,8,4': the value 4 twice");
}

TEST(SweepArgs, PointsAreTheProductFirstAxisSlowest) {
  const auto points =
      sweep_points({parse_sweep_axis("threads=1,16"), parse_sweep_axis("packet=1,4,16")}, {});
  ASSERT_EQ(points.size(), 6u);
  EXPECT_EQ(points[0], (std::vector<std::string>{"threads=1", "packet=1"}));
  EXPECT_EQ(points[2], (std::vector<std::string>{"threads=1", "packet=16"}));
  EXPECT_EQ(points[3], (std::vector<std::string>{"threads=16", "packet=1"}));
  EXPECT_EQ(points[5], (std::vector<std::string>{"threads=16", "packet=16"}));
}

TEST(SweepArgs, EveryPointIsCheckedBeforeAnyFrame) {
  const CycleRenderOptions base;
  EXPECT_EQ(error_of([&] { sweep_points({}, base); }),
            "sweep needs at least one --vary KEY=V1,V2,...");
  EXPECT_EQ(error_of([&] {
              sweep_points({parse_sweep_axis("threads=1"), parse_sweep_axis("threads=2")}, base);
            }),
            "bad --vary threads: the key is varied twice");
  // The value error of the key table, named as --vary, with the point it belongs to.
  const std::string zero = error_of([&] { sweep_points({parse_sweep_axis("threads=4,0")}, base); });
  EXPECT_EQ(zero.rfind("bad --vary threads=0: ", 0), 0u) << zero;
  EXPECT_NE(zero.find("(sweep point threads=0)"), std::string::npos) << zero;
  const std::string pow2 =
      error_of([&] { sweep_points({parse_sweep_axis("cache.list.items=512,500")}, base); });
  EXPECT_NE(pow2.find("power of two"), std::string::npos) << pow2;
  const std::string unknown = error_of([&] { sweep_points({parse_sweep_axis("warp=1")}, base); });
  EXPECT_EQ(unknown.rfind("unknown --vary key 'warp'", 0), 0u) << unknown;
  // A bad --set is named as --set, whatever is varied.
  CycleRenderOptions bad_set;
  bad_set.set = {"threads=0"};
  EXPECT_EQ(error_of([&] {
              sweep_points({parse_sweep_axis("packet=4")}, bad_set);
            }).rfind("bad --set threads=0", 0),
            0u);
  // 17 x 16 > kMaxSweepPoints.
  std::string many = "lat.add=1", more = "lat.mul=1";
  for (int i = 2; i <= 17; ++i)
    many += "," + std::to_string(i);
  for (int i = 2; i <= 16; ++i)
    more += "," + std::to_string(i);
  EXPECT_EQ(error_of([&] {
              sweep_points({parse_sweep_axis(many), parse_sweep_axis(more)}, base);
            }),
            "sweep of more than 256 points: vary fewer keys or values");
}

// builtin:room at 64x48 once, shared by the frame tests.
const PreparedScene& room() {
  static const PreparedScene p = [] {
    RenderSettings s;
    s.res = {64, 48};
    return prepare_scene("builtin:room", s);
  }();
  return p;
}

TEST(Sweep, EveryPointBitIdenticalToFp24AndTimingFollowsTheThreads) {
  RenderSettings s;
  s.res = {64, 48};
  s.cycle.set = {"lat.div=12"};  // --set applies to every point
  const SweepResult r = run_sweep_points(
      {parse_sweep_axis("threads=1,8"), parse_sweep_axis("packet=1,4")}, room(), s);
  ASSERT_EQ(r.points.size(), 4u);
  EXPECT_EQ(r.functional_rays, 64u * 48u);
  auto cycles = [&](std::size_t i) { return r.points[i].cycle["cycles"].get<std::uint64_t>(); };
  // Eight threads hide the latencies one thread waits out.
  EXPECT_GT(cycles(0), 3 * cycles(2));
  EXPECT_GT(cycles(1), 3 * cycles(3));
  EXPECT_EQ(r.points[0].speedup, 1.0);
  EXPECT_DOUBLE_EQ(r.points[3].speedup,
                   static_cast<double>(cycles(0)) / static_cast<double>(cycles(3)));
  // Each point's frame ran with its own configuration on top of --set.
  const nlohmann::json& conf = r.points[1].cycle["configuration"];
  EXPECT_EQ(conf["threads"]["value"], 1);
  EXPECT_EQ(conf["packet"]["value"], 4);
  EXPECT_EQ(conf["lat.div"]["value"], 12);
  EXPECT_EQ(r.points[1].cycle["rays"], 64 * 48);
}

// kd.* keys build the trees: a point that varies one gets its own image and its own functional
// reference frame, and its figures show the other tree (here a deeper one and a shallower one).
TEST(Sweep, TreeKeysRebuildThePointsImage) {
  RenderSettings s;
  s.res = {64, 48};
  const SweepResult r = run_sweep_points(
      {parse_sweep_axis("kd.traversal_cost=10,60"), parse_sweep_axis("threads=16,64")}, room(), s);
  ASSERT_EQ(r.points.size(), 4u);
  auto steps = [&](std::size_t i) {
    return r.points[i].cycle["per_ray"]["traversal_steps"].get<double>();
  };
  auto tests = [&](std::size_t i) {
    return r.points[i].cycle["per_ray"]["intersections"].get<double>();
  };
  // Cheap steps: a deep tree with few triangle tests; dear steps: the other way round.
  EXPECT_GT(steps(0), steps(2) + 2.0);
  EXPECT_LT(tests(0) + 2.0, tests(2));
  EXPECT_EQ(steps(0), steps(1));  // threads change the timing, not the work
  EXPECT_EQ(r.points[2].cycle["configuration"]["kd.traversal_cost"]["value"], 60.0);
  EXPECT_EQ(r.points[0].cycle["configuration"]["kd.traversal_cost"]["value"], 10.0);
  // A bad tree value fails before any frame, named as the --vary it came from.
  EXPECT_EQ(
      error_of([&] { run_sweep_points({parse_sweep_axis("kd.max_depth=12,-5")}, room(), s); }),
      "bad --vary kd.max_depth=-5: expected -1..1000 levels (sweep point kd.max_depth=-5)");
}

TEST(Sweep, APointThatDiffersFromFp24IsAnError) {
  RenderSettings s;
  s.res = {64, 48};
  const FrameResult reference = render_model(parse_model("fp24"), room(), s);
  const FrameResult frame = render_model(parse_model("cycle"), room(), s);
  check_sweep_point(frame, reference, "threads=64");  // the model as it is: no error
  FrameResult one_bit = frame;
  std::size_t hit = 0;
  while (!one_bit.hits.pixels[hit].hit())
    ++hit;
  one_bit.hits.pixels[hit].u = std::nextafter(one_bit.hits.pixels[hit].u, 2.0f);
  EXPECT_EQ(error_of([&] { check_sweep_point(one_bit, reference, "threads=64"); }),
            "sweep point threads=64: the cycle model's hit records or image differ from the "
            "functional model's (same triangle 100.0000 %, image identical)");
  FrameResult image = frame;
  image.image.rgb[7] ^= 1u;
  EXPECT_NE(
      error_of([&] { check_sweep_point(image, reference, "packet=4"); }).find("image differs"),
      std::string::npos);
  FrameResult lost = frame;
  --lost.rays;
  EXPECT_EQ(error_of([&] { check_sweep_point(lost, reference, "packet=4"); }),
            "sweep point packet=4: 3071 rays returned, the functional model traced 3072");
}

// --model cycle-e7m23: the image and the reference in e7m23, every point equal to the functional
// model in e7m23.
TEST(Sweep, WideDatapathAgainstTheE7m23Model) {
  RenderSettings s;
  s.res = {32, 24};
  const PreparedScene wide = prepare_scene("builtin:room", s, ff::Format{7, 23});
  const SweepResult r = run_sweep_points({parse_sweep_axis("threads=4,32")}, wide, s);
  EXPECT_EQ(r.functional_model, "e7m23");
  ASSERT_EQ(r.points.size(), 2u);
  EXPECT_GT(r.points[1].speedup, 2.0);
  EXPECT_EQ(error_of([] {
              SweepOptions o;
              o.scene = "builtin:cube";
              o.model = "fp24";
              o.vary = {"threads=4"};
              run_sweep(o);
            }),
            "bad --model fp24: a sweep runs cycle or cycle-e7m23");
}

TEST(Sweep, TableCsvAndJson) {
  RenderSettings s;
  s.res = {64, 48};
  const SweepResult r = run_sweep_points({parse_sweep_axis("threads=2,16")}, room(), s);
  const std::string table = sweep_table(r);
  std::istringstream t(table);
  std::string head, row1, row2, extra;
  std::getline(t, head);
  std::getline(t, row1);
  std::getline(t, row2);
  EXPECT_FALSE(std::getline(t, extra));
  EXPECT_EQ(head.rfind("threads ", 0), 0u) << head;
  EXPECT_NE(head.find("speed-up"), std::string::npos);
  EXPECT_EQ(row1.size(), head.size()) << table;  // columns line up
  EXPECT_EQ(row2.size(), head.size()) << table;
  EXPECT_NE(row1.find(std::to_string(r.points[0].cycle["cycles"].get<std::uint64_t>())),
            std::string::npos)
      << table;

  const std::string csv = sweep_csv(r);
  std::istringstream c(csv);
  std::string line;
  std::getline(c, line);
  EXPECT_EQ(line.rfind("threads,cycles,fps,mrays_per_s,speedup,usage_traversal,", 0), 0u) << line;
  const auto fields = std::count(line.begin(), line.end(), ',');
  int rows = 0;
  while (std::getline(c, line)) {
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), fields) << line;
    ++rows;
  }
  EXPECT_EQ(rows, 2);
  EXPECT_EQ(csv.substr(csv.find('\n') + 1, 2), "2,");

  SweepOptions o;
  o.scene = "builtin:room";
  o.res = "64x48";
  o.vary = {"threads=2,16"};
  const nlohmann::json j = sweep_json(r, o);
  EXPECT_EQ(j["vary"]["threads"], (std::vector<std::string>{"2", "16"}));
  ASSERT_EQ(j["points"].size(), 2u);
  EXPECT_EQ(j["points"][1]["values"]["threads"], "16");
  EXPECT_EQ(j["points"][1]["report"]["cycles"], r.points[1].cycle["cycles"]);
  EXPECT_TRUE(j["bit_identical_to_functional_model"].get<bool>());
  EXPECT_EQ(j["functional_model"], "fp24");
}

TEST(SaarcorBinary, SweepEndToEndAndBadInput) {
  const fs::path d = test_support::scratch_dir("sweep");
  fs::remove_all(d);
  const std::string report = (d / "sweep.json").string(), csv = (d / "sweep.csv").string();
  test_support::CliRun r = test_support::run_saarcor(
      "sweep builtin:cube --res 32x24 --vary threads=1,4 --set mem.latency=20 --report " + report +
      " --csv " + csv);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << "progress must stay off when stderr is not a terminal: " << r.err;
  EXPECT_NE(r.out.find("2 points, every one bit-identical to the functional fp24 model"),
            std::string::npos)
      << r.out;
  std::ifstream jf(report);
  const nlohmann::json j = nlohmann::json::parse(jf);
  EXPECT_EQ(j["points"][0]["report"]["configuration"]["mem.latency"]["value"], 20);
  EXPECT_TRUE(fs::exists(csv));

  // Bad input: one line, exit 1, and neither file written.
  fs::remove_all(d);
  const std::string outs = " --report " + report + " --csv " + csv;
  test_support::expect_one_line_error(
      test_support::run_saarcor("sweep builtin:cube --res 8x8 --vary threads=0,4" + outs),
      "bad --vary threads=0");
  test_support::expect_one_line_error(
      test_support::run_saarcor("sweep builtin:cube --res 8x8 --vary bogus=1" + outs),
      "unknown --vary key 'bogus'");
  test_support::expect_one_line_error(
      test_support::run_saarcor("sweep builtin:cube --res 8x8 --vary threads=4 --csv x.txt"),
      "bad --csv 'x.txt'");
  test_support::expect_one_line_error(
      test_support::run_saarcor("sweep /nonexistent/s.glb --res 8x8 --vary threads=4" + outs),
      "/nonexistent/s.glb");
  test_support::expect_one_line_error(
      test_support::run_saarcor("sweep builtin:cube --res 8x8 --vary threads=4 --depth -1" + outs),
      "depth");
  EXPECT_FALSE(fs::exists(report));
  EXPECT_FALSE(fs::exists(csv));
}

// --jobs: the same rows in the same order as one job, whatever finishes first; the kd.* groups
// (own image, own reference) too, and a failing point is named as a serial run names it.
TEST(SweepParallel, JobsGiveTheSerialRows) {
  RenderSettings s;
  s.res = {64, 48};
  const std::vector<SweepAxis> axes = {parse_sweep_axis("threads=1,4,16"),
                                       parse_sweep_axis("packet=1,4")};
  SweepRun serial;
  serial.jobs = 1;
  SweepRun parallel;
  parallel.jobs = 3;
  const SweepResult a = run_sweep_points(axes, room(), s, serial);
  const SweepResult b = run_sweep_points(axes, room(), s, parallel);
  ASSERT_EQ(b.points.size(), 6u);
  for (std::size_t i = 0; i < b.points.size(); ++i) {
    EXPECT_EQ(b.points[i].index, i);
    EXPECT_EQ(b.points[i].settings, a.points[i].settings);
    EXPECT_EQ(b.points[i].cycle["cycles"], a.points[i].cycle["cycles"]);
  }
  EXPECT_EQ(sweep_csv(b), sweep_csv(a));
  EXPECT_EQ(b.functional_rays, 64u * 48u);

  const std::vector<SweepAxis> trees = {parse_sweep_axis("threads=8,32"),
                                        parse_sweep_axis("kd.traversal_cost=10,60")};
  EXPECT_EQ(sweep_csv(run_sweep_points(trees, room(), s, parallel)),
            sweep_csv(run_sweep_points(trees, room(), s, serial)));
}

TEST(SweepParallel, ShardsMergeIntoTheWholeSweepsCsv) {
  RenderSettings s;
  s.res = {32, 24};
  const std::vector<SweepAxis> axes = {parse_sweep_axis("threads=2,8,32"),
                                       parse_sweep_axis("packet=4,16")};
  const std::string whole = sweep_csv(run_sweep_points(axes, room(), s));
  std::vector<std::pair<std::string, std::string>> parts;
  for (std::size_t k = 0; k < 4; ++k) {
    SweepRun run;
    run.shard = k;
    run.shards = 4;
    const SweepResult shard = run_sweep_points(axes, room(), s, run);
    // Shard k of 4 holds points k, k + 4, ...: 6 points give 2, 2, 1, 1.
    ASSERT_EQ(shard.points.size(), k < 2 ? 2u : 1u);
    EXPECT_EQ(shard.points[0].index, k);
    parts.push_back({"part" + std::to_string(k) + ".csv", sweep_csv(shard)});
  }
  EXPECT_EQ(parts[1].second.substr(0, parts[1].second.find('\n')),
            "point,points,threads,packet,cycles,fps,mrays_per_s,speedup,usage_traversal,"
            "usage_list,usage_transformation,usage_intersection,cache_hit_traversal,"
            "cache_hit_list,cache_hit_transformation,bandwidth_mb_s_total,cycles_per_packet,"
            "simd_efficiency,fp_units,memory_kb,luts,block_rams");
  EXPECT_EQ(parts[1].second.substr(parts[1].second.find('\n') + 1, 6), "1,6,2,");
  // In any order of the files: the bytes of the one-process CSV (speed-ups over point 0 again).
  std::swap(parts[0], parts[3]);
  EXPECT_EQ(merge_sweep_csv(parts), whole);

  auto without = parts;
  without.pop_back();
  EXPECT_EQ(error_of([&] { merge_sweep_csv(without); }),
            "sweep-merge: point 0 of 6 is in none of the files (a shard missing)");
  auto twice = parts;
  twice.push_back({"again.csv", parts[1].second});
  EXPECT_EQ(error_of([&] { merge_sweep_csv(twice); }), "again.csv: point 1 is in two shard files");
  EXPECT_EQ(error_of([&] {
              merge_sweep_csv({{"whole.csv", whole}});
            }),
            "whole.csv: not a shard CSV (saarcor sweep --shard K/N): its header does not start "
            "with point,points");
}

// --pareto on shards: each shard marks its own front; sweep-merge marks the whole sweep's, so
// the merged CSV is the one-process CSV with --pareto.
TEST(SweepParallel, MergeMarksTheWholeSweepsParetoFront) {
  RenderSettings s;
  s.res = {32, 24};
  const std::vector<SweepAxis> axes = {parse_sweep_axis("threads=2,8,32"),
                                       parse_sweep_axis("packet=4,16")};
  SweepResult whole = run_sweep_points(axes, room(), s);
  mark_pareto(whole, "luts");
  std::vector<std::pair<std::string, std::string>> parts;
  for (std::size_t k = 0; k < 3; ++k) {
    SweepRun run;
    run.shard = k;
    run.shards = 3;
    SweepResult shard = run_sweep_points(axes, room(), s, run);
    mark_pareto(shard, "luts");
    parts.push_back({"part" + std::to_string(k) + ".csv", sweep_csv(shard)});
  }
  EXPECT_EQ(merge_sweep_csv(parts), sweep_csv(whole));
}

TEST(SweepParallel, ShardGrammar) {
  EXPECT_EQ(parse_shard("1/1"), (std::pair<std::size_t, std::size_t>{0, 1}));
  EXPECT_EQ(parse_shard("3/8"), (std::pair<std::size_t, std::size_t>{2, 8}));
  EXPECT_EQ(error_of([] { parse_shard("0/4"); }), "bad --shard '0/4': expected 1 <= K <= N <= 256");
  EXPECT_EQ(error_of([] { parse_shard("5/4"); }), "bad --shard '5/4': expected 1 <= K <= N <= 256");
  EXPECT_EQ(error_of([] { parse_shard("2"); }), "bad --shard '2': expected K/N, e.g. 2/8");
  EXPECT_EQ(error_of([] { parse_shard("a/b"); }), "bad --shard 'a/b': expected K/N, e.g. 2/8");
}

TEST(SaarcorBinary, SweepShardsAndMergeEndToEnd) {
  const fs::path d = test_support::scratch_dir("sweep_shard");
  fs::remove_all(d);
  fs::create_directories(d);
  const std::string args = "sweep builtin:cube --res 16x12 --vary threads=1,2,4 --jobs 2";
  ASSERT_EQ(test_support::run_saarcor(args + " --csv " + (d / "whole.csv").string()).status, 0);
  for (int k = 1; k <= 2; ++k) {
    const test_support::CliRun r =
        test_support::run_saarcor(args + " --shard " + std::to_string(k) + "/2 --csv " +
                                  (d / ("part" + std::to_string(k) + ".csv")).string());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("3 points, shard " + std::to_string(k) + "/2: " + (k == 1 ? "2" : "1")),
              std::string::npos)
        << r.out;
  }
  const test_support::CliRun m =
      test_support::run_saarcor("sweep-merge " + (d / "part2.csv").string() + " " +
                                (d / "part1.csv").string() + " -o " + (d / "merged.csv").string());
  ASSERT_EQ(m.status, 0) << m.err;
  EXPECT_NE(m.out.find("2 shard files, 3 points"), std::string::npos) << m.out;
  auto slurp = [](const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
  };
  EXPECT_EQ(slurp(d / "merged.csv"), slurp(d / "whole.csv"));
  test_support::expect_one_line_error(test_support::run_saarcor(args + " --shard 3/2"),
                                      "bad --shard '3/2'");
  test_support::expect_one_line_error(
      test_support::run_saarcor("sweep-merge " + (d / "whole.csv").string() + " -o " +
                                (d / "x.csv").string()),
      "not a shard CSV");
}

}  // namespace
}  // namespace saarcor
