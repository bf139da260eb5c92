// The traversal unit with its thread machinery (rtl/traversal_threads.sv) alone, with mock
// neighbours in the style of units/unit_timing_test.cpp: the paths are pushes in chosen cycles,
// the traversal cache answers every request after its hit latency with the image's node words,
// and the exact cycles of the unit's port events (issue, cache request, leaving) are asserted as
// sums of named latencies. The test-only fault of two input priorities swapped must be caught at
// its first wrong event.
#include <gtest/gtest.h>

#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "Vtrav_proto.h"
#include "rtl/builds_testing.h"
#if SAARCOR_RTL_VARIANT_BUILDS
#include "Vtrav_proto_fault_priority.h"
#endif
#include "host/image_builder.h"
#include "host/scene.h"
#include "rtl/traversal_ctrl_testing.h"
#include "units/cycle_params.h"

namespace saarcor::rtl::testing {
namespace {

constexpr std::uint64_t kPathLatency = 1;   // a thread pushed in cycle c is accepted in c + 1
constexpr std::uint64_t kReadyToIssue = 1;  // a thread made ready in c issues in c + 1
constexpr int kHitLatency = 2;              // cache.hit_latency: request push to response

// One port event of the unit: the cycle, the port and the thread (and the item it names).
struct Event {
  std::uint64_t cycle = 0;
  std::string port;
  std::uint32_t thread = 0;
  std::uint32_t value = 0;
  friend bool operator==(const Event&, const Event&) = default;
};
[[maybe_unused]] std::string str(const Event& e) {  // the fault test's message
  return "cycle " + std::to_string(e.cycle) + " " + e.port + " thread " + std::to_string(e.thread) +
         " value " + std::to_string(e.value);
}

// The room's image and one generated primary packet's world rays (the model's).
struct Packet {
  host::BuiltImage built;
  units::FunctionalParams fp;
  units::PipelineUnits<F> pu;
  units::FrameSink sink;
  std::unique_ptr<State> s;
  Packet() : built(host::build_image(host::load_scene("builtin:room"))) {
    fp.packet = kLanes;
    const auto& r = built.image.registers();
    sink.reset(static_cast<int>(r.width), static_cast<int>(r.height));
    s = std::make_unique<State>(built.image, fp, pu, sink);
    const std::uint32_t x = 200, y = 150, w = r.width;
    s->rgs.start_primary(*s, {y * w + x, y * w + x + 1, (y + 1) * w + x, (y + 1) * w + x + 1});
    s->transformation.generate(*s);
  }
  // Box faces of the top-level clip (3 when every origin is inside the scene box).
  int clip_faces() const { return s->traversal.clip_face() == 1 ? 3 : 6; }
};

template <class V>
class Rig {
 public:
  explicit Rig(const Packet& pk) : pk_(pk), top_(std::make_unique<V>()) {
    const auto& r = pk.built.image.registers();
    set3(top_->scene_lo, r.scene_min);
    set3(top_->scene_hi, r.scene_max);
    top_->top_root = r.top_root;
    top_->req_ready = 1;
    top_->rst = 1;
    for (int i = 0; i < 3; ++i)
      edge();
    top_->rst = 0;
    cycle_ = 0;
  }
  ~Rig() { top_->final(); }

