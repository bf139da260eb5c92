// The cycle model of the DynRTP (testbench/chip.h; docs/cycle-model.md): bit-identical to the
// functional fp24 model on every scene under a covering design of configurations (threads, packet
// width, caches, latencies, shadow and secondary rays); ray and thread conservation; thread
// scaling; the prototype configuration on the room beside the paper's Table 4 row for Scene6;
// parameters and bad input.
#include "testbench/chip.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <sstream>
#include <string>

#include "host/image_builder.h"
#include "host/scene.h"
#include "memif/memory_system.h"
#include "testbench/dynrtc_testing.h"

namespace saarcor::units {
namespace {

using testing::build;
using testing::configs;
using testing::expect_bit_exact;
using testing::kSanitized;
using testing::scene_cases;
using testing::SceneCase;

class BitExact : public ::testing::TestWithParam<int> {};

TEST_P(BitExact, CycleModelEqualsFunctionalModel) {
  const auto cases = scene_cases();
  const int i = GetParam();
  const SceneCase& sc = cases[static_cast<std::size_t>(i)];
  if (kSanitized && sc.bank_mb > 4) GTEST_SKIP() << "large scene: release build only";
  const host::BuiltImage b =
      kSanitized ? build(sc.spec, 16, 12, sc.bank_mb) : build(sc.spec, sc.w, sc.h, sc.bank_mb);
  const auto& cf = configs();
  const std::size_t n = cf.size() - 1;
  const std::size_t a = 1 + (2 * static_cast<std::size_t>(i)) % n;
  const std::size_t c = 1 + (2 * static_cast<std::size_t>(i) + 1) % n;
  const std::vector<std::size_t> runs =
      kSanitized ? std::vector<std::size_t>{a} : std::vector<std::size_t>{0, a, c};
  for (std::size_t k : runs)
    expect_bit_exact(b, cf[k], sc.spec + " [" + cf[k].name + "]");
  // Textures unfiltered (one texel per hit instead of four), with shadows and reflections: the
  // other filter's shading reads and pixels.
  if (kSanitized) return;
  const host::BuiltImage nearest = build(sc.spec, sc.w, sc.h, sc.bank_mb, false);
  const testing::Config& shaded = cf[6];
  ASSERT_TRUE(shaded.shadows_and_secondary);
  expect_bit_exact(nearest, shaded, sc.spec + " nearest [" + shaded.name + "]");
}

INSTANTIATE_TEST_SUITE_P(Scenes, BitExact, ::testing::Range(0, 28));

TEST(DynRtc, SceneCasesCoverEveryBuiltinAndModel) {
  // 7 built-ins (suncor-wind is SunCOR's object, checked by the frame-sequence tests) + 21 glTF
  // files (MANIFEST glTF table)
  EXPECT_EQ(scene_cases().size(), 28u);
}

// Refraction (docs/shading.md section 7) with shadow, reflection and total internal reflection
// rays on builtin:glass: bit-identical to the functional model with one DynRTP and with four, for
// thread counts from 1 to 64 and packets of 1, 4 and 16 (refraction packets do not share an
// origin, so they take 2P transformation steps), and every kind of ray is traced.
TEST(DynRtc, RefractionOnGlassIsBitExact) {
  const host::BuiltImage b = build("builtin:glass", kSanitized ? 16 : 32, kSanitized ? 12 : 24);
  const std::vector<testing::Config> cases = {
      {"p1-t1", {"threads=1"}, true},
      {"p1-t4-packet1", {"threads=4", "packet=1"}, true},
      {"p1-t64", {}, true},
      {"p4-t2-packet16", {"pipelines=4", "threads=2", "packet=16"}, true},
      {"p4-t16-random-lat", {"pipelines=4", "threads=16"}, true, 29},
  };
  for (const testing::Config& c : cases)
    expect_bit_exact(b, c, std::string("glass [") + c.name + "]");
  const FunctionalFrame fn = run_functional(b.image, testing::shading_of(cases[0]));
  for (const RayKind k : {RayKind::kShadow, RayKind::kReflection, RayKind::kRefraction})
    EXPECT_GT(fn.rays_issued[static_cast<std::size_t>(k)], 10u) << ray_kind_name(k);
}

// The evaluation order of modules changes no figure; with several DynRTPs too (the RGC's packet
// count is shared by the pipelines' ray sources).
TEST(DynRtc, EvaluationOrderChangesNothing) {
  const host::BuiltImage b = build("builtin:room", 32, 24);
  for (const int pipelines : {1, 3}) {
    CycleParams p = prototype_params();
    p.pipelines = pipelines;
    p.threads = 64 / pipelines;
    const CycleFrame a = run_cycle(b.image, p);
    for (const std::uint64_t seed : {99u, 5u}) {
      CycleRunOptions o;
      o.shuffle_seed = seed;
      const CycleFrame c = run_cycle(b.image, p, o);
      EXPECT_EQ(a.cycles, c.cycles) << pipelines;
      EXPECT_EQ(a.issue_cycles, c.issue_cycles) << pipelines;
      EXPECT_EQ(a.stats_json, c.stats_json) << pipelines;
    }
  }
}

// The units' next_wakeup() is exact: skipping idle cycles (many with one thread and slow memory)
// gives the same cycles and statistics as evaluating every cycle.
TEST(DynRtc, IdleSkipChangesNothing) {
  const host::BuiltImage b = build("builtin:room", 16, 12);
  // With three DynRTPs a ray source with a free thread sleeps until the RGC's next grant.
  for (const int pipelines : {1, 3}) {
    CycleParams p = prototype_params();
    p.pipelines = pipelines;
    p.threads = 2;
    p.mem_latency = 30;
    CycleRunOptions every;
    every.idle_skip = false;
    const CycleFrame a = run_cycle(b.image, p);
    const CycleFrame c = run_cycle(b.image, p, every);
    EXPECT_GT(a.skipped_cycles, 0u) << pipelines;
    EXPECT_EQ(c.skipped_cycles, 0u) << pipelines;
    EXPECT_EQ(a.cycles, c.cycles) << pipelines;
    EXPECT_EQ(a.stats_json, c.stats_json) << pipelines;
  }
}

// With one DynRTP the RGS's shading and frame-buffer ports are the memory controller's lanes,
// served in closed form (docs/memif.md "Lanes"); evaluating every cycle steps each request
// through the channels and the controller instead. Both give the same frame, from the tightest
// queues and ports to deep ones behind a slow SRAM, with the textured room and with glass's
// shadow, reflection and refraction rays (several waves per packet, child packets).
TEST(DynRtc, LanesGiveTheSteppedFrame) {
  struct Case {
    const char* scene;
    int threads, latency, queue_depth, port_capacity;
    bool secondary;
  };
  const Case cases[] = {
      {"builtin:room", 64, 4, 1, 2, false},
      {"builtin:room", 16, 200, 64, 256, false},
      {"builtin:glass", 8, 9, 2, 3, true},
  };
  for (const Case& c : cases) {
    const host::BuiltImage b = build(c.scene, 16, 12);
    CycleParams p = prototype_params();
    p.threads = c.threads;
    p.mem_latency = c.latency;
    p.mem_queue_depth = c.queue_depth;
    p.mem_port_capacity = c.port_capacity;
    CycleRunOptions lanes;
    lanes.shading.shadows = c.secondary;
    lanes.shading.secondary = c.secondary;
    CycleRunOptions stepped = lanes;
    stepped.idle_skip = false;
    const CycleFrame a = run_cycle(b.image, p, lanes);
    const CycleFrame s = run_cycle(b.image, p, stepped);
    const std::string what = std::string(c.scene) + " queue " + std::to_string(c.queue_depth);
    EXPECT_GT(a.shading_bytes, 0u) << what;
    EXPECT_EQ(a.cycles, s.cycles) << what;
    EXPECT_EQ(a.stats_json, s.stats_json) << what;
    EXPECT_EQ(a.frame.rgb, s.frame.rgb) << what;
  }
}

// Several DynRTPs (D44): the RGC spreads the packets over the pipelines on demand, each pipeline
// reads through its own caches, the results stay the functional model's, and the frame takes
// fewer cycles; usage is per unit (averaged over the pipelines).
TEST(DynRtc, PipelinesShareTheFrame) {
  const host::BuiltImage b = build("builtin:room", 64, 48);
  testing::Config four{"t16x4", {"pipelines=4", "threads=16"}};
  testing::expect_bit_exact(b, four, "room [t16x4]");
  CycleParams one = prototype_params();
  one.threads = 16;
  CycleParams p = one;
  p.pipelines = 4;
  // The DynRTC's work: shading off (with shading the four RGSs share the one shading bank, a word
  // per cycle, which then bounds the frame: ShadingBankBoundsFourPipelines).
  CycleRunOptions hits;
  hits.shading.shade = false;
  const CycleFrame a = run_cycle(b.image, one, hits);
  const CycleFrame c = run_cycle(b.image, p, hits);
  ASSERT_EQ(a.per_pipeline.size(), 1u);
  EXPECT_EQ(a.per_pipeline[0].packets, a.packets);
  ASSERT_EQ(c.per_pipeline.size(), 4u);
  std::uint64_t packets = 0;
  std::array<std::uint64_t, kTable4Units> issued{};
  for (const CycleFrame::PipelineCount& pc : c.per_pipeline) {
    // On demand: no pipeline gets less than half its share.
    EXPECT_GE(pc.packets, c.packets / 8) << c.stats_json;
    packets += pc.packets;
    for (std::size_t u = 0; u < issued.size(); ++u)
      issued[u] += pc.issue_cycles[u];
  }
  EXPECT_EQ(packets, c.packets);
  EXPECT_EQ(issued, c.issue_cycles);
  // The same work in all: steps issued per unit equal the one-pipeline run's.
  EXPECT_EQ(c.issue_cycles, a.issue_cycles);
  // More than twice as fast (2.2x on this small frame, 3.7x at 256x192: the tail of the frame,
  // when fewer packets than threads are left, is the same length with four pipelines).
  EXPECT_LT(c.cycles * 2, a.cycles) << a.cycles << " vs " << c.cycles;
  EXPECT_NEAR(
      c.figures.usage(0),
      100.0 * static_cast<double>(c.issue_cycles[0]) / (4.0 * static_cast<double>(c.cycles)), 1e-9);
  // Eight DynRTPs wait on the scene banks' one issue path (D21); a path per bank relieves it.
  CycleParams eight = prototype_params();
  eight.pipelines = 8;
  eight.mem_scene_paths = 1;
  const CycleFrame shared_path = run_cycle(b.image, eight, hits);
  eight.mem_scene_paths = 3;
  const CycleFrame three_paths = run_cycle(b.image, eight, hits);
  EXPECT_LT(three_paths.cycles * 4, shared_path.cycles * 3)
      << shared_path.cycles << " vs " << three_paths.cycles;  // 24,783 vs 14,678 cycles
  EXPECT_EQ(three_paths.issue_cycles, shared_path.issue_cycles);
  EXPECT_NE(three_paths.stats_json.find("mi.ctrl.path5.bank_switches"), std::string::npos);
  // Every pipeline's caches and ports are in the statistics.
  EXPECT_NE(c.stats_json.find("dynrtp3.traversal"), std::string::npos);
  EXPECT_NE(c.stats_json.find("dynrtp3.rgs.packets_admitted"), std::string::npos);
}

// The thread programs on a second host thread ahead of the simulation (the default on a
// multi-core host) and a program per thread run inline give the same run: cycles, every
// statistic, every hit record, the image and the op counts, under every configuration of the
// covering design (one thread, packets of 1 and 16, tiny caches, random latencies, shadow and
// secondary rays). Also with the program thread one finished packet ahead: packets then retire
// long after later ones started (a slow packet's slot must not be needed by a later packet).
TEST(DynRtc, ProgramsAheadChangeNothing) {
  const host::BuiltImage b = build("builtin:room", kSanitized ? 16 : 32, kSanitized ? 12 : 24);
  for (const testing::Config& c : configs()) {
    const CycleParams p = testing::params_of(c);
    CycleRunOptions per_step;
    per_step.shading = testing::shading_of(c);
    per_step.programs = ProgramMode::kPerStep;
    const CycleFrame i = run_cycle(b.image, p, per_step);
    EXPECT_EQ(i.programs, ProgramMode::kPerStep);
    EXPECT_EQ(i.host_threads, 1);
    // Packet-first, and ahead with the default window and with a one-packet window.
    for (const int window : {0, 192, 1}) {
      CycleRunOptions recorded = per_step;
      recorded.programs = window == 0 ? ProgramMode::kPacketFirst : ProgramMode::kAhead;
      recorded.ahead_packets = window;
      const CycleFrame a = run_cycle(b.image, p, recorded);
      const std::string what = std::string(c.name) + ", " + program_mode_name(recorded.programs) +
                               ", window " + std::to_string(window);
      EXPECT_EQ(a.programs, recorded.programs) << what;
      EXPECT_EQ(a.host_threads, window == 0 ? 1 : 2) << what;
      EXPECT_EQ(a.cycles, i.cycles) << what;
      EXPECT_EQ(a.stats_json, i.stats_json) << what;
      ASSERT_EQ(a.frame.pixels.size(), i.frame.pixels.size()) << what;
      for (std::size_t k = 0; k < a.frame.pixels.size(); ++k)
        ASSERT_TRUE(testing::same_record(a.frame.pixels[k], i.frame.pixels[k]))
            << what << ": pixel " << k;
      EXPECT_EQ(a.frame.rgb, i.frame.rgb) << what;
      EXPECT_EQ(a.frame.units.transformation_ops, i.frame.units.transformation_ops) << what;
      EXPECT_EQ(a.frame.units.rgs_ops, i.frame.units.rgs_ops) << what;
      EXPECT_EQ(a.frame.rays_issued, i.frame.rays_issued) << what;
    }
  }
  CycleRunOptions bad;
  bad.programs = ProgramMode::kAhead;
  bad.ahead_packets = 0;
  EXPECT_THROW(run_cycle(b.image, prototype_params(), bad), std::runtime_error);
}

// An error of a thread program (here the stack overflow of D26) stops the run with the same
// one-line error in every mode: on the program thread, and with fewer threads than packets in
// flight.
TEST(DynRtc, ProgramThreadErrorsReachTheCaller) {
  const host::BuiltImage b = build("builtin:room", 16, 12);
  for (const ProgramMode mode :
       {ProgramMode::kPerStep, ProgramMode::kPacketFirst, ProgramMode::kAhead}) {
    for (const int threads : {1, 64}) {
      CycleParams p = prototype_params();
      p.stack = 2;
      p.threads = threads;
      CycleRunOptions o;
      o.programs = mode;
      try {
        run_cycle(b.image, p, o);
        ADD_FAILURE() << "a 2-entry stack was enough (" << program_mode_name(mode) << ")";
      } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("stack overflow"), std::string::npos) << e.what();
      }
    }
  }
}

