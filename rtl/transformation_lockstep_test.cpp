// The transformation unit (rtl/transformation_threads.sv) in lockstep with the cycle model: the
// injected fault "the n + 1 rule off" (FAULT_N_PLUS_ONE_OFF: 2n steps for a packet whose rays
// share an origin) is caught at its first wrong event, which the test finds in the healthy run's
// events: the first thread leaving the unit (every primary packet shares its origin, D31), which
// the faulty RTL lets go n - 1 cycles later. And "a row fetched out of order"
// (FAULT_ROW_ORDER: an entry's second row requested third and its third second), caught at the
// healthy run's second row request: the first entry's second row, whose address the faulty RTL
// sends one row later. And the hand-overs a whole-DynRTC top wires directly: what the list and
// transformation units send is what the next unit's input takes.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "rtl/builds_testing.h"
#include "rtl/lockstep.h"
#include "units/boundary_intersection.h"
#include "units/boundary_list.h"
#include "units/boundary_transformation.h"
#include "units/boundary_traversal.h"
#include "units/cycle_params.h"

namespace saarcor::rtl {
namespace {

using units::BoundaryEvent;
using units::BoundaryPort;

// The transformation unit alone on the room at 24x18.
LockstepOptions room_transformation() {
  LockstepOptions o;
  o.units = {"transformation"};
  o.scene = "builtin:room";
  o.width = 24;
  o.height = 18;
  return o;
}

TEST(TransformationLockstep, NPlusOneOffIsCaughtAtTheFirstSharedOriginPacket) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  LockstepOptions o = room_transformation();
  std::uint64_t first = 0;
  bool shared = false;
  o.model_events = [&](const BoundaryEvent& e) {
    if (e.unit != units::UnitId::kTransformation || e.port != BoundaryPort::kOutput) return;
    if (first != 0) return;
    first = e.cycle;
    shared = e.field[2] != 0;
  };
  const LockstepResult healthy = run_lockstep(o);
  ASSERT_FALSE(healthy.diverged) << healthy.screen;
  ASSERT_NE(first, 0u);
  ASSERT_TRUE(shared) << "the room's first packet does not share its origin";

  o.model_events = nullptr;
  o.fault = "n-plus-one-off";
  const LockstepResult r = run_lockstep(o);
  ASSERT_TRUE(r.diverged);
  EXPECT_EQ(r.divergence.cycle, first) << r.screen;
  EXPECT_EQ(r.divergence.unit, "transformation");
  EXPECT_EQ(r.divergence.port, "output");
  EXPECT_EQ(r.divergence.kind, "timing");
  const int n = units::prototype_params().packet;
  EXPECT_EQ(r.divergence.other_cycle, first + static_cast<std::uint64_t>(2 * n - (n + 1)));
}

TEST(TransformationLockstep, RowOutOfOrderIsCaughtAtTheFirstEntrysSecondRow) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  LockstepOptions o = room_transformation();
  int requests = 0;
  std::uint64_t second = 0, address = 0;
  o.model_events = [&](const BoundaryEvent& e) {
    if (e.unit != units::UnitId::kTransformation || e.cache) return;
    if (e.port != BoundaryPort::kCacheRequest || ++requests != 2) return;
    second = e.cycle;
    address = e.field[0];
  };
  const LockstepResult healthy = run_lockstep(o);
  ASSERT_FALSE(healthy.diverged) << healthy.screen;
  ASSERT_NE(second, 0u);

  o.model_events = nullptr;
  o.fault = "row-out-of-order";
  const LockstepResult r = run_lockstep(o);
  ASSERT_TRUE(r.diverged);
  EXPECT_EQ(r.divergence.cycle, second) << r.screen;
  EXPECT_EQ(r.divergence.unit, "transformation");
  EXPECT_EQ(r.divergence.port, "cache_request");
  EXPECT_EQ(r.divergence.kind, "payload");
  EXPECT_EQ(r.divergence.field, "address");
  EXPECT_EQ(r.divergence.model_value, address);
  EXPECT_EQ(r.divergence.rtl_value, address + 1);
}

