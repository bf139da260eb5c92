// The list unit's RTL (rtl/list_unit.sv on rtl/unit_threads.sv) alone with mock neighbours, in
// the style of units/unit_timing_test.cpp, and its builds' parameters against the cycle model's.
#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "memif/cache.h"
#include "rtl/list_rtl.h"
#include "units/boundary_list.h"
#include "units/cycle_params.h"

namespace saarcor::rtl {
namespace {

// The builds' parameters come from rtl/CMakeLists.txt; the prototype's build must be the cycle
// model's defaults (a knob the RTL ignored would show here first).
TEST(ListBuilds, PrototypeBuildIsTheModelsDefaults) {
  const units::CycleParams p = units::prototype_params();
  const ListBuild& b = list_builds().at(0);
  EXPECT_EQ(b.name, "proto");
  EXPECT_EQ(b.threads, p.threads);
  EXPECT_EQ(b.packet, p.packet);
  EXPECT_EQ(b.mailbox, p.mailbox);
  EXPECT_EQ(b.triangle_mailbox, p.triangle_mailbox);
  EXPECT_EQ(b.depth, p.list_depth());
  EXPECT_EQ(b.fault, 0);
}

// ---- the RTL alone, mock neighbours ------------------------------------------------------------
// Latencies (units/unit_timing_test.cpp): a path pushed in s is accepted in s + 1 and the entry's
// request leaves in that cycle; a cache hit is answered hit_latency cycles after its request; a
// thread made ready issues one cycle later; it leaves `depth` cycles after its issue.
constexpr std::uint64_t kPathLatency = 1;
constexpr std::uint64_t kReadyToIssue = 1;

struct Mock {
  std::unique_ptr<ListRtl> rtl = make_list_rtl(list_builds().at(0));
  std::uint64_t cycle = 0;
  std::map<std::uint64_t, ListInputs> in;  // by cycle
  std::vector<std::pair<std::uint64_t, ListOutputs>> req, out;
  void run(std::uint64_t cycles) {
    rtl->reset();
    for (; cycle < cycles; ++cycle) {
      const ListOutputs o = rtl->cycle(in[cycle]);
      if (o.req) req.emplace_back(cycle, o);
      if (o.out) out.emplace_back(cycle, o);
    }
  }
};

// A leaf's list of two entries for four rays: the first entry goes to the transformation unit
// with all four rays; the thread comes back from the intersection unit with two rays left, reads
// the same entry again (the object mailbox has it for all four: a skip), and the list is done.
TEST(ListUnitRtl, EntryLeavesAfterFetchHitIssueAndDepthThenMailboxSkipPops) {
  const std::uint64_t hit = static_cast<std::uint64_t>(memif::CacheConfig{}.hit_latency);
  const std::uint64_t depth = static_cast<std::uint64_t>(units::prototype_params().list_depth());
  Mock m;
  const std::uint32_t t = 5, entry = 0x42;
  const std::uint64_t pushed = 3;
  ListInputs& leaf = m.in[pushed];
  leaf.valid[2] = leaf.start[2] = true;  // path c from the traversal unit
  leaf.thread[2] = t;
  leaf.next[2] = 100;
  leaf.end[2] = 102;
  leaf.mask[2] = 0xF;
  const std::uint64_t request1 = pushed + kPathLatency;
  m.in[request1 + hit].resp = true;
  m.in[request1 + hit].resp_thread = t;
  m.in[request1 + hit].resp_word = entry;
  const std::uint64_t left1 = request1 + hit + kReadyToIssue + depth;
  const std::uint64_t back = 40;  // from the intersection unit: rays 0 and 1 left
  ListInputs& resume = m.in[back];
  resume.valid[1] = true;
  resume.thread[1] = t;
  resume.mask[1] = 0x3;
  const std::uint64_t request2 = back + kPathLatency;
  m.in[request2 + hit].resp = true;
  m.in[request2 + hit].resp_thread = t;
  m.in[request2 + hit].resp_word = entry;
  const std::uint64_t left2 = request2 + hit + kReadyToIssue + depth;
  m.run(80);

  ASSERT_EQ(m.req.size(), 2u);
  EXPECT_EQ(m.req[0].first, request1);
  EXPECT_EQ(m.req[0].second.req_item, 100u);
  EXPECT_EQ(m.req[0].second.req_thread, t);
  EXPECT_EQ(m.req[1].first, request2);
  EXPECT_EQ(m.req[1].second.req_item, 101u);  // the unit's own cursor, not the thread's payload
  ASSERT_EQ(m.out.size(), 2u);
  EXPECT_EQ(m.out[0].first, left1);
  EXPECT_EQ(m.out[0].second.kind, static_cast<std::uint32_t>(units::ListOut::kEntry));
  EXPECT_EQ(m.out[0].second.entry, entry);
  EXPECT_EQ(m.out[0].second.mask, 0xFu);
  EXPECT_EQ(m.out[0].second.next, 101u);
  EXPECT_EQ(m.out[0].second.list, 0xFu);  // the level's rays, on to the intersection unit
  EXPECT_FALSE(m.out[0].second.last);     // entry 101 is left
  EXPECT_EQ(m.out[1].first, left2);
  EXPECT_EQ(m.out[1].second.kind, static_cast<std::uint32_t>(units::ListOut::kPop));
  EXPECT_EQ(m.out[1].second.mask, 0x3u);
  EXPECT_EQ(m.out[1].second.next, 102u);
  EXPECT_EQ(m.out[1].second.list, 0u);  // a pop carries the list in its mask alone
  EXPECT_FALSE(m.out[1].second.last);
}

// A list of one entry: the entry leaves as the list's last (its cursor after it at the end),
// with the level's rays (0b0110) beside the rays that need it (the same two: an empty mailbox).
TEST(ListUnitRtl, EntryThatEndsItsListLeavesMarkedLast) {
  const std::uint64_t hit = static_cast<std::uint64_t>(memif::CacheConfig{}.hit_latency);
  Mock m;
  const std::uint32_t t = 2;
  ListInputs& leaf = m.in[1];
  leaf.valid[2] = leaf.start[2] = true;
  leaf.thread[2] = t;
  leaf.level[2] = true;  // a bottom-level list: the entry is a triangle
  leaf.next[2] = 30;
  leaf.end[2] = 31;
  leaf.mask[2] = 0b0110;
  m.in[1 + kPathLatency + hit].resp = true;
  m.in[1 + kPathLatency + hit].resp_thread = t;
  m.in[1 + kPathLatency + hit].resp_word = 7;
  m.run(30);
  ASSERT_EQ(m.out.size(), 1u);
  EXPECT_EQ(m.out[0].second.kind, static_cast<std::uint32_t>(units::ListOut::kEntry));
  EXPECT_EQ(m.out[0].second.level, 1u);
  EXPECT_EQ(m.out[0].second.entry, 7u);
  EXPECT_EQ(m.out[0].second.next, 31u);
  EXPECT_EQ(m.out[0].second.mask, 0b0110u);
  EXPECT_EQ(m.out[0].second.list, 0b0110u);
  EXPECT_TRUE(m.out[0].second.last);
}

// Input priority (D25; units/dynrtp.cpp: the unit's loop, then the intersection unit, then path
// c): three threads pushed in the same cycle are accepted one per cycle in that order, each
// request leaving in its accept cycle.
TEST(ListUnitRtl, ThreadsArrivingTogetherAreAcceptedInPathPriority) {
  Mock m;
  const std::uint64_t pushed = 2;
  ListInputs& in = m.in[pushed];
  for (std::size_t path = 0; path < 3; ++path) {
    in.valid[path] = in.start[path] = true;
    in.thread[path] = static_cast<std::uint32_t>(10 + path);
    in.next[path] = static_cast<std::uint32_t>(200 + 10 * path);
    in.end[path] = in.next[path] + 1;
    in.mask[path] = 0x1;
  }
  m.run(20);
  ASSERT_EQ(m.req.size(), 3u);
  for (std::size_t path = 0; path < 3; ++path) {
    EXPECT_EQ(m.req[path].first, pushed + kPathLatency + path);
    EXPECT_EQ(m.req[path].second.req_thread, 10 + path);
    EXPECT_EQ(m.req[path].second.req_item, 200 + 10 * path);
  }
}

// A full request queue (req_ready low) holds the fetch: the request leaves in the first cycle the
// cache takes it, and no other thread is accepted meanwhile.
TEST(ListUnitRtl, FullCacheQueueHoldsTheRequest) {
  Mock m;
  const std::uint64_t pushed = 2, blocked = 4;
  for (std::uint32_t k = 0; k < 2; ++k) {
    ListInputs& in = m.in[pushed + k];
    in.valid[2] = in.start[2] = true;
    in.thread[2] = k;
    in.next[2] = 50 + k;
    in.end[2] = 60;
    in.mask[2] = 0x1;
  }
  const std::uint64_t accepted = pushed + kPathLatency;
  for (std::uint64_t c = accepted; c < accepted + blocked; ++c)
    m.in[c].req_ready = false;
  m.run(20);
  ASSERT_EQ(m.req.size(), 2u);
  EXPECT_EQ(m.req[0].first, accepted + blocked);
  EXPECT_EQ(m.req[0].second.req_thread, 0u);
  EXPECT_EQ(m.req[1].first, accepted + blocked + 1);
  EXPECT_EQ(m.req[1].second.req_thread, 1u);
}

}  // namespace
}  // namespace saarcor::rtl
