// The transformation unit (rtl/transformation_threads.sv) in lockstep with the cycle model: the
// injected fault "the n + 1 rule off" (FAULT_N_PLUS_ONE_OFF: 2n steps for a packet whose rays
// share an origin) is caught at its first wrong event, which the test finds in the healthy run's
// events: the first thread leaving the unit (every primary packet shares its origin, D31), which
// the faulty RTL lets go n - 1 cycles later. And "a row fetched out of order"
// (FAULT_ROW_ORDER: an entry's second row requested third and its third second), caught at the
// healthy run's second row request: the first entry's second row, whose address the faulty RTL
// sends one row later.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "rtl/builds_testing.h"
#include "rtl/lockstep.h"
#include "units/boundary_transformation.h"
#include "units/cycle_params.h"

namespace saarcor::rtl {
namespace {

using units::BoundaryEvent;
using units::BoundaryPort;

// The transformation unit alone on the room at 24x18.
LockstepOptions room_transformation() {
  LockstepOptions o;
  o.units = {"transformation"};
  o.scene = "builtin:room";
  o.width = 24;
  o.height = 18;
  return o;
}

TEST(TransformationLockstep, NPlusOneOffIsCaughtAtTheFirstSharedOriginPacket) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  LockstepOptions o = room_transformation();
  std::uint64_t first = 0;
  bool shared = false;
  o.model_events = [&](const BoundaryEvent& e) {
    if (e.unit != units::UnitId::kTransformation || e.port != BoundaryPort::kOutput) return;
    if (first != 0) return;
    first = e.cycle;
    shared = e.field[2] != 0;
  };
  const LockstepResult healthy = run_lockstep(o);
  ASSERT_FALSE(healthy.diverged) << healthy.screen;
  ASSERT_NE(first, 0u);
  ASSERT_TRUE(shared) << "the room's first packet does not share its origin";

  o.model_events = nullptr;
  o.fault = "n-plus-one-off";
  const LockstepResult r = run_lockstep(o);
  ASSERT_TRUE(r.diverged);
  EXPECT_EQ(r.divergence.cycle, first) << r.screen;
  EXPECT_EQ(r.divergence.unit, "transformation");
  EXPECT_EQ(r.divergence.port, "output");
  EXPECT_EQ(r.divergence.kind, "timing");
  const int n = units::prototype_params().packet;
  EXPECT_EQ(r.divergence.other_cycle, first + static_cast<std::uint64_t>(2 * n - (n + 1)));
}

TEST(TransformationLockstep, RowOutOfOrderIsCaughtAtTheFirstEntrysSecondRow) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  LockstepOptions o = room_transformation();
  int requests = 0;
  std::uint64_t second = 0, address = 0;
  o.model_events = [&](const BoundaryEvent& e) {
    if (e.unit != units::UnitId::kTransformation || e.cache) return;
    if (e.port != BoundaryPort::kCacheRequest || ++requests != 2) return;
    second = e.cycle;
    address = e.field[0];
  };
  const LockstepResult healthy = run_lockstep(o);
  ASSERT_FALSE(healthy.diverged) << healthy.screen;
  ASSERT_NE(second, 0u);

  o.model_events = nullptr;
  o.fault = "row-out-of-order";
  const LockstepResult r = run_lockstep(o);
  ASSERT_TRUE(r.diverged);
  EXPECT_EQ(r.divergence.cycle, second) << r.screen;
  EXPECT_EQ(r.divergence.unit, "transformation");
  EXPECT_EQ(r.divergence.port, "cache_request");
  EXPECT_EQ(r.divergence.kind, "payload");
  EXPECT_EQ(r.divergence.field, "address");
  EXPECT_EQ(r.divergence.model_value, address);
  EXPECT_EQ(r.divergence.rtl_value, address + 1);
}

}  // namespace
}  // namespace saarcor::rtl