// Thread scaling (paper section 5: nearly linear up to 32 threads, about +10% from 32 to 64).
TEST(DynRtc, ThreadScalingOnTheRoom) {
  // 128x96 (3,072 packets): at 64x48 the 64 threads share 768 packets and the frame's tail, when
  // fewer packets than threads remain, is a visible part of it.
  const host::BuiltImage b = build("builtin:room", 128, 96);
  std::map<int, std::uint64_t> cycles;
  std::printf("thread scaling, builtin:room 128x96, prototype otherwise\n");
  std::printf("threads   cycles  cycles/packet  speed-up  trav  list  xfrm   int (usage %%)\n");
  for (int t : {1, 2, 4, 8, 16, 32, 64}) {
    CycleParams p = prototype_params();
    p.threads = t;
    const CycleFrame c = run_cycle(b.image, p);
    cycles[t] = c.cycles;
    std::printf("%7d %8llu %14.1f %9.2f %5.1f %5.1f %5.1f %5.1f\n", t,
                static_cast<unsigned long long>(c.cycles),
                static_cast<double>(c.cycles) / static_cast<double>(c.packets),
                static_cast<double>(cycles[1]) / static_cast<double>(c.cycles), c.figures.usage(0),
                c.figures.usage(1), c.figures.usage(2), c.figures.usage(3));
  }
  EXPECT_GE(static_cast<double>(cycles[1]) / static_cast<double>(cycles[32]), 8.0);
  const double gain = static_cast<double>(cycles[32]) / static_cast<double>(cycles[64]) - 1.0;
  std::printf("64 threads against 32: %+.1f%% (paper: about +10%%)\n", 100.0 * gain);
  EXPECT_GE(gain, 0.0);
  EXPECT_LE(gain, 0.25);
  for (int t : {2, 4, 8, 16, 32})
    EXPECT_LE(cycles[t], cycles[t / 2]) << t << " threads";
}

