// Frame sequences at full size (label deep; docs/bart.md and docs/frames.md quote these runs):
// BART's kitchen and robots, 20 frames each at 512x384 through the cycle model in the prototype
// configuration, the animated glTF models and the built-in dynamic scenes over 30 frames. Every
// frame is checked bit for bit against the functional model (run_sequence throws otherwise).
#include <gtest/gtest.h>

#include <set>

#include "testbench/frame_sequence.h"

namespace saarcor {
namespace {

std::string shared(const std::string& rel) {
  return std::string(SAARCOR_SHARED_SCENES) + "/" + rel;
}

SequenceResult run(const std::string& scene, int w, int h, int n) {
  RenderSettings s;
  s.res = {w, h};
  s.heartbeat = false;
  SequenceOptions o;
  o.frames = n;
  return run_sequence(scene, parse_model("cycle"), s, o);
}

// `dynamic` instances at most move per frame (the kitchen's car starts at 4 s, the robots stop
// one by one); frames where none moves keep their top level. Every frame differs from every other
// (the camera or the objects move).
void expect_moving_sequence(const SequenceResult& r, std::uint32_t dynamic, int gaps) {
  std::set<std::uint64_t> digests;
  std::uint64_t moved = 0;
  for (const SequenceFrame& f : r.frames) {
    SCOPED_TRACE("frame " + std::to_string(f.index));
    EXPECT_TRUE(f.checked);
    digests.insert(f.digest);
    if (f.index == 0) continue;
    EXPECT_EQ(f.bottom_level_builds, 0u);
    EXPECT_LE(f.moved_instances, dynamic);
    EXPECT_EQ(f.top_level_builds, f.moved_instances > 0 ? 1u : 0u);
    moved += f.moved_instances;
  }
  EXPECT_GT(moved, 0u);
  EXPECT_EQ(digests.size(), r.frames.size());
  EXPECT_EQ(r.gaps(), gaps);
  EXPECT_EQ(r.hidden_uploads(), static_cast<int>(r.frames.size()) - 1 - gaps);
  std::printf("%s", sequence_table(r).c_str());
}

TEST(FrameSequenceDeep, BartKitchenTwentyFramesAt512x384) {
  const SequenceResult r = run(shared("BART/kitchen/aff/kitchen.aff"), 512, 384, 20);
  expect_moving_sequence(r, 86, 0);
}

TEST(FrameSequenceDeep, BartRobotsTwentyFramesAt512x384) {
  const SequenceResult r = run(shared("BART/robot/aff/Robot.aff"), 512, 384, 20);
  expect_moving_sequence(r, 220, 0);
}

TEST(FrameSequenceDeep, AnimatedScenesThirtyFrames) {
  expect_moving_sequence(run("builtin:dynamic", 256, 192, 30), 16, 0);
  expect_moving_sequence(run(shared("BoxAnimated/BoxAnimated.gltf"), 256, 192, 30), 1, 1);
  expect_moving_sequence(run(shared("AnimatedCube/AnimatedCube.gltf"), 256, 192, 30), 1, 0);
  expect_moving_sequence(run(shared("CesiumMilkTruck/CesiumMilkTruck.gltf"), 256, 192, 30), 2, 0);
  expect_moving_sequence(run("builtin:suncor-wind", 128, 96, 10), 5622, 0);
}

}  // namespace
}  // namespace saarcor
