// The RTL units (rtl/traversal_threads.sv, rtl/list_unit.sv, rtl/transformation_threads.sv,
// rtl/intersection_threads.sv) in lockstep with the cycle model
// (rtl/lockstep.h): 0 divergences on the CI scenes and configurations, the injected faults caught
// at their first wrong event, bad input refused.
#include "rtl/lockstep.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "rtl/builds_testing.h"
#include "rtl/intersection_rtl.h"
#include "rtl/list_rtl.h"
#include "rtl/transformation_rtl.h"
#include "rtl/traversal_rtl.h"
#include "units/boundary_list.h"
#include "units/cycle_params.h"

namespace saarcor::rtl {
namespace {

using units::BoundaryEvent;
using units::BoundaryPort;

std::string shared(const std::string& rel) {
  return std::string(SAARCOR_SHARED_SCENES) + "/" + rel;
}

// ---- lockstep ----------------------------------------------------------------------------------
LockstepResult run(const std::string& scene, std::vector<std::string> set = {}, int w = 24,
                   int h = 18, bool shadows = false, int depth = 0) {
  LockstepOptions o;
  o.units = {"traversal", "list", "transformation", "intersection", "caches"};
  o.scene = scene;
  o.set = std::move(set);
  o.width = w;
  o.height = h;
  o.shadows = shadows;
  o.depth = depth;
  return run_lockstep(o);
}

// The units agree with the model on every port event: the list unit's each request answered and
// each entry leaving; the traversal unit's node fetches answered, and more threads leaving than
// node steps (the clips and pops leave too); the transformation unit's row fetches answered and
// every thread leaving again; the intersection unit's every triangle leaving again (one hit
// update each), each packet start seen by the list and the intersection unit; each unit's cache
// looks up and answers every request the unit sent, and gets a fill for each line request.
void expect_agreement(const LockstepResult& r) {
  EXPECT_FALSE(r.diverged) << r.screen;
  const LockstepUnit& list = r.unit("list");
  const LockstepUnit& trav = r.unit("traversal");
  EXPECT_GT(list.event(BoundaryPort::kCacheRequest), 0u);
  EXPECT_EQ(list.event(BoundaryPort::kCacheRequest), list.event(BoundaryPort::kCacheResponse));
  EXPECT_GE(list.event(BoundaryPort::kOutput), list.event(BoundaryPort::kCacheRequest));
  EXPECT_GT(trav.event(BoundaryPort::kCacheRequest), 0u);
  EXPECT_EQ(trav.event(BoundaryPort::kCacheRequest), trav.event(BoundaryPort::kCacheResponse));
  EXPECT_GT(trav.event(BoundaryPort::kOutput), trav.event(BoundaryPort::kCacheRequest));
  EXPECT_GT(trav.event(BoundaryPort::kSideBand), 0u);  // hit updates
  const LockstepUnit& isect = r.unit("intersection");
  EXPECT_GT(isect.event(BoundaryPort::kInput), 0u);
  EXPECT_EQ(isect.event(BoundaryPort::kOutput), isect.event(BoundaryPort::kInput));
  EXPECT_EQ(isect.event(BoundaryPort::kOutput), trav.event(BoundaryPort::kSideBand));
  EXPECT_EQ(isect.event(BoundaryPort::kSideBand), list.event(BoundaryPort::kSideBand));
  const LockstepUnit& xf = r.unit("transformation");
  EXPECT_GT(xf.event(BoundaryPort::kCacheRequest), 0u);
  EXPECT_EQ(xf.event(BoundaryPort::kCacheRequest), xf.event(BoundaryPort::kCacheResponse));
  EXPECT_EQ(xf.event(BoundaryPort::kOutput), xf.event(BoundaryPort::kInput));
  EXPECT_GE(xf.event(BoundaryPort::kOutput), isect.event(BoundaryPort::kInput));
  for (const auto& [name, unit] : {std::pair{"node-cache", &trav}, std::pair{"list-cache", &list},
                                   std::pair{"row-cache", &xf}}) {
    const LockstepUnit& c = r.unit(name);
    EXPECT_EQ(c.event(BoundaryPort::kCacheRequest), unit->event(BoundaryPort::kCacheRequest));
    EXPECT_EQ(c.event(BoundaryPort::kCacheAccept), c.event(BoundaryPort::kCacheRequest));
    EXPECT_EQ(c.event(BoundaryPort::kCacheReply), c.event(BoundaryPort::kCacheRequest));
    EXPECT_GT(c.event(BoundaryPort::kMemRequest), 0u);
    EXPECT_EQ(c.event(BoundaryPort::kMemFill), c.event(BoundaryPort::kMemRequest));
  }
  std::printf(
      "  %s/%s: %llu cycles; traversal %llu requests, %llu outputs; list %llu requests, "
      "%llu outputs; transformation %llu rows, %llu outputs; intersection %llu outputs compared\n",
      trav.build.c_str(), list.build.c_str(), static_cast<unsigned long long>(r.cycles),
      static_cast<unsigned long long>(trav.event(BoundaryPort::kCacheRequest)),
      static_cast<unsigned long long>(trav.event(BoundaryPort::kOutput)),
      static_cast<unsigned long long>(list.event(BoundaryPort::kCacheRequest)),
      static_cast<unsigned long long>(list.event(BoundaryPort::kOutput)),
      static_cast<unsigned long long>(xf.event(BoundaryPort::kCacheRequest)),
      static_cast<unsigned long long>(xf.event(BoundaryPort::kOutput)),
      static_cast<unsigned long long>(isect.event(BoundaryPort::kOutput)));
}

const std::vector<std::string> kP1 = {"threads=13", "packet=1", "mailbox=1", "triangle_mailbox=1",
                                      "cache.list.items=8"};
const std::vector<std::string> kP16 = {"threads=16", "packet=16", "cache.list.items=8"};

TEST(Lockstep, RoomPrototype) {
  expect_agreement(run("builtin:room"));
}
TEST(Lockstep, RoomP1ThirteenThreadsMailbox1Cache8) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  expect_agreement(run("builtin:room", kP1));
}
TEST(Lockstep, RoomP16Cache8) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  expect_agreement(run("builtin:room", kP16, 32, 32));
}
TEST(Lockstep, DynamicShadowsDepth2) {
  expect_agreement(run("builtin:dynamic", {}, 24, 18, true, 2));
}
TEST(Lockstep, DynamicShadowsDepth2P1) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  expect_agreement(run("builtin:dynamic", kP1, 16, 12, true, 2));
}
TEST(Lockstep, SunCorTwoLevels) {
  expect_agreement(run("builtin:suncor", {}, 24, 18));
}
// A small stack (16 entries: the traversal unit's proto_stack16 build beside the list unit's
// proto).
TEST(Lockstep, SunCorStack16) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  expect_agreement(run("builtin:suncor", {"stack=16"}, 24, 18));
}
TEST(Lockstep, DuckGltf) {
  expect_agreement(run(shared("Duck/Duck.gltf")));
}
TEST(Lockstep, TwoCylinderEngineGltfP16) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  expect_agreement(run(shared("2CylinderEngine/2CylinderEngine.gltf"), kP16, 32, 24));
}

