// The four units (traversal, list, transformation, intersection) and the three caches in lockstep
// with the cycle model at full size (label deep; rtl/lockstep.h): the room at 512x384 and frame 0
// of the BART kitchen at 256x192, 0 divergences. The whole DynRTC in RTL (rtl/dynrtc.sv) on the
// room at 512x384, builtin:suncor at 256x192 and frame 0 of the BART robots at 256x192: 0
// divergences, and the frame the model's RGS wrote from the hit records every port agreed on is
// the functional model's, pixel for pixel.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "host/image_builder.h"
#include "host/scene.h"
#include "rtl/lockstep.h"
#include "units/cycle_params.h"
#include "units/dynrtp.h"
#include "units/functional_model.h"

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

// The whole DynRTC, and the lockstep frame against the functional model's (R, G, B bytes).
void expect_whole_dynrtc(const std::string& scene, int w, int h) {
  LockstepOptions o;
  o.units = {"dynrtc"};
  o.scene = scene;
  o.width = w;
  o.height = h;
  const LockstepResult r = run_lockstep(o);
  ASSERT_FALSE(r.diverged) << r.screen;
  EXPECT_GT(r.unit("dynrtc").event(units::BoundaryPort::kMemFill), 0u);
  host::ImageParams ip;
  ip.width = w;
  ip.height = h;
  const host::BuiltImage built = host::build_image(host::load_scene(scene), ip);
  const units::FunctionalFrame f =
      units::run_functional(built.image, units::functional_params(units::prototype_params()));
  ASSERT_EQ(r.frame.size(), static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  std::size_t differ = 0;
  for (std::size_t i = 0; i < r.frame.size(); ++i)
    for (std::size_t c = 0; c < 3; ++c)
      differ += ((r.frame[i] >> (8 * c)) & 0xFFu) != f.rgb[3 * i + c] ? 1 : 0;
  EXPECT_EQ(differ, 0u) << "channels that differ from the functional model's";
  std::printf("  whole DynRTC: %llu cycles, %.0f k cycles/s co-simulated, %zu pixels identical\n",
              static_cast<unsigned long long>(r.cycles), r.cycles / r.seconds / 1e3,
              r.frame.size());
}

TEST(DynrtcLockstepDeep, Room512x384) {
  expect_whole_dynrtc("builtin:room", 512, 384);
}

TEST(DynrtcLockstepDeep, Suncor256x192) {
  expect_whole_dynrtc("builtin:suncor", 256, 192);
}

TEST(DynrtcLockstepDeep, BartRobotsFrame0At256x192) {
  expect_whole_dynrtc(std::string(SAARCOR_SHARED_SCENES) + "/BART/robot/aff/Robot.aff", 256, 192);
}

TEST(ListLockstepDeep, Room512x384) {
  expect_agreement("builtin:room", 512, 384);
}

TEST(ListLockstepDeep, BartKitchenFrame0At256x192) {
  expect_agreement(std::string(SAARCOR_SHARED_SCENES) + "/BART/kitchen/aff/kitchen.aff", 256, 192);
}

}  // namespace
}  // namespace saarcor::rtl
