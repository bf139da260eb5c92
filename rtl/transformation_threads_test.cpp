// The transformation unit with its thread machinery (rtl/transformation_threads.sv) alone, with
// mock neighbours in the style of units/unit_timing_test.cpp: paths a and d are pushes in chosen
// cycles, the row cache answers every request after its hit latency, and the exact cycles of the
// unit's port events (row requests, leaving) are asserted as sums of named latencies; the rays
// are computed by hand (fp24: e7m16, bias 63; matrices of 0, 1 and a translation).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <type_traits>
#include <vector>

#include "Vxf_proto.h"
#include "rtl/builds_testing.h"
#if SAARCOR_RTL_VARIANT_BUILDS
#include "Vxf_proto_fault_n_plus_one_off.h"
#endif
#include "rtl/port_bits.h"
#include "units/cycle_params.h"
#include "verilated.h"

namespace saarcor::rtl {
namespace {

constexpr std::uint64_t kPathLatency = 1;   // a thread pushed in cycle c is accepted in c + 1
constexpr std::uint64_t kReadyToIssue = 1;  // a thread made ready in c issues in c + 1
constexpr std::uint64_t kHitLatency = 2;    // the mock row cache: request to response
constexpr int kLanes = 4;                   // the prototype's packet (the proto build's P)
constexpr std::uint32_t kRowBase = 100;     // the frame's instance_row_base

constexpr std::uint32_t kZero = 0, kQuarter = 0x3D0000, kHalf = 0x3E0000, kOne = 0x3F0000,
                        kOneHalf = 0x3F8000, kTwo = 0x400000, kMinusOne = 0xBF0000;

using Row = std::array<std::uint32_t, 4>;    // m_r0, m_r1, m_r2, t_r
using Words = std::array<std::uint32_t, 3>;  // a row as the SRAM holds it
using Vec = std::array<std::uint32_t, 3>;
// Four fp24 fields in three words (fixedfloat/pack.h pack_row: field k at bit 24 k).
Words pack(const Row& r) {
  return {r[0] | r[1] << 24, r[1] >> 8 | r[2] << 16, r[2] >> 16 | r[3] << 8};
}
// The identity with a translation (tx, 0, 0).
std::array<Row, 3> shift_x(std::uint32_t tx) {
  return {Row{kOne, kZero, kZero, tx}, Row{kZero, kOne, kZero, kZero},
          Row{kZero, kZero, kOne, kZero}};
}

struct Leaving {
  std::uint64_t cycle = 0;
  std::uint32_t thread = 0, dest = 0, level = 0, mask = 0, root = 0;
  std::uint32_t list = 0, last = 0, instance = 0, triangle = 0, shadow = 0;
  std::vector<Vec> o, d;
  Vec lo{}, hi{};
};

template <class V>
class Rig {
 public:
  Rig() : ctx_(std::make_unique<VerilatedContext>()), v_(std::make_unique<V>(ctx_.get())) {
    v_->instance_row_base = kRowBase;
    v_->rst = 1;
    for (int i = 0; i < 2; ++i) {
      v_->clk = 0;
      v_->eval();
      v_->clk = 1;
      v_->eval();
    }
    v_->rst = 0;
  }
  ~Rig() {
    v_.reset();
    ctx_.reset();
    Verilated::threadContextp(Verilated::defaultContextp());
  }
  // Path a: a packet (shared origin `o`, per lane direction d[i]) through matrix m.
  void generate(std::uint32_t thread, bool shared, const std::array<Row, 3>& m, const Vec& o,
                const std::vector<Vec>& d, bool shadow = false) {
    V& v = *v_;
    v.a_valid = 1;
    v.a_thread = static_cast<std::remove_reference_t<decltype(v.a_thread)>>(thread);
    v.a_shadow = shadow;
    v.a_shared = shared;
    v.a_valid_lanes = 0xF;
    for (int i = 0; i < kLanes; ++i) {
      for (int k = 0; k < 12; ++k)
        put_bits(v.a_t, (12 * i + k) * 24, 24, m[static_cast<std::size_t>(k / 4)][k % 4]);
      for (int a = 0; a < 3; ++a) {
        put_bits(v.a_ro, (3 * i + a) * 24, 24, o[static_cast<std::size_t>(a)]);
        put_bits(v.a_rd, (3 * i + a) * 24, 24, d[static_cast<std::size_t>(i)][a]);
      }
    }
  }
  // Path d: an object (kind 0) or a triangle (kind 1), with the level's rays still in the list
  // and whether the entry was its last.
  void entry(std::uint32_t thread, bool triangle, std::uint32_t id, std::uint32_t mask,
             std::uint32_t list, bool last) {
    V& v = *v_;
    v.d_valid = 1;
    v.d_thread = static_cast<std::remove_reference_t<decltype(v.d_thread)>>(thread);
    v.d_kind = triangle;
    v.d_entry = id;
    v.d_mask = mask;
    v.d_list = list;
    v.d_last = last;
  }
  void cycle() {
    V& v = *v_;
    v.req_ready = 1;
    v.resp_valid = 0;
    if (!due_.empty() && due_.front().first == now) {
      const auto [item, thread] = due_.front().second;
      due_.pop_front();
      v.resp_valid = 1;
      v.resp_thread = static_cast<std::remove_reference_t<decltype(v.resp_thread)>>(thread);
      v.resp_item = item;
      const Words& w = rows[item];
      for (int k = 0; k < 3; ++k)
        put_bits(v.resp_words, 32 * k, 32, w[static_cast<std::size_t>(k)]);
    }
    v.clk = 0;
    v.eval();
    if (v.req_valid) {
      requests.emplace_back(now, v.req_item);
      due_.push_back({now + kHitLatency, {v.req_item, static_cast<std::uint32_t>(v.req_thread)}});
    }
    if (v.out_valid) collect();
    v.clk = 1;
    v.eval();
    v.a_valid = 0;
    v.d_valid = 0;
    ++now;
  }
  void run_to(std::uint64_t c) {
    while (now < c)
      cycle();
  }

