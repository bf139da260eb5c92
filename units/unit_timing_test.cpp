// Exact-cycle tests of the DynRTP units in isolation (units/cycle_unit.h,
// units/dynrtc_units.h; the style of memif/cache_test.cpp): each unit is built alone on a
// hw::Kernel with mock neighbours (a scripted thread table, a source pushing thread ids on an
// input path, a sink popping its output paths) and, where it reads scene data, the real per-type
// cache of a memif::MemorySystem over a random scene image. Every expected cycle is written as a
// sum of named latencies, and a comment says which timing rule each assertion pins (what would
// move it if that rule changed).
//
// The latencies every sum uses (units/cycle_unit.cpp, units/dynrtp.cpp):
//   kPathLatency    a thread path is a channel of latency 1: pushed in cycle s, the unit accepts
//                   (pops) it in s + 1 (and a sink pops what a unit pushes one cycle later);
//   kReadyToIssue   CycleUnit::evaluate runs deliver, issue, receive, accept in that order, so a
//                   thread that becomes ready in cycle x (accepted with nothing to fetch, or its
//                   last cache response received) issues in x + 1 at the earliest;
//   steps - 1       a request holds the issue slot for Request::steps cycles; it enters the
//                   pipeline with its last step;
//   depth           the unit's pipeline depth from the fp latencies (units/cycle_params.h);
//   hit latency     memif::CacheConfig::hit_latency: a hit pushed in c is poppable in c + 2.
#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "hw/kernel.h"
#include "memif/cache.h"
#include "memif/image_format.h"
#include "memif/memory_system.h"
#include "memif/test_traffic.h"
#include "units/cycle_params.h"
#include "units/dynrtc_units.h"
#include "units/unit_testing.h"

namespace saarcor::units {
namespace {

using testing::kDone;
using testing::ScriptedThreads;

using memif::ItemType;

constexpr int kP = 4;  // rays per packet (the prototype)
constexpr std::uint64_t kMask = (1u << kP) - 1;
constexpr int kPathLatency = 1;
constexpr int kReadyToIssue = 1;

// The prototype's fp latencies and the unit depths derived from them.
const CycleParams& params() {
  static const CycleParams p = prototype_params();
  return p;
}

// Requests as the thread program forms them (units/thread_program.h struct Request).
Request node(std::uint32_t n) {
  return {UnitId::kTraversal, Phase::kTraverse, n, 1, kMask};
}
Request face(Phase clip, std::uint32_t f) {
  return {UnitId::kTraversal, clip, f, 1, kMask};
}
Request list_entry(std::uint32_t e) {
  return {UnitId::kList, Phase::kList, e, 1, kMask};
}
Request generate(int steps) {
  return {UnitId::kTransformation, Phase::kGenerate, memif::kNone, steps, kMask};
}
Request transform_object(std::uint32_t first_row, int steps) {
  return {UnitId::kTransformation, Phase::kTransformObject, first_row, steps, kMask};
}
Request intersect() {
  return {UnitId::kIntersection, Phase::kIntersect, memif::kNone, kP, kMask};
}
Request shade() {
  return {UnitId::kRgs, Phase::kShadeSurface, memif::kNone, 1, kMask};
}
// The neighbour upstream: pushes thread `second` onto the path at cycle `first` (or later while
// the path is full), one per cycle.
class Source : public hw::Module {
 public:
  Source(hw::Kernel& k, std::string name, ThreadPath& path,
         std::vector<std::pair<std::uint64_t, ThreadToken>> script)
      : hw::Module(k, std::move(name)), path_(path), script(std::move(script)) {
    produces(path_);
  }
  int evaluate() override {
    if (next_ < script.size() && script[next_].first <= now() && path_.can_push()) {
      path_.push(script[next_].second);
      pushed_at.push_back(now());
      ++next_;
      return 1;
    }
    return 0;
  }
  ThreadPath& path_;
  std::vector<std::pair<std::uint64_t, ThreadToken>> script;
  std::vector<std::uint64_t> pushed_at;

 private:
  std::size_t next_ = 0;
};

// The neighbours downstream: pops every path as soon as a thread is visible, records the cycle.
class Sink : public hw::Module {
 public:
  struct Got {
    std::uint64_t cycle;
    ThreadToken thread;
    std::size_t path;  // index into the paths given
  };
  Sink(hw::Kernel& k, std::string name, std::vector<ThreadPath*> paths)
      : hw::Module(k, std::move(name)), paths_(std::move(paths)) {
    for (ThreadPath* p : paths_)
      consumes(*p);
  }
  int evaluate() override {
    int n = 0;
    for (std::size_t i = 0; i < paths_.size(); ++i)
      if (paths_[i]->can_pop()) {
        got.push_back({now(), paths_[i]->pop(), i});
        ++n;
      }
    return n;
  }
  // The cycle thread t was popped (kNever if it was not).
  std::uint64_t got_at(ThreadToken t) const {
    for (const Got& g : got)
      if (g.thread == t) return g.cycle;
    ADD_FAILURE() << "thread " << t << " never left the unit";
    return hw::kNever;
  }
  std::vector<Got> got;