  // Path b's payload for `thread` (the packet's world rays) and its top level's start, in one
  // cycle (load port 0).
  void load(std::uint32_t thread) {
    top_->ld_valid = 1;
    put_bits(top_->ld_thread, 0, thread_bits(kThreads), thread);
    top_->ld_bottom = 0;
    top_->ld_shadow = 0;
    std::uint64_t valid = 0, done = 0;
    for (int i = 0; i < pk_.s->p; ++i) {
      const auto& l = pk_.s->lane(i);
      for (int k = 0; k < 3; ++k) {
        const auto a = static_cast<std::size_t>(k);
        put_bits(top_->ld_o, i * 72 + k * 24, 24, l.world.o[a].bits);
        put_bits(top_->ld_d, i * 72 + k * 24, 24, l.world.d[a].bits);
      }
      put_bits(top_->ld_tbest, i * 24, 24, l.hit.t.bits);
      valid |= std::uint64_t{l.valid} << i;
      done |= std::uint64_t{l.done} << i;
    }
    put_bits(top_->ld_lane_valid, 0, pk_.s->p, valid);
    put_bits(top_->ld_done, 0, pk_.s->p, done);
    step();
  }
  std::uint64_t cycle() const { return cycle_; }
  // Pushes in the current cycle.
  void push_b(std::uint32_t t) {
    top_->b_valid = 1;
    top_->b_thread = t;
  }
  void push_f(std::uint32_t t) {
    top_->f_valid = 1;
    top_->f_thread = t;
  }
  // One cycle: the mock cache's response due now, the port events, the clock edge.
  void step() {
    if (!due_.empty() && due_.front().first == cycle_) {
      const std::uint32_t item = due_.front().second.value;
      const auto w = memif::encode_node(pk_.built.image.node(item));
      top_->resp_valid = 1;
      top_->resp_thread = due_.front().second.thread;
      top_->resp_w0 = w[0];
      top_->resp_w1 = w[1];
      due_.pop_front();
    }
    top_->clk = 0;
    top_->eval();
    if (top_->iss_valid) events.push_back({cycle_, "issue", top_->iss_thread, 0});
    if (top_->req_valid) {
      events.push_back({cycle_, "cache request", top_->req_thread, top_->req_item});
      due_.push_back({cycle_ + kHitLatency, {cycle_, "", top_->req_thread, top_->req_item}});
    }
    if (top_->out_valid)
      events.push_back({cycle_, "out dest " + std::to_string(top_->out_dest), top_->out_thread,
                        top_->out_first});
    if (top_->out2_valid)
      events.push_back(
          {cycle_, "out2 dest " + std::to_string(top_->out2_dest), top_->out2_thread, 0});
    edge();
    ++cycle_;
  }
  void run(int cycles) {
    for (int i = 0; i < cycles; ++i)
      step();
  }

  std::vector<Event> events;

