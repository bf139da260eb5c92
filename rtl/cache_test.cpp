// The per-type cache's RTL (rtl/cache.sv) alone with mock neighbours (a unit that pushes
// requests, a routing that takes line requests and pushes fills), in the style of
// units/unit_timing_test.cpp: the exact cycle of each accept, line request and response as a sum
// of named latencies; and its builds' parameters against the cycle model's.
#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "memif/cache.h"
#include "rtl/cache_rtl.h"
#include "units/cycle_params.h"

namespace saarcor::rtl {
namespace {

// The builds' parameters come from rtl/CMakeLists.txt; the prototype's build must be the cycle
// model's defaults (its arrays hold the default caches: 512 items, every item type).
TEST(CacheBuilds, PrototypeBuildIsTheModelsDefaults) {
  const units::CycleParams p = units::prototype_params();
  const CacheBuild& b = cache_builds().at(0);
  EXPECT_EQ(b.name, "proto");
  for (const auto& c : p.cache) {
    EXPECT_GE(b.items, c.items);
    EXPECT_GE(b.ways, c.ways);
  }
  EXPECT_EQ(b.items, memif::CacheConfig{}.items);
  EXPECT_EQ(b.words, memif::kMaxRequestWords);
  EXPECT_EQ(b.hit_latency, p.cache_hit_latency);
  EXPECT_EQ(b.misses, p.cache_misses);
  EXPECT_EQ(b.targets, p.cache_merge_targets);
  EXPECT_EQ(b.request_queue, p.cache_request_queue);
  EXPECT_EQ(b.memory_queue, p.cache_memory_queue);
  EXPECT_EQ(b.fault, 0);
  // The same figures as memif's defaults (the cycle model's keys start from them).
  EXPECT_EQ(b.hit_latency, memif::CacheConfig{}.hit_latency);
  EXPECT_EQ(b.misses, memif::CacheConfig{}.max_misses);
  EXPECT_EQ(b.targets, memif::CacheConfig{}.max_targets);
}

// ---- the RTL alone, mock neighbours ------------------------------------------------------------
// Latencies (memif/cache.h, hw/channel.h): a request pushed in c is looked up in c + 1 (the
// request queue's latency); a line request pushed in c can be taken by the routing in c + 1; a
// fill pushed in c is written in c + 1 (the fill queue's latency) and answers its first request
// in that cycle; a response pushed in c reaches the unit in c + hit_latency - 1.
constexpr std::uint64_t kRequestQueue = 1;
constexpr std::uint64_t kFillQueue = 1;
const std::uint64_t kHit = static_cast<std::uint64_t>(memif::CacheConfig{}.hit_latency);
const std::uint64_t kResponse = kHit - 1;

struct Event {
  std::uint64_t cycle;
  CacheOutputs out;
};

struct Mock {
  explicit Mock(CacheSizes s) : sizes(s) {}
  CacheSizes sizes;
  std::unique_ptr<CacheRtl> rtl = make_cache_rtl(cache_builds().at(0));
  std::map<std::uint64_t, CacheInputs> in;  // by cycle
  std::vector<Event> accepts, responses, line_requests;
  void request(std::uint64_t c, std::uint32_t index, std::uint32_t tag) {
    in[c].req = true;
    in[c].req_index = index;
    in[c].req_requester = 2;
    in[c].req_tag = tag;
  }
  void fill(std::uint64_t c, std::uint32_t mshr, std::uint32_t w0, std::uint32_t w1) {
    in[c].fill = true;
    in[c].fill_tag = mshr;
    in[c].fill_words = {w0, w1, 0, 0};
  }
  void run(std::uint64_t cycles) {
    rtl->reset(sizes);
    for (std::uint64_t c = 0; c < cycles; ++c) {
      const CacheOutputs o = rtl->cycle(in[c]);
      if (o.accept) accepts.push_back({c, o});
      if (o.resp) responses.push_back({c, o});
      if (o.mreq) line_requests.push_back({c, o});
    }
  }
};

// A miss, a hit on the filled line and a miss merged into an outstanding one, on an 8-item
// direct-mapped cache of kd-nodes (two words) whose region starts at word 100.
TEST(CacheRtl, MissHitAndMergedMissTakeTheirNamedLatencies) {
  Mock m({8, 1, 2, 100});
  const std::uint64_t memory = 9;  // the routing's and the controller's round trip (the mock's)
  // Item 5: bank 3 + 5 mod 3 = 5, offset 100 + (5 div 3) * 2 = 102.
  const std::uint64_t miss_pushed = 2;
  m.request(miss_pushed, 5, 7);
  const std::uint64_t miss_line = miss_pushed + kRequestQueue;
  m.in[miss_line + 1].mem_take = true;
  const std::uint64_t fill1 = miss_line + 1 + memory;
  m.fill(fill1, 0, 0xA5, 0x5A);
  // The hit: item 5 again, after the fill.
  const std::uint64_t hit_pushed = 20;
  m.request(hit_pushed, 5, 9);
  // The merged miss: item 6 twice in a row; the second joins MSHR 0 (free again) of the first.
  const std::uint64_t second_miss = 30;
  m.request(second_miss, 6, 11);
  m.request(second_miss + 1, 6, 12);
  m.in[second_miss + kRequestQueue + 1].mem_take = true;
  const std::uint64_t fill2 = 45;
  m.fill(fill2, 0, 0xB6, 0x6B);
  m.run(60);

  ASSERT_EQ(m.accepts.size(), 4u);
  EXPECT_EQ(m.accepts[0].cycle, miss_pushed + kRequestQueue);
  EXPECT_EQ(m.accepts[0].out.acc_kind, 2u);  // miss
  EXPECT_EQ(m.accepts[0].out.acc_mshr, 0u);
  EXPECT_EQ(m.accepts[1].cycle, hit_pushed + kRequestQueue);
  EXPECT_EQ(m.accepts[1].out.acc_kind, 0u);  // hit
  EXPECT_EQ(m.accepts[2].cycle, second_miss + kRequestQueue);
  EXPECT_EQ(m.accepts[2].out.acc_kind, 2u);
  EXPECT_EQ(m.accepts[3].cycle, second_miss + 1 + kRequestQueue);
  EXPECT_EQ(m.accepts[3].out.acc_kind, 1u);  // merge
  EXPECT_EQ(m.accepts[3].out.acc_mshr, 0u);

  ASSERT_EQ(m.line_requests.size(), 2u);  // the merge sends none
  EXPECT_EQ(m.line_requests[0].cycle, miss_line);
  EXPECT_EQ(m.line_requests[0].out.mreq_tag, 0u);
  EXPECT_EQ(m.line_requests[0].out.mreq_bank, 5u);
  EXPECT_EQ(m.line_requests[0].out.mreq_offset, 102u);
  EXPECT_EQ(m.line_requests[0].out.mreq_words, 2u);
  // Item 6: bank 3 + 0, offset 100 + 2 * 2.
  EXPECT_EQ(m.line_requests[1].out.mreq_bank, 3u);
  EXPECT_EQ(m.line_requests[1].out.mreq_offset, 104u);

  ASSERT_EQ(m.responses.size(), 4u);
  // The miss: fill pushed, written and answered a fill-queue latency later, then the response's.
  EXPECT_EQ(m.responses[0].cycle, fill1 + kFillQueue + kResponse);
  EXPECT_EQ(m.responses[0].out.resp_tag, 7u);
  EXPECT_EQ(m.responses[0].out.resp_words[0], 0xA5u);
  EXPECT_EQ(m.responses[0].out.resp_words[1], 0x5Au);
  // The hit: hit_latency after its push, the filled line's words.
  EXPECT_EQ(m.responses[1].cycle, hit_pushed + kHit);
  EXPECT_EQ(m.responses[1].out.resp_tag, 9u);
  EXPECT_EQ(m.responses[1].out.resp_words[0], 0xA5u);
  EXPECT_EQ(m.responses[1].out.resp_requester, 2u);
  // The merged miss: both answered by one fill, one per cycle in request order.
  EXPECT_EQ(m.responses[2].cycle, fill2 + kFillQueue + kResponse);
  EXPECT_EQ(m.responses[2].out.resp_tag, 11u);
  EXPECT_EQ(m.responses[3].cycle, fill2 + kFillQueue + kResponse + 1);
  EXPECT_EQ(m.responses[3].out.resp_tag, 12u);
  EXPECT_EQ(m.responses[3].out.resp_index, 6u);
  EXPECT_EQ(m.responses[3].out.resp_words[1], 0x6Bu);
}

// A hit in the cycle a fill answers its request waits one cycle (one response per cycle, the
// delivery first); with two ways, items 1 and 5 (one set of a 4-item, 2-way cache) both stay, and
// a third item of the set evicts the least recently used one.
TEST(CacheRtl, HitWaitsForTheDeliveryAndTwoWaysKeepTheMostRecent) {
  Mock m({4, 2, 2, 0});
  m.request(0, 1, 1);  // miss, MSHR 0
  m.request(1, 5, 2);  // the same set: miss, MSHR 1
  m.in[2].mem_take = true;
  m.in[3].mem_take = true;
  m.fill(10, 0, 0x11, 0);
  m.fill(11, 1, 0x55, 0);
  m.request(14, 1, 3);  // hit (way 0 of set 1); item 5 is now the least recently used
  m.request(20, 3, 4);  // set 1 again: evicts item 5
  m.in[22].mem_take = true;
  m.fill(25, 0, 0x33, 0);
  m.request(25, 1, 5);  // still a hit: looked up in 26, the cycle the fill answers item 3
  m.request(30, 5, 6);  // a miss again
  m.run(40);
  ASSERT_EQ(m.accepts.size(), 6u);
  EXPECT_EQ(m.accepts[2].out.acc_kind, 0u);
  EXPECT_EQ(m.accepts[3].out.acc_kind, 2u);
  EXPECT_EQ(m.accepts[4].out.acc_kind, 0u);
  // The fill of item 3 is delivered in 25 + 1 = 26; the hit looked up there waits until 27.
  EXPECT_EQ(m.accepts[4].cycle, 25 + kFillQueue + 1);
  EXPECT_EQ(m.accepts[5].out.acc_kind, 2u);
  EXPECT_EQ(m.accepts[5].out.acc_index, 5u);
  ASSERT_EQ(m.responses.size(), 5u);
  EXPECT_EQ(m.responses[3].out.resp_tag, 4u);
  EXPECT_EQ(m.responses[3].cycle, 25 + kFillQueue + kResponse);
  EXPECT_EQ(m.responses[4].out.resp_tag, 5u);
  EXPECT_EQ(m.responses[4].cycle, m.accepts[4].cycle + kResponse);
  EXPECT_EQ(m.responses[4].out.resp_words[0], 0x11u);
}

}  // namespace
}  // namespace saarcor::rtl