  std::uint64_t now = 0;
  std::map<std::uint32_t, Words> rows;                            // the row cache's contents
  std::vector<std::pair<std::uint64_t, std::uint32_t>> requests;  // cycle, row
  std::vector<Leaving> out;

 private:
  void collect() {
    V& v = *v_;
    Leaving& l = out.emplace_back();
    l.cycle = now;
    l.thread = v.out_thread;
    l.dest = v.out_dest;
    l.level = v.out_level;
    l.mask = v.out_mask;
    l.root = v.out_root;
    l.list = v.out_list;
    l.last = v.out_last;
    l.instance = v.out_instance;
    l.triangle = v.out_triangle;
    l.shadow = v.out_shadow;
    const auto field = [](const auto& port, int k) {
      return static_cast<std::uint32_t>(get_bits(port, k * 24, 24));
    };
    for (int i = 0; i < kLanes; ++i) {
      l.o.push_back({field(v.out_o, 3 * i), field(v.out_o, 3 * i + 1), field(v.out_o, 3 * i + 2)});
      l.d.push_back({field(v.out_d, 3 * i), field(v.out_d, 3 * i + 1), field(v.out_d, 3 * i + 2)});
    }
    l.lo = {field(v.out_lo, 0), field(v.out_lo, 1), field(v.out_lo, 2)};
    l.hi = {field(v.out_hi, 0), field(v.out_hi, 1), field(v.out_hi, 2)};
  }
  std::unique_ptr<VerilatedContext> ctx_;
  std::unique_ptr<V> v_;
  std::deque<std::pair<std::uint64_t, std::pair<std::uint32_t, std::uint32_t>>> due_;
};

const std::vector<Vec> kDirs = {
    {kOne, kZero, kZero}, {kZero, kOne, kZero}, {kZero, kZero, kOne}, {kHalf, kHalf, kZero}};
const Vec kOrigin = {kHalf, kQuarter, kOne};

// Instance 2: rows 112-117 (matrix: a shift by -1 in x; header: root 77, triangle rows at 500;
// box (0, 0, 0) .. (2, 1, 1)); triangle 4: rows 512-514 (a shift by +1 in x).
template <class V>
void load_instance_and_triangle(Rig<V>& rig) {
  const auto inst = shift_x(kMinusOne);
  for (std::uint32_t r = 0; r < 3; ++r)
    rig.rows[kRowBase + 12 + r] = pack(inst[r]);
  rig.rows[kRowBase + 15] = {77, 500, 0};  // the header: raw words (root, triangle_row_base)
  rig.rows[kRowBase + 16] = pack({kZero, kZero, kZero, 0});
  rig.rows[kRowBase + 17] = pack({kTwo, kOne, kOne, 0});
  const auto tri = shift_x(kOne);
  for (std::uint32_t r = 0; r < 3; ++r)
    rig.rows[512 + r] = pack(tri[r]);
}

// Ray generation, an object and a triangle of one thread: steps, fetches and rays.
TEST(TransformationThreads, GenerationObjectAndTriangleInTheCyclesOfTheRules) {
  const units::CycleParams p = units::prototype_params();
  const auto depth = static_cast<std::uint64_t>(p.transformation_depth());  // mul + add + add
  ASSERT_EQ(p.packet, kLanes);
  Rig<Vxf_proto> rig;
  load_instance_and_triangle(rig);

  rig.run_to(5);
  rig.generate(9, true, shift_x(kOne), kOrigin, kDirs);
  rig.run_to(100);
  ASSERT_EQ(rig.out.size(), 1u);
  // Accepted in 6, nothing to fetch: issued in 7 for n + 1 = 5 steps, out `depth` after the last.
  const std::uint64_t gen_issue = 5 + kPathLatency + kReadyToIssue;
  EXPECT_EQ(rig.out[0].cycle, gen_issue + kLanes + depth);
  EXPECT_EQ(rig.out[0].dest, 0u);  // a primary packet: the traversal unit's top level
  const Vec world_o = {kOneHalf, kQuarter, kOne};  // (1/2 + 1, 1/4, 1)
  for (int i = 0; i < kLanes; ++i) {
    EXPECT_EQ(rig.out[0].o[static_cast<std::size_t>(i)], world_o) << i;
    EXPECT_EQ(rig.out[0].d[static_cast<std::size_t>(i)], kDirs[static_cast<std::size_t>(i)]) << i;
  }

  const std::uint64_t c = 120;
  rig.run_to(c);
  rig.entry(9, false, 2, 0b0101, 0b0111, false);  // instance 2 for lanes 0 and 2
  rig.run_to(200);
  // Six rows, one a cycle from the accept on; ready with the last response, issued a cycle on.
  ASSERT_EQ(rig.requests.size(), 6u);
  for (std::uint64_t k = 0; k < 6; ++k) {
    EXPECT_EQ(rig.requests[k].first, c + kPathLatency + k);
    EXPECT_EQ(rig.requests[k].second, kRowBase + 12 + k);
  }
  const std::uint64_t obj_issue = c + kPathLatency + 5 + kHitLatency + kReadyToIssue;
  ASSERT_EQ(rig.out.size(), 2u);
  EXPECT_EQ(rig.out[1].cycle, obj_issue + kLanes + depth);
  EXPECT_EQ(rig.out[1].dest, 0u);
  EXPECT_EQ(rig.out[1].level, 1u);  // the object's bottom level starts
  EXPECT_EQ(rig.out[1].root, 77u);
  EXPECT_EQ(rig.out[1].mask, 0b0101u);
  EXPECT_EQ(rig.out[1].lo, (Vec{kZero, kZero, kZero}));
  EXPECT_EQ(rig.out[1].hi, (Vec{kTwo, kOne, kOne}));
  const Vec object_o = {kHalf, kQuarter, kOne};  // the shared origin, every lane: 3/2 - 1
  for (int i = 0; i < kLanes; ++i) {
    EXPECT_EQ(rig.out[1].o[static_cast<std::size_t>(i)], object_o) << i;
    EXPECT_EQ(rig.out[1].d[static_cast<std::size_t>(i)], kDirs[static_cast<std::size_t>(i)]) << i;
  }

  rig.run_to(220);
  // Triangle 4 (rows 500 + 3 * 4) for lane 0, the bottom-level list's last, rays 0 and 1 in it.
  rig.entry(9, true, 4, 0b0001, 0b0011, true);
  rig.run_to(300);
  ASSERT_EQ(rig.requests.size(), 9u);
  EXPECT_EQ(rig.requests[6].second, 512u);
  ASSERT_EQ(rig.out.size(), 3u);
  EXPECT_EQ(rig.out[2].cycle,
            220 + kPathLatency + 2 + kHitLatency + kReadyToIssue + kLanes + depth);
  EXPECT_EQ(rig.out[2].dest, 1u);  // the intersection unit
  EXPECT_EQ(rig.out[2].o[0], world_o);
  EXPECT_EQ(rig.out[2].d[0], kDirs[0]);
  EXPECT_EQ(rig.out[2].d[1], (Vec{kZero, kZero, kZero}));  // lane 1 never entered a triangle
}

// What leaves beside the rays, for a shadow packet (path a's flag 1): a triangle (dest 1) takes
// to the intersection unit its input fields, path d's list and last, the object the thread
// entered (instance 2, though the triangle's id replaced the entry since) and the triangle, and
// no shadow flag (that unit has it from path a's side band); a level start (generation to the
// RGS, which decides to trace the shadow rays; the object to the traversal unit) the flag alone.
TEST(TransformationThreads, TriangleCarriesTheIntersectionFieldsALevelStartTheShadowFlag) {
  Rig<Vxf_proto> rig;
  load_instance_and_triangle(rig);
  rig.run_to(5);
  rig.generate(3, true, shift_x(kOne), kOrigin, kDirs, true);
  rig.run_to(60);
  rig.entry(3, false, 2, 0b1111, 0b1111, true);  // the top-level list's last entry
  rig.run_to(140);
  rig.entry(3, true, 4, 0b0010, 0b0110, true);  // rays 1 and 2 in the bottom list, its last
  rig.run_to(220);
  ASSERT_EQ(rig.out.size(), 3u);
  EXPECT_EQ(rig.out[0].dest, 2u);  // the RGS
  EXPECT_EQ(rig.out[1].dest, 0u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(rig.out[k].shadow, 1u) << k;
    EXPECT_EQ(rig.out[k].list, 0u) << k;
    EXPECT_EQ(rig.out[k].last, 0u) << k;  // the object's last flag stays behind
    EXPECT_EQ(rig.out[k].instance, 0u) << k;
    EXPECT_EQ(rig.out[k].triangle, 0u) << k;
  }
  EXPECT_EQ(rig.out[2].dest, 1u);
  EXPECT_EQ(rig.out[2].shadow, 0u);
  EXPECT_EQ(rig.out[2].list, 0b0110u);
  EXPECT_EQ(rig.out[2].last, 1u);
  EXPECT_EQ(rig.out[2].instance, 2u);
  EXPECT_EQ(rig.out[2].triangle, 4u);
}

// Without a shared origin a packet takes 2n steps, as does every packet of the fault build.
TEST(TransformationThreads, TwoNStepsWithoutASharedOriginOrWithTheFault) {
  const auto depth = static_cast<std::uint64_t>(units::prototype_params().transformation_depth());
  const std::uint64_t issue = 5 + kPathLatency + kReadyToIssue;
  Rig<Vxf_proto> separate;
  separate.run_to(5);
  separate.generate(1, false, shift_x(kOne), kOrigin, kDirs);
  separate.run_to(60);
  ASSERT_EQ(separate.out.size(), 1u);
  EXPECT_EQ(separate.out[0].cycle, issue + 2 * kLanes - 1 + depth);
  EXPECT_EQ(separate.out[0].o[3], (Vec{kOneHalf, kQuarter, kOne}));
#if SAARCOR_RTL_VARIANT_BUILDS
  Rig<Vxf_proto_fault_n_plus_one_off> faulty;
  faulty.run_to(5);
  faulty.generate(1, true, shift_x(kOne), kOrigin, kDirs);
  faulty.run_to(60);
  ASSERT_EQ(faulty.out.size(), 1u);
  EXPECT_EQ(faulty.out[0].cycle, issue + 2 * kLanes - 1 + depth);
#endif
}

}  // namespace
}  // namespace saarcor::rtl