// The prototype configuration on the room (the paper's Scene6 stand-in) beside Table 4's Scene6
// row (1024x768 there; usage, hit rates and cycles per packet do not depend on the resolution).
TEST(DynRtc, PrototypeOnTheRoomBesideTable4) {
  const host::BuiltImage b = build("builtin:room", 256, 192);
  const CycleFrame c = run_cycle(b.image, prototype_params());
  const auto& f = c.figures;
  const double per_packet = static_cast<double>(c.cycles) / static_cast<double>(c.packets);
  const UnitStats& u = c.frame.units;
  const double ratio = f.usage(3) / f.usage(2);
  const double op_ratio = static_cast<double>(u.traversal_ops.total()) /
                          static_cast<double>(u.intersection_ops.total());
  const double step_ratio = static_cast<double>(c.per_ray_sum.traversal_steps) /
                            static_cast<double>(c.per_ray_sum.intersections);
  const double tri_per_packet =
      static_cast<double>(u.intersection_packets) / static_cast<double>(c.packets);
  std::printf("builtin:room 256x192, prototype configuration, against Table 4 Scene6\n");
  std::printf(
      "                 usage %% trav list xfrm  int | hit %% trav list xfrm | cycles/packet\n");
  std::printf("model room             %4.0f %4.0f %4.0f %4.0f |       %4.0f %4.0f %4.0f | %6.1f\n",
              f.usage(0), f.usage(1), f.usage(2), f.usage(3), f.cache_hit(0), f.cache_hit(1),
              f.cache_hit(2), per_packet);
  std::printf("paper Scene6             68   16   85   41 |         99   97   99 |   29.9\n");
  std::printf("intersection/transformation usage %.2f (paper 0.41-0.65 over all scenes)\n", ratio);
  std::printf("traversal/intersection: ops %.2f, steps per ray %.2f (paper: about 4:1)\n", op_ratio,
              step_ratio);
  std::printf("triangle tests per packet %.1f (Scene6 calibration: about 3); DynRTC %.1f MB/s\n",
              tri_per_packet, f.bw_dynrtc());
  for (int k = 0; k < kCacheUnits; ++k)
    EXPECT_GT(f.cache_hit(k), 90.0) << cache_unit_name(CacheUnit(k));
  // Usage is the work the thread program asks for, spread over the frame: P intersection cycles
  // per triangle test and n+1 transformation steps per matrix (D30, D31). The ratio follows from
  // the scene's triangle tests per packet.
  const double predicted =
      static_cast<double>(u.intersection_packets * 4) / static_cast<double>(u.transformation_steps);
  EXPECT_NEAR(ratio, predicted, 0.01);
  // The issue's band (paper: 0.41-0.65 over its scenes). The room's tree gives about 2.4
  // triangle tests per packet (Scene6's calibration: ~3), near the band's bottom
  // (docs/cycle-model.md).
  EXPECT_GT(ratio, 0.4);
  EXPECT_LT(ratio, 0.7);
  EXPECT_EQ(c.issue_cycles[2], u.transformation_steps);
  EXPECT_EQ(c.issue_cycles[3], u.intersection_packets * 4);
  // A list unit step reads an entry or finds the list done; the traversal unit issues node steps,
  // clip faces and the pops of the lists that end (D49).
  EXPECT_EQ(c.issue_cycles[1], u.list_steps + u.list_returns);
  EXPECT_EQ(c.issue_cycles[0], u.traversal_steps + u.clip_steps + u.pop_steps);
  EXPECT_GT(u.pop_steps, 0u);
  EXPECT_GT(u.list_returns, 0u);
}