// The injected fault (a mailbox that never hits, list_unit.sv FAULT_MAILBOX_NEVER_HITS) is caught
// at the first event the mailbox decides: the model's first list output whose rays the mailbox
// reduced (a skip, or an entry for fewer rays than the list holds).
TEST(ListLockstep, MailboxThatNeverHitsIsCaughtAtItsFirstWrongEvent) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  LockstepOptions o;
  o.units = {"list"};
  o.scene = "builtin:room";
  o.width = 24;
  o.height = 18;
  // Per (thread, level): the rays and the cursor the thread arrived with.
  std::map<std::pair<std::uint32_t, std::uint64_t>, std::pair<std::uint64_t, std::uint64_t>> in;
  std::uint64_t first = 0;
  o.model_events = [&](const BoundaryEvent& e) {
    if (e.port == BoundaryPort::kInput) in[{e.thread, e.field[1]}] = {e.field[4], e.field[2]};
    if (e.port != BoundaryPort::kOutput || first != 0) return;
    const auto& [rays, next] = in[{e.thread, e.field[1]}];
    const bool entry = e.field[0] == static_cast<std::uint64_t>(units::ListOut::kEntry);
    // A thread back from an object whose list is done reads no entry (its cursor unchanged):
    // no mailbox decides that.
    if (!entry && e.field[2] == next) return;
    if (!entry || e.field[4] != rays) first = e.cycle;
  };
  const LockstepResult healthy = run_lockstep(o);
  ASSERT_FALSE(healthy.diverged) << healthy.screen;
  ASSERT_NE(first, 0u) << "the room's lists never hit the mailbox";

  o.model_events = nullptr;
  o.fault = "mailbox-never-hits";
  const LockstepResult r = run_lockstep(o);
  ASSERT_TRUE(r.diverged);
  EXPECT_EQ(r.divergence.cycle, first) << r.screen;
  EXPECT_EQ(r.divergence.port, "output");
  EXPECT_EQ(r.divergence.kind, "payload");
  EXPECT_NE(r.screen.find("the last 16 events"), std::string::npos);
  // The replay (--until the divergence's cycle) stops there with the same divergence.
  o.until = r.divergence.cycle;
  const LockstepResult replay = run_lockstep(o);
  EXPECT_TRUE(replay.diverged);
  EXPECT_EQ(replay.divergence.cycle, first);
  EXPECT_EQ(replay.divergence.field, r.divergence.field);
}