// The hand-overs of the model's record, per thread in order: an output and the input it becomes.
struct HandOvers {
  // Per hand-over (0 list -> transformation, path d; 1 transformation -> intersection, path e;
  // 2 transformation -> traversal, path b) and thread: the sender's outputs, the receiver's inputs.
  std::array<std::map<std::uint32_t, std::vector<BoundaryEvent>>, 3> out, in;
  void record(const BoundaryEvent& e) {
    using units::UnitId;
    if (e.cache) return;
    const bool output = e.port == BoundaryPort::kOutput, input = e.port == BoundaryPort::kInput;
    if (output && e.unit == UnitId::kList && e.path == UnitId::kTransformation)
      out[0][e.thread].push_back(e);
    if (input && e.unit == UnitId::kTransformation && e.path == UnitId::kList)
      in[0][e.thread].push_back(e);
    if (output && e.unit == UnitId::kTransformation && e.path == UnitId::kIntersection)
      out[1][e.thread].push_back(e);
    if (input && e.unit == UnitId::kIntersection) in[1][e.thread].push_back(e);
    if (output && e.unit == UnitId::kTransformation && e.path == UnitId::kTraversal)
      out[2][e.thread].push_back(e);
    if (input && e.unit == UnitId::kTraversal && e.path == UnitId::kTransformation)
      in[2][e.thread].push_back(e);
  }
  // Hand-over k's pairs: field `from` of each output against field `to` of its input.
  int expect_equal(std::size_t k, const std::vector<std::pair<int, int>>& fields) const {
    int pairs = 0;
    for (const auto& [thread, outs] : out[k]) {
      const std::vector<BoundaryEvent>& ins = in[k].at(thread);
      EXPECT_EQ(outs.size(), ins.size()) << "hand-over " << k << ", thread " << thread;
      for (std::size_t i = 0; i < outs.size() && i < ins.size(); ++i, ++pairs)
        for (const auto& [from, to] : fields)
          EXPECT_EQ(outs[i].field[static_cast<std::size_t>(from)],
                    ins[i].field[static_cast<std::size_t>(to)])
              << "hand-over " << k << ", thread " << thread << ", " << outs[i].names[from] << " / "
              << ins[i].names[to] << ", cycle " << outs[i].cycle;
    }
    return pairs;
  }
};

// A whole-DynRTC top wires the units' ports to each other, so each output must carry the next
// unit's input of the same thread: the list unit's entry (entry, mask, list, last) is the
// transformation unit's path d input; a triangle's output (mask, list, last, instance, triangle;
// the rays) the intersection unit's path e input; a level start (level, shadow) the traversal
// unit's. The room with shadow and secondary rays, so shadow packets enter objects too.
TEST(TransformationLockstep, OutputsAreTheNextUnitsInputs) {
  LockstepOptions o = room_transformation();
  o.units = {"traversal", "list", "transformation", "intersection"};
  o.shadows = true;
  o.depth = 2;
  HandOvers h;
  o.model_events = [&](const BoundaryEvent& e) { h.record(e); };
  const LockstepResult r = run_lockstep(o);
  ASSERT_FALSE(r.diverged) << r.screen;
  // list: entry 3, mask 4, list 5, last 6; transformation path d: entry 2, mask 3, list 4, last 5.
  EXPECT_GT(h.expect_equal(0, {{3, 2}, {4, 3}, {5, 4}, {6, 5}}), 0);
  // transformation: mask 3, list 5, last 6, instance 7, triangle 8; intersection: 0 .. 4.
  EXPECT_GT(h.expect_equal(1, {{3, 0}, {5, 1}, {6, 2}, {7, 3}, {8, 4}}), 0);
  // transformation: level 1, shadow 9; the traversal unit's level start: level 1, shadow 2.
  EXPECT_GT(h.expect_equal(2, {{1, 1}, {9, 2}}), 0);
  for (const auto& [thread, outs] : h.out[1])
    for (std::size_t i = 0; i < outs.size(); ++i)
      EXPECT_EQ(outs[i].wide, h.in[1].at(thread).at(i).wide) << "thread " << thread;
  int lasts = 0, shadows = 0;
  for (const auto& [thread, outs] : h.out[1])
    for (const BoundaryEvent& e : outs)
      lasts += e.field[6] != 0;
  for (const auto& [thread, outs] : h.out[2])
    for (const BoundaryEvent& e : outs)
      shadows += e.field[9] != 0;
  EXPECT_GT(lasts, 0);    // some triangle ended its list
  EXPECT_GT(shadows, 0);  // some shadow packet entered an object
}

}  // namespace
}  // namespace saarcor::rtl