TEST(DynRtc, ParametersPresetsAndBadSettings) {
  const CycleParams p = prototype_params();
  EXPECT_EQ(p.threads, 64);
  EXPECT_EQ(p.packet, 4);
  EXPECT_EQ(p.stack, 64);
  EXPECT_EQ(p.cache[0].items, 512);
  EXPECT_EQ(p.traversal_depth(), 12);
  EXPECT_EQ(p.transformation_depth(), 9);
  EXPECT_EQ(p.intersection_depth(), 18);
  EXPECT_EQ(cycle_preset("table2").threads, 32);
  EXPECT_EQ(p.pipelines, 1);
  EXPECT_EQ(cycle_preset("standard").pipelines, 4);
  EXPECT_EQ(cycle_preset("standard").threads, 64);
  CycleParams q = p;
  apply_cycle_setting(q, "cache.list.ways=4");
  apply_cycle_setting(q, "clock_mhz=120.5");
  EXPECT_EQ(q.cache[1].ways, 4);
  EXPECT_DOUBLE_EQ(q.clock_mhz, 120.5);
  EXPECT_EQ(describe(q).size(), cycle_param_table().size());
  const auto fails = [](const std::string& kv, const std::string& needle) {
    CycleParams r = prototype_params();
    try {
      apply_cycle_setting(r, kv);
      check_cycle_params(r);
    } catch (const std::runtime_error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(needle), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
      return;
    }
    ADD_FAILURE() << kv << " was accepted";
  };
  fails("threads=0", "threads");
  fails("threads=-3", "threads");
  fails("packet=3", "power of two");
  fails("packet=128", "packet");
  fails("cache.traversal.items=100", "power of two");
  fails("cache.list.ways=1024", "cache.list.ways");
  fails("lat.div=0", "lat.div");
  fails("lat.add=2.5", "integer");
  fails("mem.latency=fast", "not a number");
  fails("cache.bogus.items=8", "unknown --set key 'cache.bogus.items'");
  fails("threads", "KEY=VALUE");
  fails("=4", "KEY=VALUE");
  fails("mem.scene_paths=2", "mem.scene_paths=2");
  fails("mem.scene_paths=4", "mem.scene_paths");
  fails("pipelines=0", "pipelines");
  fails("pipelines=17", "pipelines");
  fails("mem.queue_depth=0", "mem.queue_depth");
  fails("mem.max_burst=0", "mem.max_burst");
  fails("mem.reorder=2", "mem.reorder");
  fails("mem.port_capacity=1", "mem.port_capacity");
  fails("cache.merge_targets=0", "cache.merge_targets");
  fails("cache.request_queue=0", "cache.request_queue");
  fails("cache.memory_queue=0", "cache.memory_queue");
  fails("cache.merge_targets=2.5", "integer");
  fails("routing.responses=0", "routing.responses");
  fails("hostbus.mb_s=0", "hostbus.mb_s");
  fails("hostbus.mb_s=-132", "hostbus.mb_s");
  fails("hostbus.mb_s=inf", "hostbus.mb_s");
  fails("hostbus.burst_words=5", "hostbus.burst_words");
  fails("hostbus.burst_words=0", "hostbus.burst_words");
  // Every memory-interface key with its default, in the table and the resolved configuration.
  const std::map<std::string, double> mem_defaults = {
      {"mem.queue_depth", 8},    {"mem.reorder", 1},          {"mem.max_burst", 8},
      {"mem.port_capacity", 4},  {"cache.merge_targets", 16}, {"cache.request_queue", 4},
      {"cache.memory_queue", 2}, {"routing.responses", 1},    {"hostbus.mb_s", 132},
      {"hostbus.burst_words", 4}};
  for (const auto& [key, value] : mem_defaults) {
    int found = 0;
    for (const CycleParamInfo& i : describe(p))
      if (i.name == key) {
        ++found;
        EXPECT_EQ(i.value, value) << key;
        EXPECT_FALSE(i.unit.empty()) << key;
        EXPECT_FALSE(i.help.empty()) << key;
      }
    EXPECT_EQ(found, 1) << key;
  }
  CycleParams fast = p;
  apply_cycle_setting(fast, "hostbus.mb_s=266.5");  // fractions are fine for a bandwidth
  EXPECT_DOUBLE_EQ(fast.hostbus_mb_s, 266.5);
  // Set in code, out of range: check_cycle_params refuses it in one line naming the key.
  const auto refused = [](CycleParams r, const std::string& line) {
    try {
      check_cycle_params(r);
      ADD_FAILURE() << line << " accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), line);
    }
  };
  CycleParams bad = p;
  bad.mem_queue_depth = 0;
  refused(bad, "bad mem.queue_depth=0: expected 1..1024 requests");
  bad = p;
  bad.cache_merge_targets = -1;
  refused(bad, "bad cache.merge_targets=-1: expected 1..1024 requests");
  bad = p;
  bad.routing_responses = 0;
  refused(bad, "bad routing.responses=0: expected 1..64 responses/cycle");
  bad = p;
  bad.hostbus_mb_s = 0;
  refused(bad, "bad hostbus.mb_s=0: expected 0.001..1000000 MB/s");
  bad = p;
  bad.hostbus_burst_words = 8;
  refused(bad, "bad hostbus.burst_words=8: expected 1..4 words");
  bad = p;
  bad.mem_port_capacity = 1;
  refused(bad, "bad mem.port_capacity=1: expected 2..256 entries");
  // 16 DynRTPs of the prototype's 64 threads: 1024 threads in all, accepted; 128 each: too many.
  CycleParams many = prototype_params();
  apply_cycle_setting(many, "pipelines=16");
  check_cycle_params(many);
  apply_cycle_setting(many, "threads=512");
  try {
    check_cycle_params(many);
    ADD_FAILURE() << "16 x 512 threads accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "bad pipelines=16 with threads=512: 8192 threads in all, at most 4096");
  }
  try {
    cycle_preset("asic");
    ADD_FAILURE() << "preset asic accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("prototype"), std::string::npos);
  }
  // ways must divide items: 8 items, 16 ways.
  CycleParams r = prototype_params();
  apply_cycle_setting(r, "cache.transformation.items=8");
  apply_cycle_setting(r, "cache.transformation.ways=16");
  EXPECT_THROW(check_cycle_params(r), std::runtime_error);
}

