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
  EXPECT_FALSE(b.fault_mailbox_never_hits);
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
  EXPECT_EQ(m.out[1].first, left2);
  EXPECT_EQ(m.out[1].second.kind, static_cast<std::uint32_t>(units::ListOut::kPop));
  EXPECT_EQ(m.out[1].second.mask, 0x3u);
  EXPECT_EQ(m.out[1].second.next, 102u);
}

}  // namespace
}  // namespace saarcor::rtl
