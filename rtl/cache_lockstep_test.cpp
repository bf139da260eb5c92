// The per-type caches (rtl/cache.sv) in lockstep with the cycle model's (memif::Cache): every
// lookup, response and line request in the model's cycle with the model's bits, on the room with
// the prototype's, 8-item and 2-way caches; and the injected fault "a miss merged into the wrong
// target" (cache.sv FAULT_MERGE_WRONG) caught at its first wrong event, which the test finds in
// the healthy run's events: the first request merged into an outstanding miss. (The caches beside
// the four units, on the CI scenes: rtl/lockstep_test.cpp.)
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "rtl/builds_testing.h"
#include "rtl/lockstep.h"
#include "units/boundary_cache.h"

namespace saarcor::rtl {
namespace {

using units::BoundaryEvent;
using units::BoundaryPort;

// The three caches agree with the model's: each request pushed is looked up and answered once,
// each miss sends one line request and gets one fill.
void expect_caches_agree(const LockstepResult& r) {
  ASSERT_FALSE(r.diverged) << r.screen;
  for (const char* name : {"node-cache", "list-cache", "row-cache"}) {
    const LockstepUnit& c = r.unit(name);
    EXPECT_GT(c.event(BoundaryPort::kCacheRequest), 0u) << name;
    EXPECT_EQ(c.event(BoundaryPort::kCacheAccept), c.event(BoundaryPort::kCacheRequest)) << name;
    EXPECT_EQ(c.event(BoundaryPort::kCacheReply), c.event(BoundaryPort::kCacheRequest)) << name;
    EXPECT_GT(c.event(BoundaryPort::kMemRequest), 0u) << name;
    EXPECT_EQ(c.event(BoundaryPort::kMemTaken), c.event(BoundaryPort::kMemRequest)) << name;
    EXPECT_EQ(c.event(BoundaryPort::kMemFill), c.event(BoundaryPort::kMemRequest)) << name;
    std::printf("  %s (build %s): %llu requests, %llu line requests compared\n", name,
                c.build.c_str(),
                static_cast<unsigned long long>(c.event(BoundaryPort::kCacheAccept)),
                static_cast<unsigned long long>(c.event(BoundaryPort::kMemRequest)));
  }
}

LockstepResult run_caches(std::vector<std::string> set) {
  LockstepOptions o;
  o.units = {"caches"};
  o.scene = "builtin:room";
  o.set = std::move(set);
  return run_lockstep(o);
}

TEST(CacheLockstep, RoomPrototypeCaches) {
  expect_caches_agree(run_caches({}));
}
TEST(CacheLockstep, RoomEightItemCaches) {
  expect_caches_agree(run_caches(
      {"cache.traversal.items=8", "cache.list.items=8", "cache.transformation.items=8"}));
}
TEST(CacheLockstep, RoomTwoWayCaches) {
  expect_caches_agree(run_caches({"cache.traversal.items=64", "cache.traversal.ways=2",
                                  "cache.list.items=16", "cache.list.ways=2",
                                  "cache.transformation.items=32", "cache.transformation.ways=2"}));
}

TEST(CacheLockstep, MergeIntoTheWrongTargetIsCaughtAtTheFirstMerge) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  LockstepOptions o;
  o.units = {"caches"};
  o.scene = "builtin:room";
  o.set = {"cache.transformation.items=8"};  // (small: the row cache merges early)
  std::uint64_t first = 0;
  std::string cache;
  o.model_events = [&](const BoundaryEvent& e) {
    if (first != 0 || !e.cache || e.port != BoundaryPort::kCacheAccept) return;
    if (e.field[3] != static_cast<std::uint64_t>(units::CacheKind::kMerge)) return;
    first = e.cycle;
    cache = units::cache_name(e.unit);
  };
  const LockstepResult healthy = run_lockstep(o);
  ASSERT_FALSE(healthy.diverged) << healthy.screen;
  ASSERT_NE(first, 0u) << "no request of the room merged into an outstanding miss";

  o.model_events = nullptr;
  o.fault = "merge-wrong-target";
  const LockstepResult r = run_lockstep(o);
  ASSERT_TRUE(r.diverged);
  EXPECT_EQ(r.divergence.cycle, first) << r.screen;
  EXPECT_EQ(r.divergence.unit, cache);
  EXPECT_EQ(r.divergence.port, "cache_accept");
  EXPECT_EQ(r.divergence.kind, "payload");
  EXPECT_EQ(r.divergence.field, "mshr");
  EXPECT_EQ(r.divergence.rtl_value, (r.divergence.model_value + 1) % 8);
}

// A cache configuration no build has is one error line naming it.
TEST(CacheLockstep, ConfigurationsNoBuildHasAreRefused) {
  const auto error = [](std::vector<std::string> set) {
    try {
      (void)run_caches(std::move(set));
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_NE(error({"cache.traversal.items=24", "cache.traversal.ways=3"}).find("power of two"),
            std::string::npos);
  EXPECT_NE(error({"cache.hit_latency=3"}).find("no Verilated node-cache for cache.hit_latency=3"),
            std::string::npos);
  EXPECT_NE(error({"cache.list.items=1024"}).find("items=1024"), std::string::npos);
}

}  // namespace
}  // namespace saarcor::rtl