 private:
  std::vector<ThreadPath*> paths_;
};

ThreadPath& path(hw::Kernel& k, const std::string& name) {
  return k.make_channel<ThreadToken>(name, 8, kPathLatency);
}

std::uint64_t u64(int v) {
  return static_cast<std::uint64_t>(v);
}

// (1) Traversal node step. Thread 0 misses node 7 (warming the line), thread 1 asks for node 7
// later and hits: accepted in c (its one node request goes to the cache in c), the hit is
// poppable in c + hit, the thread issues one cycle later, leaves after the depth.
TEST(UnitTimingTraversal, NodeStepHitLeavesAfterHitReadyIssueAndDepth) {
  memif::MemoryImage img = memif::testing::random_scene_image(ff::kFp24, 1);
  hw::Kernel k;
  memif::MemorySystem mi(k, img);
  memif::Cache& cache = mi.cache(0, ItemType::kNode);
  ScriptedThreads threads(k, {{node(7), shade()}, {node(7), shade()}});
  const int depth = params().lat_add + params().lat_div + params().lat_cmp;  // 3 + 8 + 1
  ASSERT_EQ(depth, 12);
  ASSERT_EQ(depth, params().traversal_depth());
  auto& tu = k.make<TraversalUnit>("t.traversal", threads, depth, cache);
  ThreadPath& b = path(k, "t.path_b");
  ThreadPath& g = path(k, "t.path_g");
  tu.add_input(&b);
  tu.set_output(UnitId::kRgs, &g);
  const std::uint64_t pushed1 = 100;  // long after thread 0's miss has been served
  Source src(k, "t.source", b, {{0, 0}, {pushed1, 1}});
  Sink sink(k, "t.sink", {&g});
  k.run_to_completion([&] { return sink.got.size() == 2; }, 1000);

  const int hit = cache.config().hit_latency;
  EXPECT_EQ(hit, 2);    // memif::CacheConfig's default
  const int steps = 1;  // one packet-node step
  const std::uint64_t c1 = pushed1 + kPathLatency;
  // Pins: the fetch goes out in the accept cycle (accept()), hit latency, receive-then-issue order.
  EXPECT_EQ(threads.issued_at(1), c1 + u64(hit + kReadyToIssue));
  // Pins additionally: done_at = issue + steps - 1 + depth (issue()), and deliver on the path.
  const std::uint64_t expected1 =
      c1 + u64(hit + kReadyToIssue + (steps - 1) + depth + kPathLatency);
  EXPECT_EQ(sink.got_at(1), expected1);  // 101 + 2 + 1 + 0 + 12 + 1 = 117

  // Thread 0 missed: the memory round trip derived in memif/cache_test.cpp (bank start 4 cycles
  // after the push, last of w words, data 4 cycles later, routing and fill 2, poppable 1 later)
  // replaces the hit latency.
  const int w = img.item_words(ItemType::kNode);
  const int miss = 4 + w - 1 + 4 + 2 + 1;
  const std::uint64_t c0 = 0 + kPathLatency;
  EXPECT_EQ(sink.got_at(0), c0 + u64(miss + kReadyToIssue + (steps - 1) + depth + kPathLatency));
  EXPECT_EQ(cache.misses(), 1u);
  EXPECT_EQ(cache.hits(), 1u);
  EXPECT_EQ(tu.issue_cycles(), 2u);
  EXPECT_EQ(tu.requests_served(), 2u);
  EXPECT_EQ(tu.occupancy(), 0);
}

// The list unit has the same shape with the list cache and depth lat_cmp (1): one entry fetched in
// the accept cycle, a hit, issue, one cycle of mailbox compare.
TEST(UnitTimingList, EntryHitLeavesAfterHitReadyIssueAndDepth) {
  memif::MemoryImage img = memif::testing::random_scene_image(ff::kFp24, 2);
  hw::Kernel k;
  memif::MemorySystem mi(k, img);
  memif::Cache& cache = mi.cache(0, ItemType::kList);
  const Request next = transform_object(30, kP + 1);  // path d
  ScriptedThreads threads(k, {{list_entry(11), next}, {list_entry(11), next}});
  const int depth = params().lat_cmp;
  ASSERT_EQ(depth, 1);
  auto& lu = k.make<ListUnit>("t.list", threads, depth, cache);
  ThreadPath& c = path(k, "t.path_c");
  ThreadPath& d = path(k, "t.path_d");
  lu.add_input(&c);
  lu.set_output(UnitId::kTransformation, &d);
  const std::uint64_t pushed1 = 100;
  Source src(k, "t.source", c, {{0, 0}, {pushed1, 1}});
  Sink sink(k, "t.sink", {&d});
  k.run_to_completion([&] { return sink.got.size() == 2; }, 1000);

  const int hit = cache.config().hit_latency;
  const std::uint64_t c1 = pushed1 + kPathLatency;
  EXPECT_EQ(sink.got_at(1), c1 + u64(hit + kReadyToIssue + depth + kPathLatency));  // 101+2+1+1+1
  EXPECT_EQ(cache.hits(), 1u);
  EXPECT_EQ(cache.misses(), 1u);
}

// A thread back from an object whose top-level list is done (D49: the request names no entry,
// memif::kNone) fetches nothing: it issues one cycle after its accept and leaves for the traversal
// unit's pop after the mailbox compare's depth. Were it fetched, it would wait for a miss.
TEST(UnitTimingList, DoneListFetchesNothingAndPassesOnToThePop) {
  memif::MemoryImage img = memif::testing::random_scene_image(ff::kFp24, 2);
  hw::Kernel k;
  memif::MemorySystem mi(k, img);
  memif::Cache& cache = mi.cache(0, ItemType::kList);
  const Request done_list{UnitId::kList, Phase::kList, memif::kNone, 1, kMask};
  const Request pop{UnitId::kTraversal, Phase::kPop, memif::kNone, 1, kMask};
  ScriptedThreads threads(k, {{done_list, pop}});
  const int depth = params().lat_cmp;
  auto& lu = k.make<ListUnit>("t.list", threads, depth, cache);
  ThreadPath& c = path(k, "t.path_c");
  ThreadPath& to_traversal = path(k, "t.list_to_traversal");
  lu.add_input(&c);
  lu.set_output(UnitId::kTraversal, &to_traversal);
  Source src(k, "t.source", c, {{0, 0}});
  Sink sink(k, "t.sink", {&to_traversal});
  k.run_to_completion([&] { return sink.got.size() == 1; }, 1000);

  const std::uint64_t issue = 0 + kPathLatency + kReadyToIssue;
  EXPECT_EQ(threads.issued_at(0), issue);
  EXPECT_EQ(sink.got_at(0), issue + u64(depth + kPathLatency));  // 2 + 1 + 1
  EXPECT_EQ(cache.requests_count(), 0u);
}

// The pop engine (D49, TraversalUnit::extra): three threads arrive on path f one cycle apart, each
// with a pop request (nothing fetched, one issue cycle). The thread program says how many stack
// entries each pop reads (Request::pop_cycles of the request after it): thread 0 one (the top
// entry is popped), thread 1 four (three entries dropped, then one popped), thread 2 one. Each
// reaches the engine at its issue + depth. Thread 0 leaves then; thread 1 reads one entry there
// and the other three in the next cycles; thread 2 reaches the engine while thread 1 is in its
// queue, waits, and reads its entry the cycle after thread 1's last. Were drops free (the old
// rule), all three would leave at issue + depth.
TEST(UnitTimingTraversal, PopEngineReadsOneStackEntryPerCycleAndQueues) {
  memif::MemoryImage img = memif::testing::random_scene_image(ff::kFp24, 5);
  hw::Kernel k;
  memif::MemorySystem mi(k, img);
  memif::Cache& cache = mi.cache(0, ItemType::kNode);
  const Request pop{UnitId::kTraversal, Phase::kPop, memif::kNone, 1, kMask};
  const auto after = [](int entries) {
    Request r = shade();  // the next request: the top level ended, or any other unit
    r.pop_cycles = static_cast<std::uint16_t>(entries);
    return r;
  };
  ScriptedThreads threads(k, {{pop, after(1)}, {pop, after(4)}, {pop, after(1)}});
  const int depth = params().traversal_depth();
  auto& tu = k.make<TraversalUnit>("t.traversal", threads, depth, cache);
  ThreadPath& f = path(k, "t.path_f");
  ThreadPath& g = path(k, "t.path_g");
  tu.add_input(&f);
  tu.set_output(UnitId::kRgs, &g);
  Source src(k, "t.source", f, {{0, 0}, {1, 1}, {2, 2}});
  Sink sink(k, "t.sink", {&g});
  k.run_to_completion([&] { return sink.got.size() == 3; }, 1000);

  const std::uint64_t issue0 = 0 + kPathLatency + kReadyToIssue;  // a pop fetches nothing
  EXPECT_EQ(threads.issued_at(0), issue0);
  EXPECT_EQ(threads.issued_at(1), issue0 + 1);
  EXPECT_EQ(threads.issued_at(2), issue0 + 2);
  const std::uint64_t stage1 = issue0 + 1 + u64(depth);           // thread 1 reaches the engine
  EXPECT_EQ(sink.got_at(0), issue0 + u64(depth + kPathLatency));  // 2 + 12 + 1
  EXPECT_EQ(sink.got_at(1), stage1 + u64(3 + kPathLatency));      // + 3 dropped entries
  EXPECT_EQ(sink.got_at(2), stage1 + u64(3 + 1 + kPathLatency));  // behind thread 1
  EXPECT_EQ(tu.issue_cycles(), 3u);
  EXPECT_EQ(cache.requests_count(), 0u);
}

// (2) Transformation: a ray-generation request (no fetch: the matrix comes from the RGS) holds the
// issue slot for its steps, P + 1 with a shared origin and 2P without (D31): two packets arriving
// back to back issue `steps` cycles apart, and each leaves steps - 1 + depth after its first step.
// (The step counts themselves are the thread program's (ThreadProgram::transform_steps); the mock
// table scripts them, so this pins the unit's side: Request::steps cycles in the issue slot.)
TEST(UnitTimingTransformation, SharedOriginTakesPPlusOneIssueCyclesOtherwiseTwoP) {
  const int depth = params().lat_mul + params().lat_add + params().lat_add;  // 3 + 3 + 3
  ASSERT_EQ(depth, 9);
  ASSERT_EQ(depth, params().transformation_depth());
  const int shared_origin_steps = kP + 1;  // one origin step + P direction steps
  const int separate_origin_steps = 2 * kP;
  for (const int steps : {shared_origin_steps, separate_origin_steps}) {
    SCOPED_TRACE(steps);
    memif::MemoryImage img = memif::testing::random_scene_image(ff::kFp24, 3);
    hw::Kernel k;
    memif::MemorySystem mi(k, img);
    const Request next = face(Phase::kClipTop, 0);  // path b
    ScriptedThreads threads(k, {{generate(steps), next}, {generate(steps), next}});
    auto& xu =
        k.make<TransformationUnit>("t.transformation", threads, depth, mi.cache(0, ItemType::kRow));
    ThreadPath& a = path(k, "t.path_a");
    ThreadPath& b = path(k, "t.path_b");
    xu.add_input(&a);
    xu.set_output(UnitId::kTraversal, &b);
    Source src(k, "t.source", a, {{0, 0}, {0, 1}});  // pushed in cycles 0 and 1
    Sink sink(k, "t.sink", {&b});
    k.run_to_completion([&] { return sink.got.size() == 2; }, 1000);

    const std::uint64_t c0 = 0 + kPathLatency;
    const std::uint64_t issue0 = c0 + kReadyToIssue;
    EXPECT_EQ(threads.issued_at(0), issue0);
    // Pins the issue-slot occupancy: the second packet (ready since cycle 2) waits `steps` cycles.
    EXPECT_EQ(threads.issued_at(1), issue0 + u64(steps));
    // Pins done_at = first step + steps - 1 + depth.
    EXPECT_EQ(sink.got_at(0), issue0 + u64((steps - 1) + depth + kPathLatency));
    EXPECT_EQ(sink.got_at(1), issue0 + u64(steps + (steps - 1) + depth + kPathLatency));
    EXPECT_EQ(xu.issue_cycles(), u64(2 * steps));  // the usage Table 4 reports
    EXPECT_EQ(xu.requests_served(), 2u);
  }
}

// An object transformation reads the instance's six rows, one cache request per cycle (D32): with
// all six rows hitting, the thread is ready when the last row's hit arrives.
TEST(UnitTimingTransformation, ObjectRowsAreFetchedOnePerCycleBeforeIssue) {
  memif::MemoryImage img = memif::testing::random_scene_image(ff::kFp24, 4);
  hw::Kernel k;
  memif::MemorySystem mi(k, img);
  memif::Cache& cache = mi.cache(0, ItemType::kRow);
  const int depth = params().transformation_depth();
  const int steps = kP + 1;
  const Request next = face(Phase::kClipBottom, 0);  // path b
  ScriptedThreads threads(
      k, {{transform_object(30, steps), next}, {transform_object(30, steps), next}});
  auto& xu = k.make<TransformationUnit>("t.transformation", threads, depth, cache);
  ThreadPath& d = path(k, "t.path_d");
  ThreadPath& b = path(k, "t.path_b");
  xu.add_input(&d);
  xu.set_output(UnitId::kTraversal, &b);
  const std::uint64_t pushed1 = 200;
  Source src(k, "t.source", d, {{0, 0}, {pushed1, 1}});
  Sink sink(k, "t.sink", {&b});
  k.run_to_completion([&] { return sink.got.size() == 2; }, 1000);

  const int rows = memif::kInstanceRows;  // 6: matrix, header, object box
  const int hit = cache.config().hit_latency;
  const std::uint64_t c1 = pushed1 + kPathLatency;
  // Rows go out in c1 .. c1 + rows - 1; the last hit is poppable hit cycles after its push.
  const std::uint64_t issue1 = c1 + u64((rows - 1) + hit + kReadyToIssue);
  EXPECT_EQ(threads.issued_at(1), issue1);  // 201 + 5 + 2 + 1 = 209
  EXPECT_EQ(sink.got_at(1), issue1 + u64((steps - 1) + depth + kPathLatency));
  EXPECT_EQ(cache.hits(), u64(rows));
  EXPECT_EQ(cache.misses(), u64(rows));
}

// (3) Intersection: P cycles per packet (one ray per cycle, D30), nothing fetched.
TEST(UnitTimingIntersection, PacketTakesPIssueCycles) {
  hw::Kernel k;
  const int depth = params().lat_div + params().lat_mul + params().lat_add + params().lat_add +
                    params().lat_cmp;  // 8 + 3 + 3 + 3 + 1
  ASSERT_EQ(depth, 18);
  ASSERT_EQ(depth, params().intersection_depth());
  const Request next = node(7);  // path f
  ScriptedThreads threads(k, {{intersect(), next}, {intersect(), next}});
  auto& iu = k.make<IntersectionUnit>("t.intersection", threads, depth);
  ThreadPath& e = path(k, "t.path_e");
  ThreadPath& f = path(k, "t.path_f");
  iu.add_input(&e);
  iu.set_output(UnitId::kTraversal, &f);
  Source src(k, "t.source", e, {{0, 0}, {0, 1}});
  Sink sink(k, "t.sink", {&f});
  k.run_to_completion([&] { return sink.got.size() == 2; }, 1000);

  const int steps = kP;
  const std::uint64_t issue0 = 0 + kPathLatency + kReadyToIssue;
  EXPECT_EQ(threads.issued_at(0), issue0);
  EXPECT_EQ(threads.issued_at(1), issue0 + u64(steps));  // pins P cycles in the issue slot
  EXPECT_EQ(sink.got_at(0), issue0 + u64((steps - 1) + depth + kPathLatency));  // 2+3+18+1 = 24
  EXPECT_EQ(sink.got_at(1), issue0 + u64(steps + (steps - 1) + depth + kPathLatency));
  EXPECT_EQ(iu.issue_cycles(), u64(2 * steps));
}

// (4) Chained clip faces (TraversalUnit::chains): the six faces of a box issue on consecutive
// cycles (each is one request, one execute) and the thread goes through the pipeline once, after
// the last face; a second thread waits behind the whole chain. Were chains() false, face 0 would
// leave on the traversal loop path and come back depth + 2 cycles later, face by face.
TEST(UnitTimingTraversal, ChainedClipFacesIssueBackToBackAndLeaveOnce) {
  memif::MemoryImage img = memif::testing::random_scene_image(ff::kFp24, 5);
  hw::Kernel k;
  memif::MemorySystem mi(k, img);
  memif::Cache& cache = mi.cache(0, ItemType::kNode);
  const int faces = 6;
  std::vector<Request> top, bottom;
  for (int i = 0; i < faces; ++i) {
    top.push_back(face(Phase::kClipTop, static_cast<std::uint32_t>(i)));
    bottom.push_back(face(Phase::kClipBottom, static_cast<std::uint32_t>(i)));
  }
  top.push_back(shade());
  bottom.push_back(shade());
  ScriptedThreads threads(k, {top, bottom});
  const int depth = params().traversal_depth();
  auto& tu = k.make<TraversalUnit>("t.traversal", threads, depth, cache);
  ThreadPath& loop = path(k, "t.traversal_loop");
  ThreadPath& b = path(k, "t.path_b");
  ThreadPath& g = path(k, "t.path_g");
  tu.add_input(&loop);
  tu.add_input(&b);
  tu.set_output(UnitId::kTraversal, &loop);
  tu.set_output(UnitId::kRgs, &g);
  Source src(k, "t.source", b, {{0, 0}, {0, 1}});
  Sink sink(k, "t.sink", {&g});
  k.run_to_completion([&] { return sink.got.size() == 2; }, 1000);

  const std::uint64_t issue0 = 0 + kPathLatency + kReadyToIssue;  // faces read nothing
  for (int i = 0; i < faces; ++i) {
    EXPECT_EQ(threads.issued_at(0, i), issue0 + u64(i)) << "top face " << i;
    EXPECT_EQ(threads.issued_at(1, i), issue0 + u64(faces + i)) << "bottom face " << i;
  }
  // One pipeline pass after the last face: issue0 + (faces - 1) + depth, then the path.
  EXPECT_EQ(sink.got_at(0), issue0 + u64((faces - 1) + depth + kPathLatency));  // 2+5+12+1 = 20
  EXPECT_EQ(sink.got_at(1), issue0 + u64(faces + (faces - 1) + depth + kPathLatency));
  EXPECT_EQ(loop.total_pushes(), 0u);  // never back through the loop path
  EXPECT_EQ(tu.issue_cycles(), u64(2 * faces));
  EXPECT_EQ(tu.requests_served(), u64(2 * faces));
  EXPECT_EQ(cache.requests_count(), 0u);  // clip faces fetch nothing
}

// A clip face followed by a node step does not chain (chains() needs the same phase): the node
// step goes through the pipeline and back on the loop path before its fetch.
TEST(UnitTimingTraversal, ClipFaceDoesNotChainIntoANodeStep) {
  memif::MemoryImage img = memif::testing::random_scene_image(ff::kFp24, 6);
  hw::Kernel k;
  memif::MemorySystem mi(k, img);
  memif::Cache& cache = mi.cache(0, ItemType::kNode);
  ScriptedThreads threads(k, {{face(Phase::kClipTop, 5), node(3), shade()}});
  const int depth = params().traversal_depth();
  auto& tu = k.make<TraversalUnit>("t.traversal", threads, depth, cache);
  ThreadPath& loop = path(k, "t.traversal_loop");
  ThreadPath& b = path(k, "t.path_b");
  ThreadPath& g = path(k, "t.path_g");
  tu.add_input(&loop);
  tu.add_input(&b);
  tu.set_output(UnitId::kTraversal, &loop);
  tu.set_output(UnitId::kRgs, &g);
  Source src(k, "t.source", b, {{0, 0}});
  Sink sink(k, "t.sink", {&g});
  k.run_to_completion([&] { return sink.got.size() == 1; }, 1000);

  const std::uint64_t issue_face = 0 + kPathLatency + kReadyToIssue;
  // Face: depth, then the loop path back in; the node fetch is accepted on arrival.
  const std::uint64_t back_in = issue_face + u64(depth + kPathLatency);
  EXPECT_EQ(loop.total_pushes(), 1u);
  EXPECT_EQ(cache.misses(), 1u);
  const int w = img.item_words(ItemType::kNode);
  const int miss = 4 + w - 1 + 4 + 2 + 1;  // memif/cache_test.cpp
  EXPECT_EQ(threads.issued_at(0, 1), back_in + u64(miss + kReadyToIssue));
}

// (5a) Input priorities (D25): with threads waiting on two paths in the same cycle, the unit takes
// the one on the path added first (for the transformation unit d before a), one per cycle.
TEST(UnitTimingInputs, HigherPriorityPathIsAcceptedFirst) {
  memif::MemoryImage img = memif::testing::random_scene_image(ff::kFp24, 7);
  hw::Kernel k;
  memif::MemorySystem mi(k, img);
  const int steps = kP + 1;
  const int depth = params().transformation_depth();
  const Request next = face(Phase::kClipTop, 0);
  ScriptedThreads threads(k, {{generate(steps), next}, {generate(steps), next}});
  auto& xu =
      k.make<TransformationUnit>("t.transformation", threads, depth, mi.cache(0, ItemType::kRow));
  ThreadPath& a = path(k, "t.path_a");
  ThreadPath& d = path(k, "t.path_d");
  ThreadPath& b = path(k, "t.path_b");
  xu.add_input(&d);  // in-flight work first
  xu.add_input(&a);  // new rays
  xu.set_output(UnitId::kTraversal, &b);
  Source on_a(k, "t.source_a", a, {{0, 0}});  // registered first: evaluation order must not matter
  Source on_d(k, "t.source_d", d, {{0, 1}});
  Sink sink(k, "t.sink", {&b});
  k.run_to_completion([&] { return sink.got.size() == 2; }, 1000);

  const std::uint64_t visible = 0 + kPathLatency;  // both threads wait from cycle 1
  ASSERT_EQ(threads.issues.size(), 2u);
  EXPECT_EQ(threads.issues[0].thread, 1u);  // the thread on d
  EXPECT_EQ(threads.issued_at(1), visible + kReadyToIssue);
  // The thread on a, accepted one cycle later, issues when the d thread's steps are done.
  EXPECT_EQ(threads.issued_at(0), visible + u64(kReadyToIssue + steps));
  EXPECT_EQ(sink.got_at(1), visible + u64(kReadyToIssue + (steps - 1) + depth + kPathLatency));
}

// The RGS's neighbours: path g in (a source pushing returning threads), path a out (a sink).
struct RgsNeighbours {
  RgsNeighbours(hw::Kernel& k, RaySource& rgs)
      : a(path(k, "t.path_a")),
        g(path(k, "t.path_g")),
        src(k, "t.source", g, {}),
        sink(k, "t.sink", {&a}) {
    rgs.add_input(&g);
    rgs.set_output(UnitId::kTransformation, &a);
  }
  ThreadPath& a;
  ThreadPath& g;
  Source src;
  Sink sink;
};

// (5b) Ray source: one packet admitted per granted cycle to the oldest free thread, on path a;
// a returning packet runs its RGS phase, retires after the RGS depth, and its thread takes the
// next packet in that same cycle.
TEST(UnitTimingRaySource, AdmitsOnePacketPerGrantedCycleAndReadmitsARetiredThread) {
  hw::Kernel k;
  const int packets = 3, threads_count = 2;
  const Request first = generate(kP + 1);  // what a primary packet asks the transformation for
  ScriptedThreads threads(k, {{}, {}}, {first}, packets);
  RayGenerationController rgc(packets, 1);
  // Any depth (the chip takes the rgs.depth key): the re-admission below adds it.
  const int rgs_depth = 1;
  auto& rgs = k.make<RaySource>("t.rgs", threads, rgs_depth, rgc, 0, 0, threads_count);
  RgsNeighbours n(k, rgs);
  Source& src = n.src;
  Sink& sink = n.sink;
  k.run_to_completion([&] { return sink.got.size() == 2; }, 1000);

  // One pipeline: every cycle is granted; packets 0 and 1 go out in cycles 0 and 1.
  ASSERT_EQ(threads.starts.size(), 2u);
  for (int i = 0; i < threads_count; ++i) {
    EXPECT_EQ(threads.starts[static_cast<std::size_t>(i)].cycle, u64(i));
    EXPECT_EQ(threads.starts[static_cast<std::size_t>(i)].thread, static_cast<std::uint32_t>(i));
    EXPECT_EQ(threads.starts[static_cast<std::size_t>(i)].packet, i);
    EXPECT_EQ(sink.got_at(static_cast<ThreadToken>(i)), u64(i + kPathLatency));
  }
  EXPECT_EQ(rgs.packets_admitted(), 2u);  // no free thread left for packet 2

  // Thread 0 comes back on path g with its last RGS phase.
  threads.set_script(0, {shade(), kDone});
  const std::uint64_t returned = k.now() + 10;
  src.script.push_back({returned, 0});
  k.run_to_completion([&] { return sink.got.size() == 3; }, 1000);
  const int steps = 1;
  const std::uint64_t accepted = returned + kPathLatency;
  // Pins: issue after accept, done_at = issue + steps - 1 + depth, retire in deliver() and the
  // admission (extra()) in the same cycle.
  const std::uint64_t readmitted = accepted + u64(kReadyToIssue + (steps - 1) + rgs_depth);
  ASSERT_EQ(threads.starts.size(), 3u);
  EXPECT_EQ(threads.starts[2].cycle, readmitted);
  EXPECT_EQ(threads.starts[2].thread, 0u);
  EXPECT_EQ(threads.starts[2].packet, 2);
  EXPECT_EQ(sink.got.back().cycle, readmitted + kPathLatency);
  EXPECT_EQ(rgs.packets_retired(), 1u);
  EXPECT_EQ(rgs.packets_admitted(), 3u);
  EXPECT_TRUE(rgc.all_handed_out());
}

// With two pipelines the RGC grants pipeline 1 the odd cycles only (D44): its admissions are two
// cycles apart.
TEST(UnitTimingRaySource, RoundRobinGrantAdmitsEveryPipelinesCycle) {
  hw::Kernel k;
  const int pipelines = 2, pipeline = 1;
  ScriptedThreads threads(k, {{}, {}, {}, {}}, {generate(kP + 1)}, 8);
  RayGenerationController rgc(8, pipelines);
  auto& rgs = k.make<RaySource>("t.rgs1", threads, 1, rgc, pipeline, 2, 2);  // threads 2, 3
  RgsNeighbours n(k, rgs);
  k.run_to_completion([&] { return n.sink.got.size() == 2; }, 1000);
  ASSERT_EQ(threads.starts.size(), 2u);
  EXPECT_EQ(threads.starts[0].cycle, u64(pipeline));              // the first granted cycle
  EXPECT_EQ(threads.starts[1].cycle, u64(pipeline + pipelines));  // one round later
  EXPECT_EQ(threads.starts[0].thread, 2u);
  EXPECT_EQ(threads.starts[1].thread, 3u);
  EXPECT_EQ(threads.starts[0].packet, 0);
  EXPECT_EQ(threads.starts[1].packet, 1);
}

// (5c) The RGS with its memory ports (memif::MemorySystem's shading and frame ports over the six
// banks): a returning packet's shading reads go out in dependent waves (the shading record, then
// the material it names, then the texel the material names), each wave once the one before it has
// arrived; the shading is done rgs.depth cycles after the last word; the finished pixels go to
// the frame port one word per cycle; the thread is freed as its last write goes out, and the
// writes land in the frame-buffer bank.
RgsAccess shading_read(std::uint32_t offset, int words, int wave) {
  RgsAccess a;
  a.offset = offset;
  a.words = static_cast<std::uint8_t>(words);
  a.wave = static_cast<std::uint8_t>(wave);
  return a;
}
RgsAccess pixel_write(int bank, std::uint32_t pixel, std::uint32_t word) {
  RgsAccess a;
  a.bank = static_cast<std::uint8_t>(bank);
  a.offset = pixel;
  a.data = word;
  a.write = true;
  return a;
}

TEST(UnitTimingRgs, ReadsInDependentWavesThenShadingDepthThenOneWritePerCycle) {
  hw::Kernel k;
  memif::MemoryImage image(ff::kFp24, 1u << 12);
  memif::MemorySystem mi(k, image);
  const RgsPorts ports{&mi.shading_port(0), &mi.frame_port(0), mi.shading_client(0),
                       mi.frame_client(0)};
  const int rgs_depth = params().rgs_depth;
  const int packets = 2;  // one thread: packet 1 is admitted when packet 0 frees it
  ScriptedThreads threads(k, {{}}, {generate(kP + 1)}, packets);
  RayGenerationController rgc(packets, 1);
  auto& rgs = k.make<RaySource>("t.rgs", threads, rgs_depth, rgc, 0, 0, 1, ports);
  RgsNeighbours n(k, rgs);
  Source& src = n.src;
  Sink& sink = n.sink;
  k.run_to_completion([&] { return sink.got.size() == 1; }, 1000);

  // The packet returns with its last RGS phase: record (4 words), material (4), texel (1), then
  // its four pixels into frame-buffer bank 1.
  threads.set_script(0, {shade(), kDone});
  const std::uint32_t kPixels[kP] = {0, 1, 64, 65};
  std::vector<RgsAccess> access = {shading_read(100, 4, 0), shading_read(200, 4, 1),
                                   shading_read(300, 1, 2)};
  for (int i = 0; i < kP; ++i)
    access.push_back(pixel_write(memif::kFrameBank1, kPixels[i], 0x00102030u + i));
  threads.set_memory(0, access);
  const std::uint64_t returned = k.now() + 10;
  src.script.push_back({returned, 0});
  k.run_to_completion([&] { return sink.got.size() == 2 && mi.idle(); }, 1000);

  // A lone read of w words pushed in c is poppable in c + 2 + (w - 1) + mem.latency + 1 (the
  // port's request channel, the bank queue, w word slots, the SRAM latency, the response
  // channel; memif/memory_controller_test.cpp), and the RGS pops it and issues the next wave's
  // read in that same cycle.
  const auto round_trip = [&](int words) {
    return u64(2 + (words - 1) + params().mem_latency + 1);
  };
  const std::uint64_t issued = returned + kPathLatency + kReadyToIssue;
  EXPECT_EQ(threads.issued_at(0, 0), issued);
  const std::uint64_t record = issued;                    // wave 0 goes out at issue
  const std::uint64_t material = record + round_trip(4);  // wave 1: after the record arrived
  const std::uint64_t texel = material + round_trip(4);   // wave 2: after the material
  const std::uint64_t shaded = texel + round_trip(1) + u64(rgs_depth);
  // Pins: the four writes in shaded .. shaded + 3, the thread freed with the last one and given
  // the next packet in that cycle (waves issued together, a missing depth, writes in one cycle
  // or a free before the writes would each move it).
  const std::uint64_t freed = shaded + u64(kP - 1);
  ASSERT_EQ(threads.starts.size(), 2u);
  EXPECT_EQ(threads.starts[1].cycle, freed);
  EXPECT_EQ(sink.got[1].cycle, freed + kPathLatency);
  EXPECT_EQ(rgs.packets_retired(), 1u);
  EXPECT_EQ(k.stats().value("t.rgs.shading_reads"), 3.0);
  EXPECT_EQ(k.stats().value("t.rgs.frame_writes"), 4.0);
  EXPECT_EQ(mi.controller().client_bytes(ports.shading_client), 4u * (4 + 4 + 1));
  EXPECT_EQ(mi.controller().client_bytes(ports.frame_client), 3u * kP);  // RGB8 counted (D36)
  for (int i = 0; i < kP; ++i)
    EXPECT_EQ(image.word(memif::kFrameBank1, kPixels[i]), 0x00102030u + i) << "pixel " << i;
}

}  // namespace
}  // namespace saarcor::units
