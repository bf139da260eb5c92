// The whole DynRTC in RTL (rtl/dynrtc.sv: the four units, the three caches and the simple routing
// wired to each other) in lockstep with the cycle model, which gives it only what the RGS hands
// over and what the memory controller's cache port does: every unit's and cache's output and the
// routing's work are compared, 0 divergences, on the scenes and configurations the units run on
// alone, with shadows and secondary rays, with 2-way caches, and two DynRTCs on one routing
// (pipelines=2). (The units alone: rtl/lockstep_test.cpp.)
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "rtl/builds_testing.h"
#include "rtl/lockstep.h"

namespace saarcor::rtl {
namespace {

using units::BoundaryPort;

LockstepResult run_dynrtc(const std::string& scene, std::vector<std::string> set,
                          bool shadows = false, int depth = 0) {
  LockstepOptions o;
  o.units = {"dynrtc"};
  o.scene = scene;
  o.set = std::move(set);
  o.shadows = shadows;
  o.depth = depth;
  return run_lockstep(o);
}

// Every request a unit pushes is looked up and answered once; every line request is taken by
// the routing, answered by the controller and filled; the RGS handed packets over.
void expect_whole_agrees(const LockstepResult& r) {
  ASSERT_FALSE(r.diverged) << r.screen;
  const LockstepUnit& d = r.unit("dynrtc");
  EXPECT_GT(d.event(BoundaryPort::kInput), 0u);
  // Each packet the RGS generates starts on two side bands (the list unit's mailbox clear, the
  // intersection unit's hit reset); a shadow packet also comes back on RGS -> traversal.
  EXPECT_EQ(d.event(BoundaryPort::kSideBand) % 2, 0u);
  EXPECT_LE(d.event(BoundaryPort::kSideBand), 2 * d.event(BoundaryPort::kInput));
  EXPECT_GT(d.event(BoundaryPort::kOutput), 0u);
  EXPECT_GT(d.event(BoundaryPort::kCacheRequest), 0u);
  EXPECT_EQ(d.event(BoundaryPort::kCacheAccept), d.event(BoundaryPort::kCacheRequest));
  EXPECT_EQ(d.event(BoundaryPort::kCacheReply), d.event(BoundaryPort::kCacheRequest));
  EXPECT_GT(d.event(BoundaryPort::kMemRequest), 0u);
  EXPECT_EQ(d.event(BoundaryPort::kMemTaken), d.event(BoundaryPort::kMemRequest));
  EXPECT_EQ(d.event(BoundaryPort::kMemFill), d.event(BoundaryPort::kMemRequest));
  EXPECT_EQ(d.event(BoundaryPort::kPortResponse), d.event(BoundaryPort::kMemRequest));
  std::printf("  build %s: %llu cycles, %llu outputs, %llu cache requests, %llu line requests\n",
              d.build.c_str(), static_cast<unsigned long long>(r.model_cycles),
              static_cast<unsigned long long>(d.event(BoundaryPort::kOutput)),
              static_cast<unsigned long long>(d.event(BoundaryPort::kCacheRequest)),
              static_cast<unsigned long long>(d.event(BoundaryPort::kMemRequest)));
}

TEST(DynrtcLockstep, RoomPrototype) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  const LockstepResult r = run_dynrtc("builtin:room", {});
  expect_whole_agrees(r);
  // 32x24 at P = 4: 192 packets, each handed to the transformation unit on path a once.
  EXPECT_EQ(r.unit("dynrtc").event(BoundaryPort::kInput), 192u);
  EXPECT_EQ(r.unit("dynrtc").event(BoundaryPort::kSideBand), 384u);
  EXPECT_EQ(r.unit("dynrtc").build, "proto");
}

TEST(DynrtcLockstep, RoomOneRayPacketsThirteenThreadsOneEntryMailboxes) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  const LockstepResult r = run_dynrtc("builtin:room", {"threads=13", "packet=1", "mailbox=1",
                                                       "triangle_mailbox=1", "cache.list.items=8"});
  expect_whole_agrees(r);
  EXPECT_EQ(r.unit("dynrtc").event(BoundaryPort::kInput), 768u);  // 32x24 one-ray packets
}