// The injected fault "the loop's and the intersection path's priorities swapped"
// (unit_threads.sv FAULT_PRIORITY_SWAP) is caught at the first accept where both held a thread:
// the model's cache request for the loop's thread, the RTL's for the other (class order).
TEST(ListLockstep, SwappedPrioritiesAreCaughtAtTheirFirstWrongEvent) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  LockstepOptions o;
  o.units = {"list"};
  o.scene = "builtin:dynamic";
  o.width = 24;
  o.height = 18;
  o.shadows = true;
  std::array<std::deque<std::pair<std::uint32_t, std::uint64_t>>, 3> path;  // thread, push cycle
  std::uint64_t first = 0;
  o.model_events = [&](const BoundaryEvent& e) {
    if (e.port == BoundaryPort::kInput) {
      const std::size_t p = e.path == units::UnitId::kList           ? 0
                            : e.path == units::UnitId::kIntersection ? 1
                                                                     : 2;
      path[p].emplace_back(e.thread, e.cycle);
    }
    if (e.port != BoundaryPort::kCacheRequest) return;
    for (std::size_t p = 0; p < 3; ++p)
      for (auto it = path[p].begin(); it != path[p].end(); ++it)
        if (it->first == e.thread) {
          path[p].erase(it);
          if (p == 0 && first == 0 && !path[1].empty() && path[1].front().second < e.cycle)
            first = e.cycle;
          return;
        }
  };
  const LockstepResult healthy = run_lockstep(o);
  ASSERT_FALSE(healthy.diverged) << healthy.screen;
  ASSERT_NE(first, 0u) << "the loop and the intersection path never held threads together";

  o.model_events = nullptr;
  o.fault = "priorities-swapped";
  const LockstepResult r = run_lockstep(o);
  ASSERT_TRUE(r.diverged);
  EXPECT_EQ(r.divergence.cycle, first) << r.screen;
  EXPECT_EQ(r.divergence.port, "cache_request");
  EXPECT_EQ(r.divergence.kind, "order");
}