// A stack too small for the trees stops the run with the thread program's one-line error (D26).
TEST(DynRtc, StackOverflowIsAnError) {
  const host::BuiltImage b = build("builtin:room", 16, 12);
  CycleParams p = prototype_params();
  p.stack = 2;
  try {
    run_cycle(b.image, p);
    ADD_FAILURE() << "a 2-entry stack was enough";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("stack overflow"), std::string::npos) << e.what();
  }
}

TEST(DynRtc, OnlyFp24AndE7m23ImagesRun) {
  const host::Scene scene = host::load_scene("builtin:cube");
  host::ImageParams ip;
  ip.width = 8;
  ip.height = 8;
  ip.format = ff::Format{7, 20};
  const host::BuiltImage b = host::build_image(scene, ip);
  try {
    run_cycle(b.image, prototype_params());
    ADD_FAILURE() << "e7m20 image accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("fp24 (e7m16) and e7m23"), std::string::npos);
  }
}

// The width study: the same units 31 bits wide (e7m23) are bit-exact to the functional model in
// e7m23, under the covering design; a matrix row is four words instead of three, so the
// transformation cache moves more bytes per miss and holds the same rows.
TEST(DynRtc, E7m23DatapathIsBitExactAndWider) {
  const host::Scene scene = host::load_scene("builtin:room");
  host::ImageParams ip;
  ip.width = kSanitized ? 16 : 48;
  ip.height = kSanitized ? 12 : 36;
  const host::BuiltImage fp24 = host::build_image(scene, ip);
  ip.format = ff::Format{7, 23};
  const host::BuiltImage wide = host::build_image(scene, ip);
  for (const testing::Config& c : configs())
    testing::expect_bit_exact(wide, c, std::string("room e7m23 [") + c.name + "]");
  const CycleFrame a = run_cycle(fp24.image, prototype_params());
  const CycleFrame w = run_cycle(wide.image, prototype_params());
  const auto row = static_cast<std::size_t>(CacheUnit::kTransformation);
  // Bytes per transformation-cache miss: 3 words per row item in fp24, 4 in e7m23.
  EXPECT_EQ(a.caches[row].mem_bytes, 12 * a.caches[row].misses);
  EXPECT_EQ(w.caches[row].mem_bytes, 16 * w.caches[row].misses);
  EXPECT_NE(w.stats_json, a.stats_json);
}

