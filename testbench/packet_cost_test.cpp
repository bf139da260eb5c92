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
  EXPECT_EQ(cost_features(corner), (CostFeatures{1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}));
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
  EXPECT_EQ(cost_features(centre), (CostFeatures{1, 0, 1, 2, 2, 1, 1, 0, 0, 0, 0, 0, 0}));
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

TEST(PacketCost, ShadowRaysTowardsTheLightsThatLightTheHit) {
  // builtin:triangle's light sits at (0, 1, 3), in front of the triangle: the centre's hit (0,0,0)
  // is lit, and its shadow ray runs from the light towards it over t < 1 - 1/512, so it stops
  // short of the plane z = 0, which is the scene's whole box: one shadow ray, no step, no test.
  // The corner's ray misses: no shadow ray.
  const memif::MemoryImage image = sample_check_image("builtin:triangle", "64x48");
  const PacketCostModel model(image);
  const RayCost centre = model.trace_pixel(31.5, 23.5, {.shadows = true});
  EXPECT_EQ(centre.shadow_rays, 1u);
  EXPECT_EQ(centre.shadow_steps, 0u);
  EXPECT_EQ(centre.shadow_tests, 0u);
  EXPECT_EQ(cost_features(centre), (CostFeatures{1, 0, 1, 2, 2, 1, 1, 1, 0, 0, 0, 0, 0}));
  EXPECT_EQ(model.trace_pixel(0, 0, {.shadows = true}).shadow_rays, 0u);
  // A shadow ray that meets a triangle on its way ends there (any hit): from (0, 0, -1), behind
  // the triangle, to (0, 0, 1) in front of it, over t < 1 - 1/512.
  const RayCost through = model.trace({0, 0, -1}, {0, 0, 2}, 1.0f - 1.0f / 512.0f, true);
  EXPECT_TRUE(through.hit);
  EXPECT_EQ(through.tests, 1u);
  // The room under its lights: the primary rays' work is the same with shadows or without, and
  // every shadow ray belongs to a lit hit (at most one per light), some of them tested against
  // the room's triangles.
  const memif::MemoryImage room_image = sample_check_image("builtin:room", "64x48");
  const std::vector<RayCost> plain = packet_costs(room_image, 4);
  const std::vector<RayCost> lit = packet_costs(room_image, 4, {.shadows = true});
  ASSERT_EQ(plain.size(), lit.size());
  std::uint64_t shadow_rays = 0, shadow_tests = 0;
  for (std::size_t i = 0; i < lit.size(); ++i) {
    EXPECT_EQ(lit[i].steps, plain[i].steps);
    EXPECT_EQ(lit[i].tests, plain[i].tests);
    EXPECT_EQ(plain[i].shadow_rays, 0u);
    EXPECT_LE(lit[i].shadow_rays, lit[i].hit ? room_image.registers().light_count : 0u);
    shadow_rays += lit[i].shadow_rays;
    shadow_tests += lit[i].shadow_tests;
  }
  EXPECT_GT(shadow_rays, lit.size() / 2);
  EXPECT_GT(shadow_tests, shadow_rays);
}

TEST(PacketCost, SecondaryRaysOfReflectiveAndRefractiveHits) {
  // builtin:glass holds a mirror (reflectivity 0.95) and two refracting materials: with secondary
  // rays their hits spawn children down to the depth bound, each counted once with its work; a
  // bound of 0 spawns none, and the primary rays' work stays what it was.
  const memif::MemoryImage image = sample_check_image("builtin:glass", "64x48");
  const std::vector<RayCost> plain = packet_costs(image, 4);
  const std::vector<RayCost> one = packet_costs(image, 4, {.secondary = true, .max_depth = 1});
  const std::vector<RayCost> three = packet_costs(image, 4, {.secondary = true, .max_depth = 3});
  const std::vector<RayCost> none = packet_costs(image, 4, {.secondary = true, .max_depth = 0});
  std::uint64_t rays1 = 0, rays3 = 0, tests1 = 0;
  for (std::size_t i = 0; i < plain.size(); ++i) {
    EXPECT_EQ(three[i].steps, plain[i].steps);
    EXPECT_EQ(none[i].secondary_rays, 0u);
    // At depth 1 a hit spawns at most its three children.
    EXPECT_LE(one[i].secondary_rays, 3u);
    EXPECT_LE(one[i].secondary_rays, three[i].secondary_rays);
    EXPECT_EQ(one[i].shadow_rays, 0u);
    rays1 += one[i].secondary_rays;
    rays3 += three[i].secondary_rays;
    tests1 += one[i].secondary_tests;
  }
  EXPECT_GT(rays1, plain.size() / 20);
  EXPECT_GT(rays3, rays1);
  EXPECT_GT(tests1, rays1);
}

}  // namespace
}  // namespace saarcor
