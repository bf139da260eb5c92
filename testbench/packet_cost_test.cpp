// The packets' cost covariate (testbench/packet_cost.h) on packets whose work is known by hand.
#include "testbench/packet_cost.h"

#include <gtest/gtest.h>

#include "testbench/sample_check.h"
#include "units/functional_model.h"

namespace saarcor {
namespace {

TEST(PacketCost, EmptyPacketCostsTheBoxTestOnly) {
  // builtin:triangle: one triangle (-1,-1,0), (1,-1,0), (0,1,0) seen from (0,0,3). Its scene box
  // is the triangle's, [-1,1] x [-1,1] x [0,0]. The top-left pixel's ray meets the plane z = 0
  // outside it: no kd step, no test; its features the constant alone (the box test every packet
  // makes).
  const memif::MemoryImage image = sample_check_image("builtin:triangle", "64x48");
  const PacketCostModel model(image);
  const RayCost corner = model.trace_pixel(0, 0);
  EXPECT_FALSE(corner.box);
  EXPECT_FALSE(corner.hit);
  EXPECT_EQ(corner.steps, 0u);
  EXPECT_EQ(corner.leaves, 0u);
  EXPECT_EQ(corner.tests, 0u);
  EXPECT_EQ(cost_features(corner), (CostFeatures{1, 0, 0, 0, 0, 0, 0}));
  // The image centre's ray hits (0,0,0), inside the triangle. Both trees are single leaves (one
  // instance, one triangle): no step, two leaves, two list entries (the instance, the
  // triangle), one transformation, one test, inside the box.
  const RayCost centre = model.trace_pixel(31.5, 23.5);
  EXPECT_TRUE(centre.box);
  EXPECT_TRUE(centre.hit);
  EXPECT_EQ(centre.steps, 0u);
  EXPECT_EQ(centre.leaves, 2u);
  EXPECT_EQ(centre.lists, 2u);
  EXPECT_EQ(centre.transforms, 1u);
  EXPECT_EQ(centre.tests, 1u);
  EXPECT_EQ(cost_features(centre), (CostFeatures{1, 0, 1, 2, 2, 1, 1}));
}

TEST(PacketCost, OneRayPerPacketThroughTheTileCentre) {
  // 64x48 in 2x2 packets: 32 x 24 = 768 packets in the RGC's order (row of tiles after row).
  // Packet 0 (pixels 0..1 x 0..1) traces pixel (0.5, 0.5): the corner's miss. Packet 12 * 32 + 16
  // holds pixels 32..33 x 24..25 and traces (32.5, 24.5), next to the centre: a hit.
  const memif::MemoryImage image = sample_check_image("builtin:triangle", "64x48");
  const std::vector<RayCost> costs = packet_costs(image, 4);
  ASSERT_EQ(costs.size(), 768u);
  EXPECT_FALSE(costs[0].box);
  EXPECT_TRUE(costs[12 * 32 + 16].hit);
  EXPECT_EQ(costs[12 * 32 + 16].tests, 1u);
  // A scene with kd steps: the room's packets step through its tree, and the covariate counts
  // them.
  const std::vector<RayCost> room = packet_costs(sample_check_image("builtin:room", "64x48"), 4);
  double steps = 0;
  for (const RayCost& c : room)
    steps += c.steps;
  EXPECT_GT(steps / static_cast<double>(room.size()), 5.0);
}

}  // namespace
}  // namespace saarcor
