// The four units (traversal, list, transformation, intersection) and the three caches in lockstep
// with the cycle model at full size (label deep; rtl/lockstep.h): the room at 512x384 and frame 0
// of the BART kitchen at 256x192, 0 divergences.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "rtl/lockstep.h"

namespace saarcor::rtl {
namespace {

void expect_agreement(const std::string& scene, int w, int h) {
  LockstepOptions o;
  o.units = {"traversal", "list", "transformation", "intersection", "caches"};
  o.scene = scene;
  o.width = w;
  o.height = h;
  const LockstepResult r = run_lockstep(o);
  EXPECT_FALSE(r.diverged) << r.screen;
  EXPECT_GT(r.unit("list").event(units::BoundaryPort::kOutput), 0u);
  EXPECT_GT(r.unit("traversal").event(units::BoundaryPort::kOutput), 0u);
  EXPECT_GT(r.unit("transformation").event(units::BoundaryPort::kCacheRequest), 0u);
  EXPECT_GT(r.unit("intersection").event(units::BoundaryPort::kOutput), 0u);
  for (const char* cache : {"node-cache", "list-cache", "row-cache"})
    EXPECT_GT(r.unit(cache).event(units::BoundaryPort::kMemRequest), 0u) << cache;
  std::printf("  %llu cycles, %.0f k cycles/s co-simulated\n",
              static_cast<unsigned long long>(r.cycles), r.cycles / r.seconds / 1e3);
}

TEST(ListLockstepDeep, Room512x384) {
  expect_agreement("builtin:room", 512, 384);
}

TEST(ListLockstepDeep, BartKitchenFrame0At256x192) {
  expect_agreement(std::string(SAARCOR_SHARED_SCENES) + "/BART/kitchen/aff/kitchen.aff", 256, 192);
}

}  // namespace
}  // namespace saarcor::rtl