// The classification, each class provoked between the RTL's ports and the comparison: an output
// one cycle late (timing), an output lost (missing), an output invented (extra), two threads'
// outputs swapped (order).
class Tampered final : public UnitRtl {
 public:
  enum class Fault { kLate, kLost, kInvented, kSwapped };
  // `first`: where the cycle of the event tampered with goes (the wrapper dies with the run).
  Tampered(std::unique_ptr<UnitRtl> rtl, Fault f, std::uint64_t from, std::uint64_t& first)
      : first_(first), rtl_(std::move(rtl)), f_(f), from_(from) {}
  units::UnitId unit() const override { return rtl_->unit(); }
  void reset() override { rtl_->reset(); }
  void start_trace(const std::string& p) override { rtl_->start_trace(p); }
  void stop_trace() override { rtl_->stop_trace(); }
  void cycle(std::uint64_t c, const std::vector<BoundaryEvent>& in,
             std::vector<BoundaryEvent>& out) override {
    std::vector<BoundaryEvent> got;
    rtl_->cycle(c, in, got);
    for (BoundaryEvent& e : held_) {
      e.cycle = c;
      out.push_back(e);
    }
    held_.clear();
    for (BoundaryEvent& e : got) {
      const bool hit = !done_ && c >= from_ && e.port == BoundaryPort::kOutput;
      if (hit) done_ = true;
      if (hit && f_ == Fault::kLate) {
        held_.push_back(e);
      } else if (hit && f_ == Fault::kLost) {
      } else if (hit && f_ == Fault::kInvented) {
        out.push_back(e);
        BoundaryEvent x = e;
        x.port = BoundaryPort::kCacheRequest;
        x.fields = 3;
        x.names = units::kCacheRequestFields;
        x.field = {0xdead, 3, e.thread};
        out.insert(out.end() - 1, x);
      } else if (hit && f_ == Fault::kSwapped) {
        e.thread ^= 1;
        out.push_back(e);
      } else {
        out.push_back(e);
      }
      if (hit) first_ = c;
    }
  }
  std::uint64_t& first_;

 private:
  std::unique_ptr<UnitRtl> rtl_;
  Fault f_;
  std::uint64_t from_;
  bool done_ = false;
  std::vector<BoundaryEvent> held_;
};

TEST(ListLockstep, DivergencesAreClassified) {
  const std::pair<Tampered::Fault, const char*> cases[] = {{Tampered::Fault::kLate, "timing"},
                                                           {Tampered::Fault::kLost, "missing"},
                                                           {Tampered::Fault::kInvented, "extra"},
                                                           {Tampered::Fault::kSwapped, "order"}};
  for (const auto& [fault, kind] : cases) {
    SCOPED_TRACE(kind);
    LockstepOptions o;
    o.units = {"list"};
    o.scene = "builtin:room";
    o.width = 16;
    o.height = 12;
    std::uint64_t first = 0;
    o.wrap_rtl = [&](std::unique_ptr<UnitRtl> rtl) {
      return std::unique_ptr<UnitRtl>(
          std::make_unique<Tampered>(std::move(rtl), fault, 500, first));
    };
    const LockstepResult r = run_lockstep(o);
    ASSERT_TRUE(r.diverged);
    ASSERT_NE(first, 0u);
    EXPECT_EQ(r.divergence.kind, kind) << r.screen;
    EXPECT_EQ(r.divergence.cycle, first) << r.screen;
    if (fault == Tampered::Fault::kLate) {
      EXPECT_EQ(r.divergence.other_cycle, first + 1);
    }
  }
}

TEST(Lockstep, BadInputIsRefusedWithOneLine) {
  LockstepOptions o;
  o.scene = "builtin:room";
  const auto error = [&]() -> std::string {
    try {
      run_lockstep(o);
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      return e.what();
    }
    ADD_FAILURE() << "accepted";
    return "";
  };
  o.units = {"shading"};
  EXPECT_NE(error().find("unknown unit 'shading'"), std::string::npos);
  o.units = {"list", "list"};
  EXPECT_NE(error().find("given twice"), std::string::npos);
  o.units = {"list"};
  o.set = {"threads=7"};
  EXPECT_NE(error().find("no Verilated list unit"), std::string::npos);
  o.units = {"traversal", "list"};
  EXPECT_NE(error().find("no Verilated traversal unit"), std::string::npos);
  o.set = {"stack=32"};
  EXPECT_NE(error().find("stack=32"), std::string::npos);
  o.set = {};
  o.fault = "stack-off-by-one";
  EXPECT_NE(error().find("no unit of the run has the fault"), std::string::npos);
  o.units = {"list"};
  o.fault = "pop-off";  // the traversal unit's
  EXPECT_NE(error().find("no unit of the run has the fault"), std::string::npos);
  o.fault = "strict-uv";  // the intersection unit's
  EXPECT_NE(error().find("no unit of the run has the fault"), std::string::npos);
  o.fault = {};
  o.units = {"intersection"};
  o.set = {"lat.div=9"};
  EXPECT_NE(error().find("no Verilated intersection unit"), std::string::npos);
  o.units = {"transformation"};
  o.set = {"lat.mul=4"};
  EXPECT_NE(error().find("no Verilated transformation unit"), std::string::npos);
}

