// The intersection unit with its thread machinery (rtl/intersection_threads.sv) alone, with mock
// neighbours in the style of units/unit_timing_test.cpp: path e is a push in a chosen cycle, the
// packet start a side-band pulse, and the exact cycle a thread leaves is asserted as a sum of named
// latencies; its rays' closest hits are computed by hand (fp24: e7m16, bias 63).
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <type_traits>
#include <vector>

#include "Visect_proto.h"
#include "rtl/builds_testing.h"
#if SAARCOR_RTL_VARIANT_BUILDS
#include "Visect_proto_fault_strict_uv.h"
#endif
#include "rtl/port_bits.h"
#include "units/cycle_params.h"
#include "verilated.h"

namespace saarcor::rtl {
namespace {

constexpr std::uint64_t kPathLatency = 1;   // a thread pushed in cycle c is accepted in c + 1
constexpr std::uint64_t kReadyToIssue = 1;  // nothing to fetch: ready at accept, issued a cycle on
constexpr int kLanes = 4;                   // the prototype's packet (the proto build's P)

// fp24 encodings.
constexpr std::uint32_t kZero = 0, kQuarter = 0x3D0000, kHalf = 0x3E0000, kThreeQ = 0x3E8000,
                        kOne = 0x3F0000, kMinusOne = 0xBF0000, kMinusHalf = 0xBE0000,
                        kInf = 0x7F0000, kNone = 0xFFFFFFFFu;

struct Ray {
  std::uint32_t o[3], d[3];
};
struct Hit {
  std::uint32_t t, u, v, c, instance, triangle;
  friend bool operator==(const Hit&, const Hit&) = default;
};
struct Leaving {
  std::uint64_t cycle = 0;
  std::uint32_t thread = 0, dest = 0, mask = 0, done = 0;
  std::vector<Hit> hits;
};

// The unit clocked by hand: arrivals and packet starts in chosen cycles, its outputs collected.
template <class V>
class Rig {
 public:
  Rig() : ctx_(std::make_unique<VerilatedContext>()), v_(std::make_unique<V>(ctx_.get())) {
    v_->rst = 1;
    for (int i = 0; i < 2; ++i)
      clock();
    v_->rst = 0;
  }
  ~Rig() {
    v_.reset();
    ctx_.reset();
    Verilated::threadContextp(Verilated::defaultContextp());
  }
  // A packet starts on `thread` (path a's side band), in the current cycle.
  void start(std::uint32_t thread, bool shadow) {
    v_->st_valid = 1;
    put_bits(v_->st_thread, 0, 6, thread);
    v_->st_shadow = shadow;
  }
  // A triangle's rays for `thread` on path e, in the current cycle.
  void arrive(std::uint32_t thread, std::uint32_t mask, std::uint32_t list, bool last,
              const std::vector<Ray>& rays) {
    V& v = *v_;
    v.in_valid = 1;
    v.in_thread = static_cast<std::remove_reference_t<decltype(v.in_thread)>>(thread);
    v.in_mask = mask;
    v.in_list = list;
    v.in_last = last;
    v.in_instance = 7;
    v.in_triangle = 42;
    for (int i = 0; i < kLanes; ++i)
      for (int a = 0; a < 3; ++a) {
        put_bits(v.in_o, (3 * i + a) * 24, 24, rays[static_cast<std::size_t>(i)].o[a]);
        put_bits(v.in_d, (3 * i + a) * 24, 24, rays[static_cast<std::size_t>(i)].d[a]);
      }
  }
  // One cycle: the inputs set since the last one in, the leaving thread out.
  void cycle() {
    V& v = *v_;
    v.clk = 0;
    v.eval();
    if (v.out_valid) {
      Leaving& l = out.emplace_back();
      l.cycle = now;
      l.thread = v.out_thread;
      l.dest = v.out_dest;
      l.mask = v.out_mask;
      l.done = v.out_done;
      for (int i = 0; i < kLanes; ++i)
        l.hits.push_back({static_cast<std::uint32_t>(get_bits(v.out_t, i * 24, 24)),
                          static_cast<std::uint32_t>(get_bits(v.out_u, i * 24, 24)),
                          static_cast<std::uint32_t>(get_bits(v.out_v, i * 24, 24)),
                          static_cast<std::uint32_t>(get_bits(v.out_c, i * 24, 24)),
                          static_cast<std::uint32_t>(get_bits(v.out_instance, i * 32, 32)),
                          static_cast<std::uint32_t>(get_bits(v.out_triangle, i * 32, 32))});
    }
    v.clk = 1;
    v.eval();
    v.in_valid = 0;
    v.st_valid = 0;
    ++now;
  }
  void run_to(std::uint64_t c) {
    while (now < c)
      cycle();
  }

  std::uint64_t now = 0;
  std::vector<Leaving> out;

