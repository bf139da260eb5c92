// The list unit's RTL (rtl/list_unit.sv) in lockstep with the cycle model (rtl/lockstep.h): 0
// divergences on the CI scenes and configurations, the injected fault caught at its first wrong
// event, bad input refused.
#include "rtl/lockstep.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "units/boundary_list.h"

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
  o.scene = scene;
  o.set = std::move(set);
  o.width = w;
  o.height = h;
  o.shadows = shadows;
  o.depth = depth;
  return run_lockstep(o);
}

void expect_agreement(const LockstepResult& r) {
  EXPECT_FALSE(r.diverged) << r.screen;
  const auto ev = [&](BoundaryPort p) { return r.events[static_cast<std::size_t>(p)]; };
  EXPECT_GT(ev(BoundaryPort::kCacheRequest), 0u);
  EXPECT_EQ(ev(BoundaryPort::kCacheRequest), ev(BoundaryPort::kCacheResponse));
  // Every list step fetches its entry but a return to a list that is done (D49: a thread back
  // from an object whose top-level list has ended), which every scene here has (each packet that
  // enters the last object of its list comes back to it).
  EXPECT_GT(ev(BoundaryPort::kOutput), ev(BoundaryPort::kCacheRequest));
  std::printf("  %s: %llu cycles, %llu requests, %llu outputs compared\n", r.build.c_str(),
              static_cast<unsigned long long>(r.cycles),
              static_cast<unsigned long long>(ev(BoundaryPort::kCacheRequest)),
              static_cast<unsigned long long>(ev(BoundaryPort::kOutput)));
}

const std::vector<std::string> kP1 = {"threads=13", "packet=1", "mailbox=1", "triangle_mailbox=1",
                                      "cache.list.items=8"};
const std::vector<std::string> kP16 = {"threads=16", "packet=16", "cache.list.items=8"};

TEST(ListLockstep, RoomPrototype) {
  expect_agreement(run("builtin:room"));
}
TEST(ListLockstep, RoomP1ThirteenThreadsMailbox1Cache8) {
  expect_agreement(run("builtin:room", kP1));
}
TEST(ListLockstep, RoomP16Cache8) {
  expect_agreement(run("builtin:room", kP16, 32, 32));
}
TEST(ListLockstep, DynamicShadowsDepth2) {
  expect_agreement(run("builtin:dynamic", {}, 24, 18, true, 2));
}
TEST(ListLockstep, DynamicShadowsDepth2P1) {
  expect_agreement(run("builtin:dynamic", kP1, 16, 12, true, 2));
}
TEST(ListLockstep, SunCorTwoLevels) {
  expect_agreement(run("builtin:suncor", {}, 24, 18));
}
TEST(ListLockstep, DuckGltf) {
  expect_agreement(run(shared("Duck/Duck.gltf")));
}
TEST(ListLockstep, TwoCylinderEngineGltfP16) {
  expect_agreement(run(shared("2CylinderEngine/2CylinderEngine.gltf"), kP16, 32, 24));
}

// The injected fault (a mailbox that never hits, list_unit.sv FAULT_MAILBOX_NEVER_HITS) is caught
// at the first event the mailbox decides: the model's first list output whose rays the mailbox
// reduced (a skip, or an entry for fewer rays than the list holds).
TEST(ListLockstep, MailboxThatNeverHitsIsCaughtAtItsFirstWrongEvent) {
  LockstepOptions o;
  o.scene = "builtin:room";
  o.width = 24;
  o.height = 18;
  std::map<std::pair<std::uint32_t, std::uint64_t>, std::uint64_t> rays;  // (thread, level)
  std::uint64_t first = 0;
  o.model_events = [&](const BoundaryEvent& e) {
    if (e.port == BoundaryPort::kInput) rays[{e.thread, e.field[1]}] = e.field[4];
    if (e.port != BoundaryPort::kOutput || first != 0) return;
    const bool entry = e.field[0] == static_cast<std::uint64_t>(units::ListOut::kEntry);
    if (!entry || e.field[4] != rays[{e.thread, e.field[1]}]) first = e.cycle;
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
  LockstepOptions o;
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

TEST(ListLockstep, BadInputIsRefusedWithOneLine) {
  LockstepOptions o;
  o.scene = "builtin:room";
  o.units = {"shading"};
  EXPECT_THROW(run_lockstep(o), std::runtime_error);
  o.units = {"list"};
  o.set = {"threads=7"};
  try {
    run_lockstep(o);
    ADD_FAILURE() << "threads=7 has no Verilated build";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no Verilated list unit"), std::string::npos);
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
  o.set = {};
  o.fault = "stack-off-by-one";
  EXPECT_THROW(run_lockstep(o), std::runtime_error);
}

}  // namespace
}  // namespace saarcor::rtl