TEST(DynrtcLockstep, RoomSixteenRayPackets) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  expect_whole_agrees(run_dynrtc("builtin:room", {"threads=16", "packet=16"}));
}

TEST(DynrtcLockstep, RoomTwoWayCaches) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  expect_whole_agrees(
      run_dynrtc("builtin:room", {"cache.traversal.items=64", "cache.traversal.ways=2",
                                  "cache.list.ways=2", "cache.transformation.ways=2"}));
}

TEST(DynrtcLockstep, DynamicShadowsAndSecondaryRays) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  expect_whole_agrees(run_dynrtc("builtin:dynamic", {}, true, 2));
}

TEST(DynrtcLockstep, RoomShadowsAndSecondaryRays) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  expect_whole_agrees(run_dynrtc("builtin:room", {}, true, 2));
}

TEST(DynrtcLockstep, Suncor) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  expect_whole_agrees(run_dynrtc("builtin:suncor", {}));
}

TEST(DynrtcLockstep, DuckGltf) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  expect_whole_agrees(run_dynrtc(std::string(SAARCOR_SHARED_SCENES) + "/Duck/Duck.gltf", {}));
}

TEST(DynrtcLockstep, TwoCylinderEngineSixteenRayPackets) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  expect_whole_agrees(
      run_dynrtc(std::string(SAARCOR_SHARED_SCENES) + "/2CylinderEngine/2CylinderEngine.gltf",
                 {"threads=16", "packet=16"}));
}

// pipelines=2: two whole DynRTCs on one RTL routing share the model's memory controller; every
// event of both is compared (the second's threads are the model's ids 64..127).
TEST(DynrtcLockstep, TwoPipelinesShareOneRoutingAndTheController) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  std::vector<units::BoundaryEvent> events;
  LockstepOptions o;
  o.units = {"dynrtc"};
  o.scene = "builtin:room";
  o.set = {"pipelines=2"};
  std::array<std::uint64_t, 2> outputs{};
  o.model_events = [&](const units::BoundaryEvent& e) {
    if (e.port == BoundaryPort::kOutput && !e.cache) ++outputs[static_cast<std::size_t>(e.dynrtp)];
  };
  const LockstepResult r = run_lockstep(o);
  expect_whole_agrees(r);
  // Both DynRTPs worked; 192 packets between them, each generated once.
  EXPECT_GT(outputs[0], 0u);
  EXPECT_GT(outputs[1], 0u);
  EXPECT_EQ(r.unit("dynrtc").event(BoundaryPort::kInput), 192u);
  EXPECT_EQ(r.unit("dynrtc").event(BoundaryPort::kOutput), outputs[0] + outputs[1]);
}

TEST(DynrtcLockstep, RunsAloneAndOnlyOnItsBuildsConfigurations) {
  LockstepOptions o;
  o.scene = "builtin:room";
  o.units = {"dynrtc", "list"};
  EXPECT_THROW(run_lockstep(o), std::runtime_error);
  o.units = {"dynrtc"};
  o.set = {"lat.add=4"};
  try {
    run_lockstep(o);
    ADD_FAILURE() << "a latency the whole DynRTC is not built for ran";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("prototype's latencies"), std::string::npos) << e.what();
  }
  o.set = {"cache.traversal.ways=3"};
  EXPECT_THROW(run_lockstep(o), std::runtime_error);
  o.set = {};
  o.fault = "pop-off";  // the faults are the units' builds: never silently a healthy run
  EXPECT_THROW(run_lockstep(o), std::runtime_error);
  o.fault = "";
  o.set = {"pipelines=3"};
  EXPECT_THROW(run_lockstep(o), std::runtime_error);
  o.units = {"list"};
  o.set = {"pipelines=2"};  // two DynRTPs run only as whole DynRTCs
  EXPECT_THROW(run_lockstep(o), std::runtime_error);
}

}  // namespace
}  // namespace saarcor::rtl