 private:
  static void set3(VlWide<3>& w, const std::array<std::uint32_t, 3>& f) {
    w[0] = (f[0] & 0xFFFFFFu) | (f[1] << 24);
    w[1] = ((f[1] & 0xFFFFFFu) >> 8) | (f[2] << 16);
    w[2] = (f[2] & 0xFFFFFFu) >> 16;
  }
  void edge() {
    top_->clk = 0;
    top_->eval();
    top_->clk = 1;
    top_->eval();
    top_->ld_valid = 0;
    top_->b_valid = 0;
    top_->f_valid = 0;
    top_->l_valid = 0;
    top_->r_valid = 0;
    top_->resp_valid = 0;
  }
  const Packet& pk_;
  std::unique_ptr<V> top_;
  std::uint64_t cycle_ = 0;
  std::deque<std::pair<std::uint64_t, Event>> due_;
};

std::vector<Event> of(const std::vector<Event>& ev, const std::string& port) {
  std::vector<Event> r;
  for (const Event& e : ev)
    if (e.port == port) r.push_back(e);
  return r;
}

int depth() {
  return units::prototype_params().traversal_depth();
}

// A packet on path b: the clip faces issue back to back after the path and the ready-to-issue
// cycle; one pipeline pass after the last face the thread is back through its loop path and
// fetches the root; the node issues after the hit latency and leaves a depth later (the room's
// top level is a single leaf: for the list unit).
TEST(RtlTraversalThreads, ClipThenRootFetchAtSumsOfLatencies) {
  const Packet pk;
  Rig<Vtrav_proto> rig(pk);
  rig.load(5);
  const std::uint64_t pushed = rig.cycle();
  rig.push_b(5);
  rig.run(80);
  const int faces = pk.clip_faces();
  ASSERT_EQ(faces, 3);  // the room's camera is inside the scene box: exit faces only
  const std::uint64_t issue0 = pushed + kPathLatency + kReadyToIssue;
  const auto issues = of(rig.events, "issue");
  ASSERT_GE(issues.size(), static_cast<std::size_t>(faces + 1));
  for (int i = 0; i < faces; ++i)
    EXPECT_EQ(issues[static_cast<std::size_t>(i)].cycle, issue0 + static_cast<std::uint64_t>(i))
        << "face " << i;
  // The root's fetch: last face + depth, then the loop path.
  const auto req = of(rig.events, "cache request");
  ASSERT_GE(req.size(), 1u);
  const std::uint64_t fetch = issue0 + static_cast<std::uint64_t>(faces - 1 + depth()) +
                              kPathLatency;  // 2 + 2 + 12 + 1 after the push
  EXPECT_EQ(req[0].cycle, fetch);
  EXPECT_EQ(req[0].thread, 5u);
  EXPECT_EQ(req[0].value, pk.built.image.registers().top_root);
  // The node step: hit latency, ready-to-issue, then a depth. The room's top level is one leaf
  // (one object): the thread leaves for the list unit with the leaf's list.
  const std::uint64_t node_issue = fetch + kHitLatency + kReadyToIssue;
  EXPECT_EQ(issues[static_cast<std::size_t>(faces)].cycle, node_issue);
  const memif::KdNode root = pk.built.image.node(pk.built.image.registers().top_root);
  ASSERT_TRUE(root.leaf);
  const auto leaf = of(rig.events, "out dest 1");
  ASSERT_EQ(leaf.size(), 1u);
  EXPECT_EQ(leaf[0].cycle, node_issue + static_cast<std::uint64_t>(depth()));
  EXPECT_EQ(leaf[0].thread, 5u);
  EXPECT_EQ(leaf[0].value, root.first);
  EXPECT_EQ(req.size(), 1u);
}

// Threads on f (a pop) and b in the same cycle: f is served first (D25), one accept per cycle,
// so the pop issues one cycle before the clip and leaves for the RGS a depth later. With the
// priorities of f and b swapped the first wrong event is the first issue.
template <class V>
std::vector<Event> two_paths(const Packet& pk) {
  Rig<V> rig(pk);
  rig.load(0);
  rig.load(1);
  rig.push_b(0);
  rig.push_f(1);
  rig.run(40);
  return rig.events;
}

TEST(RtlTraversalThreads, HigherPriorityPathIsIssuedFirst) {
  const Packet pk;
  const auto ev = two_paths<Vtrav_proto>(pk);
  const auto issues = of(ev, "issue");
  ASSERT_GE(issues.size(), 2u);
  const std::uint64_t pushed = issues[0].cycle - kPathLatency - kReadyToIssue;
  EXPECT_EQ(issues[0].thread, 1u);  // f before b
  EXPECT_EQ(issues[1].thread, 0u);
  EXPECT_EQ(issues[1].cycle, issues[0].cycle + 1);
  // The pop of a thread with an empty stack and no sign group ends its top level: the RGS.
  const auto g = of(ev, "out dest 3");
  ASSERT_EQ(g.size(), 1u);
  EXPECT_EQ(g[0].thread, 1u);
  EXPECT_EQ(g[0].cycle,
            pushed + kPathLatency + kReadyToIssue + static_cast<std::uint64_t>(depth()));
}

// The SystemVerilog defaults are the cycle model's table (units/cycle_params.cpp): packet width,
// threads, stack entries, the depth from lat.add + lat.div + lat.cmp, traversal.skip_empty and
// clip.exit_only (only clip.faces_per_step = 1 is built).
TEST(RtlTraversalThreads, ParametersAreTheCycleModelsDefaults) {
  const units::CycleParams p = units::prototype_params();
  auto top = std::make_unique<Vtrav_proto>();
  top->eval();
  EXPECT_EQ(top->par_packet, p.packet);
  EXPECT_EQ(top->par_threads, p.threads);
  EXPECT_EQ(top->par_stack, p.stack);
  EXPECT_EQ(top->par_depth, p.traversal_depth());
  EXPECT_EQ(top->par_skip_empty, p.skip_empty ? 1 : 0);
  EXPECT_EQ(top->par_exit_only, p.clip_exit_only ? 1 : 0);
  EXPECT_EQ(p.clip_faces_per_step, 1);
  top->final();
}

#if SAARCOR_RTL_VARIANT_BUILDS
TEST(RtlTraversalThreadsFaults, SwappedPrioritiesAreCaughtAtTheFirstIssue) {
  const Packet pk;
  const auto good = two_paths<Vtrav_proto>(pk);
  const auto bad = two_paths<Vtrav_proto_fault_priority>(pk);
  std::size_t k = 0;
  while (k < good.size() && k < bad.size() && good[k] == bad[k])
    ++k;
  ASSERT_LT(k, good.size()) << "the swapped priorities went unnoticed";
  ASSERT_LT(k, bad.size());
  // The first event of both runs is the first issue: the same cycle, the other thread.
  EXPECT_EQ(k, 0u) << str(good[k]) << " / " << str(bad[k]);
  EXPECT_EQ(good[k].port, "issue");
  EXPECT_EQ(bad[k].port, "issue");
  EXPECT_EQ(good[k].cycle, bad[k].cycle);
  EXPECT_EQ(good[k].thread, 1u);
  EXPECT_EQ(bad[k].thread, 0u);
}
#endif

}  // namespace
}  // namespace saarcor::rtl::testing