// A stuck run stops with a report naming each waiting thread, its unit, phase, item and rays; the
// report is the same in every program mode (a replayed request keeps its ray mask beside the
// trace the units read).
TEST(DynRtc, WatchdogNamesStuckThreads) {
  const host::BuiltImage b = build("builtin:room", 16, 12);
  CycleParams p = prototype_params();
  p.threads = 2;
  p.watchdog = 20;      // shorter than one memory round trip:
  p.mem_latency = 200;  // the first misses look like a hang
  std::string reports[3];
  for (const ProgramMode mode :
       {ProgramMode::kPerStep, ProgramMode::kPacketFirst, ProgramMode::kAhead}) {
    CycleRunOptions opt;
    opt.programs = mode;
    try {
      run_cycle(b.image, p, opt);
      ADD_FAILURE() << "the watchdog did not fire";
    } catch (const std::runtime_error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("watchdog"), std::string::npos) << m;
      EXPECT_NE(m.find("thread 0: "), std::string::npos) << m;
      EXPECT_NE(m.find("thread 1: "), std::string::npos) << m;
      EXPECT_NE(m.find("dynrtp0.traversal"), std::string::npos) << m;
      // A primary packet of P = 4 rays, all active at the start: mask 0xf.
      EXPECT_NE(m.find("mask 0xf\n"), std::string::npos) << m;
      reports[static_cast<int>(mode)] = m;
    }
  }
  EXPECT_EQ(reports[1], reports[0]);
  EXPECT_EQ(reports[2], reports[0]);
  // With two DynRTPs of two threads each, thread 3 is the second pipeline's.
  p.pipelines = 2;
  try {
    run_cycle(b.image, p);
    ADD_FAILURE() << "the watchdog did not fire";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("thread 3 (dynrtp1): "), std::string::npos) << m;
    EXPECT_NE(m.find("dynrtp1.traversal"), std::string::npos) << m;
  }
}

