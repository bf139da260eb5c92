// The model's side of the boundary record (units/boundary.h): a list unit alone with mock
// neighbours (the shape of units/unit_timing_test.cpp) emits one event per port event, in the
// cycles the unit's timing rules give. Latencies as in unit_timing_test.cpp: a path is a channel
// of latency 1, a cache hit is poppable hit_latency cycles after its push, a ready thread issues
// one cycle later, and leaves the pipeline `depth` cycles after its issue.
#include "units/boundary.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "hw/kernel.h"
#include "memif/memory_system.h"
#include "memif/test_traffic.h"
#include "units/cycle_params.h"
#include "units/dynrtc_units.h"
#include "units/unit_testing.h"

namespace saarcor::units {
namespace {

constexpr int kPathLatency = 1;
constexpr int kReadyToIssue = 1;
constexpr std::uint64_t kMask = 0xF;

// Pushes thread `thread` on `path` at cycle `at` and tells the observer, as a sending unit's
// leave() does.
class Source : public hw::Module {
 public:
  Source(hw::Kernel& k, ThreadPath& path, UnitObserver& o,
         std::vector<std::pair<std::uint64_t, ThreadToken>> script)
      : hw::Module(k, "t.source"), path_(path), o_(o), script_(std::move(script)) {
    produces(path_);
  }
  int evaluate() override {
    if (next_ == script_.size() || script_[next_].first > now()) return 0;
    path_.push(script_[next_].second);
    o_.queued(now(), UnitId::kList, script_[next_].second);
    ++next_;
    return 1;
  }
  std::uint64_t next_wakeup(std::uint64_t now) const override {
    return next_ == script_.size() ? hw::kNever : std::max(now + 1, script_[next_].first);
  }

 private:
  ThreadPath& path_;
  UnitObserver& o_;
  std::vector<std::pair<std::uint64_t, ThreadToken>> script_;
  std::size_t next_ = 0;
};

class Drain : public hw::Module {
 public:
  Drain(hw::Kernel& k, ThreadPath& p) : hw::Module(k, "t.drain"), p_(p) { consumes(p_); }
  int evaluate() override {
    if (!p_.can_pop()) return 0;
    p_.pop();
    ++got;
    return 1;
  }
  int got = 0;

 private:
  ThreadPath& p_;
};

// Thread 0 misses entry 11 (warming the line); thread 1 asks for it at cycle 100 and hits: its
// five events (input, cache request, response, output) in the cycles of the rules.
TEST(BoundaryRecord, ListUnitEventsInTheCyclesOfTheTimingRules) {
  memif::MemoryImage img = memif::testing::random_scene_image(ff::kFp24, 2);
  hw::Kernel k;
  memif::MemorySystem mi(k, img);
  memif::Cache& cache = mi.cache(0, memif::ItemType::kList);
  const Request entry{UnitId::kList, Phase::kList, 11, 1, kMask};
  const Request next{UnitId::kTransformation, Phase::kTransformObject, 30, 5, kMask};
  testing::ScriptedThreads threads(k, {{entry, next}, {entry, next}});
  const int depth = prototype_params().list_depth();
  auto& lu = k.make<ListUnit>("t.list", threads, depth, cache);
  ThreadPath& c = k.make_channel<ThreadToken>("t.path_c", 8, kPathLatency);
  ThreadPath& d = k.make_channel<ThreadToken>("t.path_d", 8, kPathLatency);
  lu.add_input(&c);
  lu.set_output(UnitId::kTransformation, &d);
  RequestPayload payload(threads);
  std::vector<BoundaryEvent> got;
  BoundaryRecorder rec(threads, 2, {UnitId::kList}, payload,
                       [&](const BoundaryEvent& e) { got.push_back(e); });
  lu.set_observer(&rec);
  const std::uint64_t pushed = 100;
  Source src(k, c, rec, {{0, 0}, {pushed, 1}});
  Drain drain(k, d);
  k.run_to_completion([&] { return drain.got == 2; }, 1000);

  std::vector<BoundaryEvent> t1;
  for (const BoundaryEvent& e : got)
    if (e.thread == 1) t1.push_back(e);
  ASSERT_EQ(t1.size(), 4u);
  const int hit = cache.config().hit_latency;
  const std::uint64_t accepted = pushed + kPathLatency;
  const std::uint64_t answered = accepted + static_cast<std::uint64_t>(hit);
  const std::uint64_t left =
      answered + static_cast<std::uint64_t>(kReadyToIssue) + static_cast<std::uint64_t>(depth);
  EXPECT_EQ(t1[0].port, BoundaryPort::kInput);
  EXPECT_EQ(t1[0].cycle, pushed);
  EXPECT_EQ(t1[0].path, UnitId::kRgs);  // (the source stands in for a unit never seen)
  EXPECT_EQ(t1[0].field[1], 11u);       // item
  EXPECT_EQ(t1[1].port, BoundaryPort::kCacheRequest);
  EXPECT_EQ(t1[1].cycle, accepted);
  EXPECT_EQ(t1[1].field[0], 11u);
  EXPECT_EQ(t1[1].field[1], static_cast<std::uint64_t>(unit_index(UnitId::kList)));
  EXPECT_EQ(t1[2].port, BoundaryPort::kCacheResponse);
  EXPECT_EQ(t1[2].cycle, answered);
  ASSERT_EQ(t1[2].fields, 2);
  EXPECT_EQ(t1[2].field[1], img.list_entry(11));  // the SRAM word
  EXPECT_EQ(t1[3].port, BoundaryPort::kOutput);
  EXPECT_EQ(t1[3].cycle, left);
  EXPECT_EQ(t1[3].path, UnitId::kTransformation);
  EXPECT_EQ(t1[3].field[0], static_cast<std::uint64_t>(Phase::kTransformObject));
  EXPECT_EQ(format_boundary(t1[3]),
            "cycle " + std::to_string(left) +
                " dynrtp0 list output thread 1 to transformation phase=4 item=1e mask=f");
}

// A wide payload prints its word count, the words (the first eight) and their FNV-1a checksum:
// 2166136261 ^ 0x3f8000, times 16777619 (mod 2^32) = 0x0f47dd1f; ^ 0x400000, times 16777619 =
// 0xc86117cd.
TEST(BoundaryRecord, WideWordsPrintCompactly) {
  BoundaryEvent e;
  e.cycle = 7;
  e.unit = UnitId::kTraversal;
  e.port = BoundaryPort::kSideBand;
  e.thread = 3;
  static constexpr const char* kNames[] = {"done"};
  e.fields = 1;
  e.names = kNames;
  e.field[0] = 2;
  e.wide = {0x3f8000, 0x400000};
  EXPECT_EQ(format_boundary(e),
            "cycle 7 dynrtp0 traversal side_band thread 3 done=2 wide[2]=3f8000,400000 "
            "sum=c86117cd");
  e.wide.assign(9, 0);
  EXPECT_NE(format_boundary(e).find("wide[9]=0,0,0,0,0,0,0,0,... sum="), std::string::npos);
}

// Several units recorded at once: each unit's events carry its own payload, the others the
// thread program's request; the issue of any unit reaches every payload.
class Tagged final : public BoundaryPayload {
 public:
  explicit Tagged(std::uint64_t tag) : tag_(tag) {}
  void input(UnitId, UnitId, ThreadToken, BoundaryEvent& e) override {
    e.fields = 1;
    e.field[0] = tag_;
  }
  bool side_band(UnitId, UnitId from, ThreadToken, BoundaryEvent& side) override {
    side.unit = UnitId::kTraversal;
    return from == UnitId::kIntersection && tag_ == 2;
  }
  void issued(UnitId, ThreadToken, const Request&) override { ++issues; }
  void output(UnitId, ThreadToken, BoundaryEvent& e) override {
    e.fields = 1;
    e.field[0] = tag_ + 10;
  }
  int issues = 0;

