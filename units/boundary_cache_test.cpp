// The caches' boundary record (units/boundary_cache.h) from the model: a kd-node cache behind the
// simple routing and the memory controller, driven by a mock unit that reports its pushes and
// takes as CycleUnit does; every event in its cycle with its fields.
#include "units/boundary_cache.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <utility>
#include <vector>

#include "memif/memory_system.h"
#include "memif/test_traffic.h"

namespace saarcor::units {
namespace {

// Pushes item 7 at the scripted cycles and takes every response, reporting both to `rec` as a
// unit's cache hooks do (UnitObserver::cache_request, cache_response).
class MockUnit : public hw::Module {
 public:
  MockUnit(hw::Kernel& k, memif::Cache& c, CacheRecorder& rec, std::vector<std::uint64_t> at)
      : hw::Module(k, "unit"), c_(c), rec_(rec), at_(std::move(at)) {}
  int evaluate() override {
    int p = 0;
    if (c_.responses().can_pop()) {
      rec_.cache_response(now(), UnitId::kTraversal, c_.responses().peek());
      c_.responses().drop();
      ++taken;
      ++p;
    }
    if (next_ < at_.size() && at_[next_] <= now() && c_.requests().can_push()) {
      const memif::CacheRequest r{7, {2, static_cast<std::uint32_t>(next_++)}};
      c_.requests().push(r);
      rec_.cache_request(now(), UnitId::kTraversal, r);
      ++p;
    }
    return p;
  }
  int taken = 0;

 private:
  memif::Cache& c_;
  CacheRecorder& rec_;
  std::vector<std::uint64_t> at_;
  std::size_t next_ = 0;
};

std::vector<BoundaryEvent> of(const std::vector<BoundaryEvent>& all, BoundaryPort p) {
  std::vector<BoundaryEvent> v;
  for (const BoundaryEvent& e : all)
    if (e.port == p) v.push_back(e);
  return v;
}

// Item 7 pushed in cycles 0, 1 and 40: a miss, a merge into its MSHR 0, a hit.
TEST(CacheRecorder, MissMergeAndHitWithTheirLineRequestFillAndReplies) {
  memif::MemoryImage img = memif::testing::random_scene_image(ff::kFp24, 1);
  hw::Kernel k;
  memif::MemorySystem mi(k, img);
  std::vector<BoundaryEvent> events;
  CacheRecorder rec(mi, img, {memif::ItemType::kNode}, nullptr,
                    [&](const BoundaryEvent& e) { events.push_back(e); });
  MockUnit unit(k, mi.cache(0, memif::ItemType::kNode), rec, {0, 1, 40});
  k.run_to_completion([&] { return unit.taken == 3; }, 1000);
  for (const BoundaryEvent& e : events) {
    EXPECT_TRUE(e.cache);
    EXPECT_EQ(e.unit, UnitId::kTraversal);
  }
  const auto requests = of(events, BoundaryPort::kCacheRequest);
  ASSERT_EQ(requests.size(), 3u);
  EXPECT_EQ(requests[2].cycle, 40u);
  // Looked up a cycle after the push (the request queue's latency): miss, merge, hit.
  const auto accepts = of(events, BoundaryPort::kCacheAccept);
  ASSERT_EQ(accepts.size(), 3u);
  const std::uint64_t kinds[] = {2, 1, 0};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(accepts[i].cycle, requests[i].cycle + 1);
    EXPECT_EQ(accepts[i].field[0], 7u);
    EXPECT_EQ(accepts[i].field[1], 2u);
    EXPECT_EQ(accepts[i].field[2], i);
    EXPECT_EQ(accepts[i].field[3], kinds[i]);
    EXPECT_EQ(accepts[i].field[4], 0u);  // MSHR 0 (the hit: 0)
  }
  // One line request in the miss's cycle: MSHR 0, bank 3 + 7 mod 3, base 0 + (7 div 3) * 2.
  const auto line = of(events, BoundaryPort::kMemRequest);
  ASSERT_EQ(line.size(), 1u);
  EXPECT_EQ(line[0].cycle, accepts[0].cycle);
  EXPECT_EQ(line[0].field[0], 0u);
  EXPECT_EQ(line[0].field[1], 4u);
  EXPECT_EQ(line[0].field[2], 4u);
  EXPECT_EQ(line[0].field[3], 2u);
  // The routing takes it a cycle later and brings the fill with the item's words.
  const auto taken = of(events, BoundaryPort::kMemTaken);
  ASSERT_EQ(taken.size(), 1u);
  EXPECT_EQ(taken[0].cycle, line[0].cycle + 1);
  const auto fill = of(events, BoundaryPort::kMemFill);
  ASSERT_EQ(fill.size(), 1u);
  EXPECT_EQ(fill[0].fields, 3);
  EXPECT_EQ(fill[0].field[1], img.item_word(memif::ItemType::kNode, 7, 0));
  EXPECT_EQ(fill[0].field[2], img.item_word(memif::ItemType::kNode, 7, 1));
  // Replies where the unit takes them: the fill answers the miss and then the merge, one a cycle
  // (written a cycle after its push, then hit_latency - 1 in the response channel); the hit
  // hit_latency after its push.
  const std::uint64_t hit = static_cast<std::uint64_t>(memif::CacheConfig{}.hit_latency);
  const auto replies = of(events, BoundaryPort::kCacheReply);
  ASSERT_EQ(replies.size(), 3u);
  EXPECT_EQ(replies[0].cycle, fill[0].cycle + 1 + (hit - 1));
  EXPECT_EQ(replies[1].cycle, replies[0].cycle + 1);
  EXPECT_EQ(replies[2].cycle, requests[2].cycle + hit);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(replies[i].field[2], i);
    EXPECT_EQ(replies[i].fields, 5);
    EXPECT_EQ(replies[i].field[3], fill[0].field[1]);
  }
}

}  // namespace
}  // namespace saarcor::units