// --interval: the figures of each interval; their cycle-weighted mean is the frame's figure.
TEST(DynRtc, TimeSeriesAddsUpToTheFrame) {
  const host::BuiltImage b = build("builtin:room", 32, 24);
  CycleRunOptions o;
  o.interval = 5000;
  const CycleFrame c = run_cycle(b.image, prototype_params(), o);
  ASSERT_GE(c.series.size(), 3u);
  EXPECT_EQ(c.series.back().cycle, c.cycles);
  double busy = 0;
  std::uint64_t prev = 0;
  for (const CycleFigures& f : c.series) {
    EXPECT_GT(f.cycle, prev);
    busy += f.usage(2) * static_cast<double>(f.cycle - prev);
    prev = f.cycle;
  }
  EXPECT_NEAR(busy / static_cast<double>(c.cycles), c.figures.usage(2), 1e-9);
}

// --interval is the registry's time series, sampled at every multiple of the interval and at the
// frame's end; no figure or statistic of the frame moves with it.
TEST(DynRtc, TimeSeriesIsTheRegistrysAndMovesNoFigure) {
  const host::BuiltImage b = build("builtin:room", 32, 24);
  const CycleFrame plain = run_cycle(b.image, prototype_params());
  CycleRunOptions o;
  o.interval = 4096;
  const CycleFrame c = run_cycle(b.image, prototype_params(), o);
  EXPECT_EQ(c.cycles, plain.cycles);
  EXPECT_EQ(c.figures.value, plain.figures.value);
  EXPECT_EQ(c.stats_json, plain.stats_json);
  ASSERT_EQ(c.series.size(), (c.cycles + 4095) / 4096);
  for (std::size_t i = 0; i + 1 < c.series.size(); ++i)
    EXPECT_EQ(c.series[i].cycle, 4096 * (i + 1));
  EXPECT_EQ(c.series.back().cycle, c.cycles);
  EXPECT_TRUE(plain.series.empty());
}

// A statistic of the frame's hw/ registry (CycleFrame::stats_json) by its full name.
double stat(const CycleFrame& c, const std::string& name) {
  const std::string key = "\"" + name + "\": {";
  const auto at = c.stats_json.find(key);
  if (at == std::string::npos) {
    ADD_FAILURE() << "no statistic " << name;
    return 0;
  }
  const auto v = c.stats_json.find("\"value\": ", at);
  return std::strtod(c.stats_json.c_str() + v + 9, nullptr);
}

