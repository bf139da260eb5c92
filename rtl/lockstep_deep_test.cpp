// The traversal and list units in lockstep with the cycle model at full size (label deep;
// rtl/lockstep.h): the room at 512x384 and frame 0 of the BART kitchen at 256x192, 0 divergences.
#include <gtest/gtest.h>

#include <string>

#include "rtl/lockstep.h"

namespace saarcor::rtl {
namespace {

void expect_agreement(const std::string& scene, int w, int h) {
  LockstepOptions o;
  o.units = {"traversal", "list"};
  o.scene = scene;
  o.width = w;
  o.height = h;
  const LockstepResult r = run_lockstep(o);
  EXPECT_FALSE(r.diverged) << r.screen;
  EXPECT_GT(r.unit("list").event(units::BoundaryPort::kOutput), 0u);
  EXPECT_GT(r.unit("traversal").event(units::BoundaryPort::kOutput), 0u);
}

TEST(ListLockstepDeep, Room512x384) {
  expect_agreement("builtin:room", 512, 384);
}

TEST(ListLockstepDeep, BartKitchenFrame0At256x192) {
  expect_agreement(std::string(SAARCOR_SHARED_SCENES) + "/BART/kitchen/aff/kitchen.aff", 256, 192);
}

}  // namespace
}  // namespace saarcor::rtl