 private:
  std::uint64_t tag_;
};

TEST(BoundaryRecord, UnitPayloadsDispatchByUnit) {
  hw::Kernel k;
  const Request r{UnitId::kList, Phase::kList, 11, 1, kMask};
  testing::ScriptedThreads threads(k, {{r}});
  Tagged list(1), traversal(2);
  UnitPayloads p(threads);
  p.set(UnitId::kList, list);
  p.set(UnitId::kTraversal, traversal);
  BoundaryEvent e;
  p.input(UnitId::kList, UnitId::kTraversal, 0, e);
  EXPECT_EQ(e.field[0], 1u);
  p.output(UnitId::kTraversal, 0, e);
  EXPECT_EQ(e.field[0], 12u);
  p.input(UnitId::kIntersection, UnitId::kTransformation, 0, e);  // the request: phase, item
  EXPECT_EQ(e.fields, 3);
  EXPECT_EQ(e.field[1], 11u);
  p.issued(UnitId::kRgs, 0, r);
  EXPECT_EQ(list.issues + traversal.issues, 2);
  BoundaryEvent side;
  EXPECT_TRUE(p.side_band(UnitId::kList, UnitId::kIntersection, 0, side));
  EXPECT_EQ(side.unit, UnitId::kTraversal);
  EXPECT_FALSE(p.side_band(UnitId::kList, UnitId::kList, 0, side));
}

// A hand-over several units' payloads claim (the packet start on path a: the list unit's mailbox
// clear and the intersection unit's hit reset) is one side-band event for each, in unit order.
class Claims final : public BoundaryPayload {
 public:
  explicit Claims(UnitId unit) : unit_(unit) {}
  void input(UnitId, UnitId, ThreadToken, BoundaryEvent&) override {}
  bool side_band(UnitId to, UnitId, ThreadToken, BoundaryEvent& side) override {
    side.unit = unit_;
    return to == UnitId::kTransformation;
  }
  void issued(UnitId, ThreadToken, const Request&) override {}
  void output(UnitId, ThreadToken, BoundaryEvent&) override {}

 private:
  UnitId unit_;
};

TEST(BoundaryRecord, AHandOverIsASideBandEventOfEveryUnitThatClaimsIt) {
  hw::Kernel k;
  const Request r{UnitId::kTransformation, Phase::kGenerate, 0, 1, kMask};
  testing::ScriptedThreads threads(k, {{r}});
  Claims list(UnitId::kList), intersection(UnitId::kIntersection);
  UnitPayloads p(threads);
  p.set(UnitId::kIntersection, intersection);
  p.set(UnitId::kList, list);
  std::vector<BoundaryEvent> sides;
  p.side_bands(UnitId::kTransformation, UnitId::kRgs, 0, sides);
  ASSERT_EQ(sides.size(), 2u);
  EXPECT_EQ(sides[0].unit, UnitId::kList);  // (unit order: list before intersection)
  EXPECT_EQ(sides[1].unit, UnitId::kIntersection);
  sides.clear();
  p.side_bands(UnitId::kTraversal, UnitId::kRgs, 0, sides);
  EXPECT_TRUE(sides.empty());
}

}  // namespace
}  // namespace saarcor::units