// Each memory-interface key moves a small frame in the expected direction, and the statistics
// show why; the hits stay bit-exact (the timing changes, never the result).
TEST(DynRtc, MemoryKeysMoveTheFrame) {
  const host::BuiltImage b = build("builtin:room", 32, 24);
  // The DynRTC's traffic alone: without shading the RGS reads nothing (its frame-buffer writes
  // stay, on their own bank and port), a one-cycle hit sink, and 64-item caches so that the
  // memory interface, not the units, sets the pace (each key's effect is then well above the
  // frame's cycle-to-cycle noise).
  CycleRunOptions hits;
  hits.shading.shade = false;
  const auto run = [&](std::vector<std::string> set) {
    CycleParams p = prototype_params();
    p.rgs_depth = 1;
    for (const char* kv :
         {"cache.traversal.items=64", "cache.list.items=64", "cache.transformation.items=64"})
      apply_cycle_setting(p, kv);
    for (const auto& kv : set)
      apply_cycle_setting(p, kv);
    return run_cycle(b.image, p, hits);
  };
  const CycleFrame base = run({});
  const auto same_result = [&](const CycleFrame& c, const std::string& what) {
    EXPECT_EQ(c.frame.rgb, base.frame.rgb) << what;
    EXPECT_EQ(c.frame.units.requests, base.frame.units.requests) << what;
  };
  const auto merges = [](const CycleFrame& c) {
    std::uint64_t n = 0;
    for (const auto& cc : c.caches)
      n += cc.merges;
    return n;
  };
  const auto max_queue = [](const CycleFrame& c) {
    double q = 0;
    for (int bank = 3; bank <= 5; ++bank)
      q = std::max(q, stat(c, "mi.ctrl.bank" + std::to_string(bank) + ".max_queue"));
    return q;
  };

  // mem.queue_depth: one request per bank queue holds the routing behind every busy bank.
  const CycleFrame q1 = run({"mem.queue_depth=1"});
  same_result(q1, "mem.queue_depth=1");
  EXPECT_GT(max_queue(base), 1);
  EXPECT_EQ(max_queue(q1), 1);
  EXPECT_GT(q1.cycles, base.cycles);

  // cache.merge_targets: 1 = no secondary miss is merged; the cache waits for the fill instead.
  const CycleFrame t1 = run({"cache.merge_targets=1"});
  same_result(t1, "cache.merge_targets=1");
  EXPECT_GT(merges(base), 0u);
  EXPECT_EQ(merges(t1), 0u);
  EXPECT_GT(t1.cycles, base.cycles);

  // cache.request_queue: a 1-entry FIFO holds a unit whenever its cache waits.
  const CycleFrame r1 = run({"cache.request_queue=1"});
  same_result(r1, "cache.request_queue=1");
  EXPECT_GT(r1.cycles, base.cycles);

  // cache.memory_queue: one miss at a time towards the routing, one fill at a time back.
  const CycleFrame m1 = run({"cache.memory_queue=1"});
  same_result(m1, "cache.memory_queue=1");
  EXPECT_GT(m1.cycles, base.cycles);

  // routing.responses: the broadcast (and the controller's port to it) takes two responses per
  // cycle, so the controller hardly ever holds a finished read for the port. (The frame's time is
  // not monotone in it: earlier fills move contention to the caches' fill channels.)
  const CycleFrame w2 = run({"routing.responses=2"});
  same_result(w2, "routing.responses=2");
  EXPECT_GT(stat(base, "mi.ctrl.stall_cycles"), 100);
  EXPECT_LT(stat(w2, "mi.ctrl.stall_cycles"), stat(base, "mi.ctrl.stall_cycles") / 10);

  // mem.port_capacity: with 1-entry bank queues on one shared path the port's request channel
  // is the buffer in front of the banks; a larger one holds the routing (and the caches behind
  // it) less often.
  const auto port = [&](int capacity) {
    return run({"mem.scene_paths=1", "mem.queue_depth=1",
                "mem.port_capacity=" + std::to_string(capacity)});
  };
  const CycleFrame pc2 = port(2), pc4 = port(4), pc16 = port(16);
  same_result(pc16, "mem.port_capacity=16");
  EXPECT_EQ(stat(pc2, "mi.ctrl.caches.req.max_occupancy"), 2);
  EXPECT_EQ(stat(pc16, "mi.ctrl.caches.req.max_occupancy"), 16);
  EXPECT_GT(stat(pc2, "mi.routing.stall_cycles"), stat(pc4, "mi.routing.stall_cycles"));
  EXPECT_GT(stat(pc4, "mi.routing.stall_cycles"), 10 * stat(pc16, "mi.routing.stall_cycles"));
  EXPECT_LT(pc16.cycles, pc2.cycles);

  // mem.reorder and mem.max_burst act on a shared issue path: the scene banks on one path.
  const std::string path = "mi.ctrl.path3.bank_switches";
  const CycleFrame shared = run({"mem.scene_paths=1"});
  const CycleFrame fifo = run({"mem.scene_paths=1", "mem.reorder=0"});
  const CycleFrame burst1 = run({"mem.scene_paths=1", "mem.max_burst=1"});
  same_result(fifo, "mem.reorder=0");
  same_result(burst1, "mem.max_burst=1");
  EXPECT_GT(stat(fifo, path), stat(shared, path));
  EXPECT_GT(fifo.cycles, shared.cycles);
  EXPECT_GT(stat(burst1, path), stat(shared, path));
  EXPECT_GT(burst1.cycles, shared.cycles);
}

// The host-bus keys shape the memory system the chip builds (a frame uploads nothing): twice the
// bandwidth, half the upload time; one-word bursts, four times the write requests.
TEST(DynRtc, HostBusKeysShapeTheUpload) {
  const auto upload = [](const std::vector<std::string>& set, std::uint64_t& writes) {
    CycleParams p = prototype_params();
    for (const auto& kv : set)
      apply_cycle_setting(p, kv);
    check_cycle_params(p);
    memif::MemoryImage img(ff::kFp24, 16384);
    hw::Kernel k;
    memif::MemorySystem mi(k, img, memory_system_config(p));
    const std::vector<std::uint32_t> words(4096, 0x5A5A5A5Au);  // 16 KB
    mi.host().upload(memif::kShadingBank, 0, words);
    const std::uint64_t cycles = k.run_to_completion([&] { return mi.idle(); }, 100000000);
    EXPECT_EQ(mi.host().bytes_sent(), 16384u);
    EXPECT_EQ(img.word(memif::kShadingBank, 4095), 0x5A5A5A5Au);
    writes = k.stats()
                 .get_counter("mi.ctrl.bank" + std::to_string(memif::kShadingBank) + ".writes")
                 .value;
    return cycles;
  };
  std::uint64_t w132 = 0, w264 = 0, w1 = 0, w33 = 0;
  const std::uint64_t c132 = upload({}, w132);
  const std::uint64_t c264 = upload({"hostbus.mb_s=264"}, w264);
  const std::uint64_t c33 = upload({"hostbus.mb_s=33.5"}, w33);
  const std::uint64_t c1 = upload({"hostbus.burst_words=1"}, w1);
  // 16 KB at 132 MB/s and 90 MHz: about 10,650 cycles.
  EXPECT_NEAR(static_cast<double>(c132), 16384.0 * 90e6 / (132.0 * 1048576.0), 5);
  EXPECT_NEAR(static_cast<double>(c264) * 2, static_cast<double>(c132), 6);
  EXPECT_NEAR(static_cast<double>(c33) * 33.5, static_cast<double>(c132) * 132, 132 * 6);
  EXPECT_EQ(w132, 1024u);
  EXPECT_EQ(w264, 1024u);
  EXPECT_EQ(w1, 4096u);
  EXPECT_NEAR(static_cast<double>(c1), static_cast<double>(c132), 5);
}

}  // namespace
}  // namespace saarcor::units