// The first build of each unit is the prototype's (units/cycle_params.cpp defaults).
TEST(Lockstep, PrototypeBuildsAreTheModelsDefaults) {
  const units::CycleParams p = units::prototype_params();
  const TraversalBuild& t = traversal_builds().front();
  EXPECT_EQ(t.name, "proto");
  EXPECT_EQ(t.threads, p.threads);
  EXPECT_EQ(t.packet, p.packet);
  EXPECT_EQ(t.stack, p.stack);
  EXPECT_EQ(t.lat_add, p.lat_add);
  EXPECT_EQ(t.lat_div, p.lat_div);
  EXPECT_EQ(t.lat_cmp, p.lat_cmp);
  EXPECT_EQ(t.fault, 0);
  // Every traversal parameter set without a fault has the list unit's build beside it.
  for (const TraversalBuild& b : traversal_builds()) {
    if (b.fault != 0) continue;
    bool list = false;
    for (const ListBuild& l : list_builds())
      list = list || (l.fault == 0 && l.threads == b.threads && l.packet == b.packet);
    EXPECT_TRUE(list) << b.name;
  }
  const IntersectionBuild& i = intersection_builds().front();
  EXPECT_EQ(i.name, "proto");
  EXPECT_EQ(i.threads, p.threads);
  EXPECT_EQ(i.packet, p.packet);
  EXPECT_EQ(i.lat_add, p.lat_add);
  EXPECT_EQ(i.lat_mul, p.lat_mul);
  EXPECT_EQ(i.lat_div, p.lat_div);
  EXPECT_EQ(i.lat_cmp, p.lat_cmp);
  EXPECT_EQ(i.fault, 0);
  const TransformationBuild& x = transformation_builds().front();
  EXPECT_EQ(x.name, "proto");
  EXPECT_EQ(x.threads, p.threads);
  EXPECT_EQ(x.packet, p.packet);
  EXPECT_EQ(x.lat_add, p.lat_add);
  EXPECT_EQ(x.lat_mul, p.lat_mul);
  EXPECT_EQ(x.fault, 0);
  for (const TransformationBuild& b : transformation_builds()) {
    if (b.fault != 0) continue;
    bool intersection = false;
    for (const IntersectionBuild& n : intersection_builds())
      intersection =
          intersection || (n.fault == 0 && n.threads == b.threads && n.packet == b.packet);
    EXPECT_TRUE(intersection) << b.name;
  }
  // Every intersection parameter set without a fault has the traversal unit's build beside it.
  for (const IntersectionBuild& b : intersection_builds()) {
    if (b.fault != 0) continue;
    bool traversal = false;
    for (const TraversalBuild& t : traversal_builds())
      traversal = traversal || (t.fault == 0 && t.threads == b.threads && t.packet == b.packet);
    EXPECT_TRUE(traversal) << b.name;
  }
}

