// Per-type caches behind the simple routing and the memory controller (docs/memif.md;
// decision D20): exact hit and miss latencies with a mock unit, merging of secondary misses,
// MSHR back-pressure, fair arbitration, invalidation, bad configurations.
#include "memif/cache.h"

#include <gtest/gtest.h>

#include <functional>

#include "memif/memory_system.h"
#include "memif/test_traffic.h"

namespace saarcor::memif {
namespace {

// A mock unit: pushes scripted requests at given cycles, pops every response, records cycles.
class MockUnit : public hw::Module {
 public:
  MockUnit(hw::Kernel& k, Cache& c, std::vector<std::pair<std::uint64_t, std::uint32_t>> script)
      : hw::Module(k, "unit." + c.name()), c_(c), script_(std::move(script)) {}
  int evaluate() override {
    int p = 0;
    if (c_.responses().can_pop()) {
      got.emplace_back(now(), c_.responses().pop());
      ++p;
    }
    if (next_ < script_.size() && script_[next_].first <= now() && c_.requests().can_push()) {
      c_.requests().push({script_[next_].second, {9, static_cast<std::uint32_t>(next_)}});
      pushed_at.push_back(now());
      ++next_;
      ++p;
    }
    return p;
  }
  Cache& c_;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> script_;
  std::size_t next_ = 0;
  std::vector<std::uint64_t> pushed_at;
  std::vector<std::pair<std::uint64_t, CacheResponse>> got;
};

TEST(Cache, MissAndHitLatenciesThroughRoutingAndControllerAreExact) {
  // Miss: push 0 -> lookup 1 -> routing 2 -> controller queue 3 -> bank start 4 -> last word at
  // 4 + w - 1, data 4 cycles later -> routing -> fill and bypass to the response at 4+w-1+4+2
  // -> poppable one cycle later. Hit: hit_latency (2) after the push.
  for (ItemType t : {ItemType::kNode, ItemType::kList, ItemType::kRow}) {
    MemoryImage img = testing::random_scene_image(ff::kFp24, 1);
    hw::Kernel k;
    MemorySystem mi(k, img);
    Cache& c = mi.cache(0, t);
    MockUnit unit(k, c, {{0, 7}, {40, 7}});
    k.run_to_completion([&] { return unit.got.size() == 2; }, 1000);
    const int w = img.item_words(t);
    EXPECT_EQ(unit.got[0].first, static_cast<std::uint64_t>(4 + w - 1 + 4 + 2 + 1))
        << item_type_name(t);
    EXPECT_EQ(unit.got[1].first, 42u) << item_type_name(t);
    for (const auto& [cycle, r] : unit.got) {
      EXPECT_EQ(r.index, 7u);
      EXPECT_EQ(r.count, w);
      for (int i = 0; i < w; ++i)
        EXPECT_EQ(r.words[i], img.item_word(t, 7, i));
    }
    EXPECT_EQ(c.hits(), 1u);
    EXPECT_EQ(c.misses(), 1u);
    EXPECT_EQ(mi.controller().client_bytes(c.client()), 4u * static_cast<unsigned>(w));
  }
}

TEST(Cache, SecondaryMissesMergeAndCostNoSecondMemoryRequest) {
  MemoryImage img = testing::random_scene_image(ff::kFp24, 2);
  hw::Kernel k;
  MemorySystem mi(k, img);
  Cache& c = mi.cache(0, ItemType::kNode);
  // Four threads ask for node 5 in consecutive cycles, then one for node 5 + 512 (same set).
  MockUnit unit(k, c, {{0, 5}, {1, 5}, {2, 5}, {3, 5}});
  k.run_to_completion([&] { return unit.got.size() == 4; }, 1000);
  EXPECT_EQ(c.misses(), 1u);
  EXPECT_EQ(c.merges(), 3u);
  EXPECT_EQ(c.hits(), 0u);
  EXPECT_EQ(mi.controller().client_bytes(c.client()), 8u);
  // The fill answers the first at 12, the merged ones one per cycle after it.
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(unit.got[i].first, 12u + i);
    EXPECT_EQ(unit.got[i].second.label.tag, static_cast<std::uint32_t>(i));
  }
  EXPECT_DOUBLE_EQ(k.stats().value("dynrtp0.node_cache.hit_rate_with_merges"), 0.75);
}

TEST(Cache, OutstandingMissLimitBackPressuresTheUnit) {
  MemoryImage img = testing::random_scene_image(ff::kFp24, 3);
  hw::Kernel k;
  MemorySystemConfig cfg;
  cfg.list_cache.max_misses = 2;
  cfg.list_cache.request_capacity = 1;
  MemorySystem mi(k, img, cfg);
  Cache& c = mi.cache(0, ItemType::kList);
  MockUnit unit(k, c, {{0, 1}, {0, 2}, {0, 3}, {0, 4}});
  k.run_to_completion([&] { return unit.got.size() == 4; }, 1000);
  EXPECT_EQ(c.misses(), 4u);
  // Requests 3 and 4 could only be accepted after a miss completed.
  EXPECT_GT(unit.pushed_at[3], unit.got[0].first - 2);
  EXPECT_GT(k.stats().value("dynrtp0.list_cache.stall_cycles"), 0.0);
}

TEST(Cache, InvalidateDropsLinesSoTheNextRequestMisses) {
  MemoryImage img = testing::random_scene_image(ff::kFp24, 4);
  hw::Kernel k;
  MemorySystem mi(k, img);
  Cache& c = mi.cache(0, ItemType::kRow);
  MockUnit unit(k, c, {{0, 3}});
  k.run_to_completion([&] { return unit.got.size() == 1; }, 1000);
  mi.invalidate_caches();
  unit.script_.push_back({k.now(), 3});
  k.run_to_completion([&] { return unit.got.size() == 2; }, 1000);
  EXPECT_EQ(c.misses(), 2u);
  EXPECT_EQ(c.hits(), 0u);
}

TEST(Cache, RoutingArbitratesRoundRobinAmongCaches) {
  // Three caches miss in the same cycle, twice over: the routing forwards one per cycle in turn,
  // so no cache waits more than two cycles behind the others.
  MemoryImage img = testing::random_scene_image(ff::kFp24, 5);
  hw::Kernel k;
  MemorySystem mi(k, img);
  std::vector<std::unique_ptr<MockUnit>> units;
  for (ItemType t : {ItemType::kNode, ItemType::kList, ItemType::kRow}) {
    units.push_back(std::make_unique<MockUnit>(
        k, mi.cache(0, t), std::vector<std::pair<std::uint64_t, std::uint32_t>>{{0, 0}, {0, 3}}));
  }
  k.run_to_completion(
      [&] {
        for (auto& u : units) {
          if (u->got.size() != 2) return false;
        }
        return true;
      },
      1000);
  EXPECT_EQ(k.stats().value("mi.routing.requests"), 6.0);
  for (auto& u : units)
    EXPECT_EQ(u->got.size(), 2u);
}

TEST(Cache, BadConfigurationsAreRefusedWithOneLine) {
  MemoryImage img = testing::random_scene_image(ff::kFp24, 6);
  hw::Kernel k;
  auto make = [&](auto edit) {
    CacheConfig cfg;
    edit(cfg);
    Cache c(k, "bad", ItemType::kNode, img, 0, cfg);
  };
  EXPECT_THROW(make([](CacheConfig& c) { c.items = 0; }), std::runtime_error);
  EXPECT_THROW(make([](CacheConfig& c) { c.ways = 3; }), std::runtime_error);
  EXPECT_THROW(make([](CacheConfig& c) { c.hit_latency = 1; }), std::runtime_error);
  EXPECT_THROW(make([](CacheConfig& c) { c.max_misses = 0; }), std::runtime_error);
  EXPECT_THROW(make([](CacheConfig& c) { c.max_targets = 0; }), std::runtime_error);
  try {
    make([](CacheConfig& c) { c.ways = 3; });
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "cache 'bad': ways must divide items (512 items, 3 ways)");
  }
}

}  // namespace
}  // namespace saarcor::memif