 private:
  void clock() {
    v_->clk = 0;
    v_->eval();
    v_->clk = 1;
    v_->eval();
  }
  std::unique_ptr<VerilatedContext> ctx_;
  std::unique_ptr<V> v_;
};

// Four rays with D' = (0, 0, 1): t = -O'z. Lane 0 hits at u = v = 1/4, lane 1 misses (u + v =
// 3/2), lane 2 would hit but is masked out, lane 3 hits on the edge u + v = 1.
std::vector<Ray> rays(std::uint32_t oz) {
  return {{{kQuarter, kQuarter, oz}, {kZero, kZero, kOne}},
          {{kThreeQ, kThreeQ, oz}, {kZero, kZero, kOne}},
          {{kQuarter, kQuarter, oz}, {kZero, kZero, kOne}},
          {{kHalf, kHalf, oz}, {kZero, kZero, kOne}}};
}
constexpr std::uint32_t kMask = 0b1011;
const Hit kNoHit{kInf, kZero, kZero, kZero, kNone, kNone};

TEST(IntersectionThreads, TwoThreadsLeaveAfterTheirRaysAndTheDepthWithTheirClosestHits) {
  const units::CycleParams p = units::prototype_params();
  const auto depth = static_cast<std::uint64_t>(p.intersection_depth());  // 8 + 3 + 3 + 3 + 1
  ASSERT_EQ(p.packet, kLanes);
  Rig<Visect_proto> rig;
  rig.start(3, false);
  rig.cycle();
  rig.start(5, false);
  rig.cycle();
  const std::uint64_t a = 10;
  rig.run_to(a);
  rig.arrive(3, kMask, 0xF, false, rays(kMinusOne));  // t = 1
  rig.cycle();
  rig.arrive(5, kMask, 0xF, true, rays(kMinusOne));  // the list's last triangle
  rig.run_to(a + 100);
  ASSERT_EQ(rig.out.size(), 2u);
  // Thread 3: accepted in a + 1, issued a cycle later for P cycles (one ray a cycle), leaves
  // `depth` cycles after its last ray went in.
  const std::uint64_t issue3 = a + kPathLatency + kReadyToIssue;
  EXPECT_EQ(rig.out[0].cycle, issue3 + (kLanes - 1) + depth);
  EXPECT_EQ(rig.out[0].thread, 3u);
  EXPECT_EQ(rig.out[0].dest, 0u);  // the list goes on
  EXPECT_EQ(rig.out[0].mask, 0xFu);
  EXPECT_EQ(rig.out[0].done, 0u);
  const Hit h0{kOne, kQuarter, kQuarter, kOne, 7, 42}, h3{kOne, kHalf, kHalf, kOne, 7, 42};
  EXPECT_EQ(rig.out[0].hits, (std::vector<Hit>{h0, kNoHit, kNoHit, h3}));
  // Thread 5 arrived a cycle later and waits for the issue slot: P cycles after thread 3's issue.
  EXPECT_EQ(rig.out[1].cycle, issue3 + kLanes + (kLanes - 1) + depth);
  EXPECT_EQ(rig.out[1].thread, 5u);
  EXPECT_EQ(rig.out[1].dest, 1u);  // its list is done: the traversal unit pops (D49)
}

// A closer candidate replaces the hit, a farther one does not; shadow rays that hit are done and
// leave the list; a shadow ray's t_max is 1 - 1/512, so t = 1 misses.
TEST(IntersectionThreads, ClosestHitAndAnyHit) {
  Rig<Visect_proto> rig;
  rig.start(0, false);
  rig.cycle();
  rig.start(1, true);
  rig.cycle();
  rig.arrive(0, kMask, 0xF, false, rays(kMinusOne));  // t = 1
  rig.run_to(40);
  rig.arrive(0, 0b0001, 0xF, false, rays(kMinusHalf));  // t = 1/2: closer, lane 0 only
  rig.run_to(80);
  rig.arrive(0, 0b1000, 0xF, false, rays(kMinusOne));  // t = 1 again: not closer than lane 3's
  rig.run_to(120);
  rig.arrive(1, kMask, 0xF, false, rays(kMinusOne));  // shadow, t = 1 > t_max: no hit
  rig.run_to(160);
  rig.arrive(1, kMask, 0xF, false, rays(kMinusHalf));  // shadow, t = 1/2: lanes 0 and 3 done
  rig.run_to(200);
  ASSERT_EQ(rig.out.size(), 5u);
  const Hit h3_1{kOne, kHalf, kHalf, kOne, 7, 42};
  const Hit h0_half{kHalf, kQuarter, kQuarter, kOne, 7, 42};
  const Hit h3_half{kHalf, kHalf, kHalf, kOne, 7, 42};
  EXPECT_EQ(rig.out[1].hits, (std::vector<Hit>{h0_half, kNoHit, kNoHit, h3_1}));
  EXPECT_EQ(rig.out[2].hits, (std::vector<Hit>{h0_half, kNoHit, kNoHit, h3_1}));
  const Hit shadow_miss{0x3EFF00, kZero, kZero, kZero, kNone, kNone};
  EXPECT_EQ(rig.out[3].hits,
            (std::vector<Hit>{shadow_miss, shadow_miss, shadow_miss, shadow_miss}));
  EXPECT_EQ(rig.out[3].done, 0u);
  EXPECT_EQ(rig.out[4].hits, (std::vector<Hit>{h0_half, shadow_miss, shadow_miss, h3_half}));
  EXPECT_EQ(rig.out[4].done, 0b1001u);
  EXPECT_EQ(rig.out[4].mask, 0b0110u);  // the done rays left the list
  EXPECT_EQ(rig.out[4].dest, 0u);
}

// The fault build accepts on u + v < 1: lane 3's edge hit is lost.
#if SAARCOR_RTL_VARIANT_BUILDS
TEST(IntersectionThreads, StrictUvFaultLosesTheEdgeHit) {
  Rig<Visect_proto_fault_strict_uv> rig;
  rig.start(2, false);
  rig.cycle();
  rig.arrive(2, kMask, 0xF, false, rays(kMinusOne));
  rig.run_to(60);
  ASSERT_EQ(rig.out.size(), 1u);
  EXPECT_EQ(rig.out[0].hits[0].t, kOne);
  EXPECT_EQ(rig.out[0].hits[3], kNoHit);
}
#endif

}  // namespace
}  // namespace saarcor::rtl
