// A unit added to the DynRTP by README's recipe ("Adding a DynRTP unit"), step by step, in a test:
// a pass-through that takes a thread's request and hands the packet on unchanged after a fixed
// depth. It goes into a DynRTP between the transformation unit and the RGS, with mock neighbours
// (a scripted thread table, units/unit_testing.h, over a real memory system). The test pins the
// cycle the packet leaves the unit as a sum of named latencies (those of
// units/unit_timing_test.cpp) and that the packet reaches the RGS unchanged: the thread's requests
// are those of the same run without the unit, and from the unit on each comes exactly the unit's
// latency later.
#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "hw/kernel.h"
#include "memif/image_format.h"
#include "memif/memory_system.h"
#include "units/cycle_params.h"
#include "units/dynrtp.h"
#include "units/unit_testing.h"

namespace saarcor::units {
namespace {

using testing::kDone;
using testing::ScriptedThreads;

constexpr int kP = 4;
constexpr std::uint64_t kMask = (1u << kP) - 1;
constexpr int kPathLatency = 1;   // a thread path is a channel of latency 1
constexpr int kReadyToIssue = 1;  // accepted with nothing to fetch in x, issued in x + 1

// Recipe step 1: the unit's id and the phase it serves (unit_name, phase_name and phase_unit know
// them from here on).
const AddedUnit kPass = add_unit("pass_through", {"pass"});

// Recipe step 2: its timing as a CycleUnit. It reads no scene data (no cache, nothing to fetch),
// never chains, and a request leaves it `depth` cycles after its one issue cycle.
class PassThroughUnit final : public CycleUnit {
 public:
  PassThroughUnit(hw::Kernel& k, std::string name, ThreadTable& t, int depth)
      : CycleUnit(k, std::move(name), kPass.id, t, depth, nullptr) {}