// ---- the traversal unit ------------------------------------------------------------------------
// Wraps the Verilated traversal unit and finds the first cycle in which a thread's stack shrank
// from two or more entries: the first pop (or drop) that reads an entry with another below it,
// where a pop one entry off first reads the wrong entry (the model's events do not show the
// stack, the healthy RTL's dbg port does: it agrees with the model up to there, the lockstep
// says so). `popped`: the thread left in that cycle (the entry decided: it was popped).
class DeepPopProbe final : public UnitRtl {
 public:
  DeepPopProbe(std::unique_ptr<UnitRtl> rtl, int threads, std::uint64_t& cycle, bool& popped)
      : cycle_(cycle),
        popped_(popped),
        rtl_(std::move(rtl)),
        probe_(dynamic_cast<TraversalStackProbe*>(rtl_.get())),
        size_(static_cast<std::size_t>(threads), 0) {}
  units::UnitId unit() const override { return rtl_->unit(); }
  void reset() override { rtl_->reset(); }
  void start_trace(const std::string& p) override { rtl_->start_trace(p); }
  void stop_trace() override { rtl_->stop_trace(); }
  void cycle(std::uint64_t c, const std::vector<BoundaryEvent>& in,
             std::vector<BoundaryEvent>& out) override {
    rtl_->cycle(c, in, out);
    if (cycle_ != 0 || probe_ == nullptr) return;
    for (std::uint32_t t = 0; t < size_.size(); ++t) {
      const int s = probe_->stack_size(t);
      if (s < size_[t] && size_[t] >= 2 && cycle_ == 0) {
        cycle_ = c;
        for (const BoundaryEvent& e : out)
          popped_ = popped_ || (e.port == BoundaryPort::kOutput && e.thread == t);
      }
      size_[t] = s;
    }
  }

 private:
  std::uint64_t& cycle_;
  bool& popped_;
  std::unique_ptr<UnitRtl> rtl_;
  TraversalStackProbe* probe_;
  std::vector<int> size_;
};

// The stack pop one entry off (traversal_ctrl.sv FAULT_POP_OFF: the entry below the top) is
// caught at the first pop from a stack of two or more entries, which the healthy run names. The
// room's first such pop decides (it pops, no drop): the faulty unit lets the thread go in the
// same cycle with the entry below, whose node is another: class payload.
TEST(TraversalLockstep, StackPopOneEntryOffIsCaughtAtTheFirstDeepPop) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  LockstepOptions o;
  o.units = {"traversal"};
  o.scene = "builtin:room";
  o.width = 24;
  o.height = 18;
  std::uint64_t deep = 0;
  bool popped = false;
  o.wrap_rtl = [&](std::unique_ptr<UnitRtl> rtl) {
    return std::unique_ptr<UnitRtl>(std::make_unique<DeepPopProbe>(
        std::move(rtl), units::prototype_params().threads, deep, popped));
  };
  const LockstepResult healthy = run_lockstep(o);
  ASSERT_FALSE(healthy.diverged) << healthy.screen;
  ASSERT_NE(deep, 0u) << "no pop from a stack of two entries";
  ASSERT_TRUE(popped) << "the room's first deep pop drops its entry";

  o.wrap_rtl = nullptr;
  o.fault = "pop-off";
  const LockstepResult r = run_lockstep(o);
  ASSERT_TRUE(r.diverged);
  EXPECT_EQ(r.divergence.cycle, deep) << r.screen;
  EXPECT_EQ(r.divergence.unit, "traversal");
  EXPECT_EQ(r.divergence.port, "output");
  EXPECT_EQ(r.divergence.kind, "payload") << r.screen;
}

// The traversal pipeline one cycle short (FAULT_SHORT: the lanes' compare stage a wire) is
// caught at the unit's first output, the first clip chain's end: the RTL has it one cycle before
// the model (class timing, the model's cycle beside it).
TEST(TraversalLockstep, PipelineOneCycleShortIsCaughtAtTheFirstOutput) {
  LockstepOptions o;
  o.units = {"traversal"};
  o.scene = "builtin:room";
  o.width = 24;
  o.height = 18;
  o.fault = "short-pipeline";
  std::uint64_t first = 0;
  o.model_events = [&](const BoundaryEvent& e) {
    if (first == 0 && e.unit == units::UnitId::kTraversal && e.port == BoundaryPort::kOutput)
      first = e.cycle;
  };
  const LockstepResult r = run_lockstep(o);
  ASSERT_TRUE(r.diverged);
  ASSERT_NE(first, 0u);
  EXPECT_EQ(r.divergence.cycle, first - 1) << r.screen;
  EXPECT_EQ(r.divergence.other_cycle, first) << r.screen;
  EXPECT_EQ(r.divergence.unit, "traversal");
  EXPECT_EQ(r.divergence.port, "output");
  EXPECT_EQ(r.divergence.kind, "timing");
}

}  // namespace
}  // namespace saarcor::rtl