 protected:
  Fetch fetch(const Request&) const override { return {}; }
};
constexpr int kPassDepth = 3;

// Recipe step 3: its place in the DynRTP: a UnitSpec reading the transformation unit's path, and
// its own path among the RGS's inputs (last: after the RGS's own loop).
std::vector<UnitSpec> with_pass_through() {
  std::vector<UnitSpec> units = dynrtc_units();
  units.push_back({kPass.id, {UnitId::kTransformation}, [](const UnitContext& c) -> CycleUnit& {
                     return c.kernel.make<PassThroughUnit>(c.name, c.threads, kPassDepth);
                   }});
  for (UnitSpec& s : units)
    if (s.id == UnitId::kRgs) s.inputs.push_back(kPass.id);
  return units;
}

// Recipe step 4 is empty: the unit computes nothing, so it has no packet state, no semantics and
// no case in the thread program; the scripted thread table asks for it. Recipe step 5 is this
// file's tests.

// The requests the scripted thread makes (units/unit_timing_test.cpp forms them the same way).
Request generate() {
  return {UnitId::kTransformation, Phase::kGenerate, memif::kNone, kP + 1, kMask};
}
Request pass() {
  return {kPass.id, kPass.phase(0), memif::kNone, 1, kMask};
}
Request shade() {
  return {UnitId::kRgs, Phase::kShadeSurface, memif::kNone, 1, kMask};
}

// Where the units pushed the thread: the cycle and the unit it was queued for.
class Queued final : public UnitObserver {
 public:
  struct Event {
    std::uint64_t cycle;
    UnitId to;
  };
  void queued(std::uint64_t cycle, UnitId to, ThreadToken) override {
    events.push_back({cycle, to});
  }
  void accepted(std::uint64_t, UnitId, ThreadToken, int) override {}
  void fetched(std::uint64_t, ThreadToken) override {}
  void ready(std::uint64_t, ThreadToken) override {}
  void issued(std::uint64_t, UnitId, ThreadToken, const Request&, int, std::uint64_t) override {}
  void left(std::uint64_t, ThreadToken) override {}
  // The cycle the thread was pushed towards `to`.
  std::uint64_t at(UnitId to) const {
    for (const Event& e : events)
      if (e.to == to) return e.cycle;
    ADD_FAILURE() << "never queued for " << unit_name(to);
    return hw::kNever;
  }
  std::vector<Event> events;
};

// One packet on a one-thread DynRTP built from `units`, its primary script `primary`.
struct PacketRun {
  std::vector<ScriptedThreads::Issue> issues;
  Queued queued;
  std::uint64_t retired_at = 0, pass_issue_cycles = 0;
  bool pass_paths = false;  // the kernel has the paths transformation -> unit -> RGS
};

PacketRun run_packet(const std::vector<Request>& primary, const std::vector<UnitSpec>& units) {
  hw::Kernel k;
  memif::MemoryImage image(ff::kFp24, 1u << 12);
  memif::MemorySystem mi(k, image);
  CycleParams p = prototype_params();
  p.threads = 1;
  ScriptedThreads threads(k, {{}}, primary, 1);
  RayGenerationController rgc(1, 1);
  DynRtp d(k, mi, p, threads, rgc, 0, units);
  PacketRun r;
  d.observe(&r.queued);
  k.run_to_completion([&] { return d.rgs().packets_retired() == 1; }, 1000);
  EXPECT_EQ(d.rgs().packets_retired(), 1u);
  r.issues = threads.issues;
  r.retired_at = k.now();
  r.pass_paths = k.stats().contains("dynrtp0.transformation_to_pass_through.avg_occupancy") &&
                 k.stats().contains("dynrtp0.pass_through_to_rgs.avg_occupancy");
  if (k.stats().contains("dynrtp0.pass_through.issue_cycles"))
    r.pass_issue_cycles = k.stats().get_counter("dynrtp0.pass_through.issue_cycles").value;
  return r;
}

TEST(UnitTimingAddedUnit, IsNamedAndServesItsPhase) {
  EXPECT_STREQ(unit_name(kPass.id), "pass_through");
  EXPECT_STREQ(phase_name(kPass.phase(0)), "pass");
  EXPECT_EQ(phase_unit(kPass.phase(0)), kPass.id);
  EXPECT_GT(static_cast<int>(kPass.id), static_cast<int>(UnitId::kNone));
  EXPECT_THROW(add_unit("pass_through", {}), std::logic_error);  // a name is taken once
  EXPECT_THROW(add_unit("traversal", {}), std::logic_error);     // Figure 2's names are taken
}

// The packet leaves the pass-through kPassDepth cycles after its one issue cycle, which follows
// the transformation unit's output by a path and the ready-to-issue cycle.
TEST(UnitTimingAddedUnit, PassThroughLeavesAfterPathReadyIssueAndDepth) {
  const PacketRun r = run_packet({generate(), pass(), shade(), kDone}, with_pass_through());
  ASSERT_EQ(r.issues.size(), 3u);
  EXPECT_TRUE(r.pass_paths);
  const int generate_steps = kP + 1;  // shared origin: n + 1 (D31)
  const int depth = prototype_params().transformation_depth();
  // Admitted in cycle 0 (one pipeline: every cycle granted) onto path a.
  const std::uint64_t generate_issue = 0 + kPathLatency + kReadyToIssue;
  EXPECT_EQ(r.issues[0].cycle, generate_issue);
  const std::uint64_t transformation_out =
      generate_issue + static_cast<std::uint64_t>(generate_steps - 1 + depth);
  EXPECT_EQ(r.queued.at(kPass.id), transformation_out);
  const std::uint64_t pass_issue = transformation_out + kPathLatency + kReadyToIssue;
  EXPECT_EQ(r.issues[1].cycle, pass_issue);
  EXPECT_EQ(r.issues[1].request.unit, kPass.id);
  const int pass_steps = 1;
  // Pins: the packet leaves the unit (pushed towards the RGS) steps - 1 + depth after its issue.
  const std::uint64_t pass_out =
      pass_issue + static_cast<std::uint64_t>(pass_steps - 1 + kPassDepth);
  EXPECT_EQ(r.queued.at(UnitId::kRgs), pass_out);  // 2 + 4 + 9 + 1 + 1 + 0 + 3 = 20
  EXPECT_EQ(pass_out, 20u);
  EXPECT_EQ(r.issues[2].cycle, pass_out + kPathLatency + kReadyToIssue);
  EXPECT_EQ(r.pass_issue_cycles, static_cast<std::uint64_t>(pass_steps));  // its usage
}

// The packet is handed on unchanged: the thread's other requests are the run's without the unit,
// request for request, and each after the unit comes exactly the unit's latency later.
TEST(UnitTimingAddedUnit, PassThroughHandsThePacketOnUnchanged) {
  const PacketRun with = run_packet({generate(), pass(), shade(), kDone}, with_pass_through());
  const PacketRun without = run_packet({generate(), shade(), kDone}, dynrtc_units());
  ASSERT_EQ(with.issues.size(), 3u);
  ASSERT_EQ(without.issues.size(), 2u);
  const std::uint64_t latency = kPathLatency + kReadyToIssue + (1 - 1) + kPassDepth;
  const std::size_t with_index[] = {0, 2};  // the requests besides the pass-through's
  for (std::size_t i = 0; i < without.issues.size(); ++i) {
    const ScriptedThreads::Issue& a = with.issues[with_index[i]];
    const ScriptedThreads::Issue& b = without.issues[i];
    SCOPED_TRACE(phase_name(b.request.phase));
    EXPECT_EQ(a.request.unit, b.request.unit);
    EXPECT_EQ(a.request.phase, b.request.phase);
    EXPECT_EQ(a.request.item, b.request.item);
    EXPECT_EQ(a.request.steps, b.request.steps);
    EXPECT_EQ(a.request.mask, b.request.mask);
    EXPECT_EQ(a.thread, b.thread);
    EXPECT_EQ(a.cycle, b.cycle + (i == 0 ? 0 : latency));
  }
  EXPECT_EQ(with.retired_at, without.retired_at + latency);
  EXPECT_FALSE(without.pass_paths);  // Figure 2's DynRTP is unchanged by the registration
  EXPECT_EQ(without.pass_issue_cycles, 0u);
}

}  // namespace
}  // namespace saarcor::units
