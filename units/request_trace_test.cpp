// The request trace's line format and tokens, and the Kanata log of hand-made records
// (units/request_trace.h, units/run_trace.h; docs/traces.md). The traces of real frames, and the
// cycle and functional models' agreement, are testbench/trace_test.cpp.
#include "units/request_trace.h"

#include <gtest/gtest.h>

#include <sstream>
#include <stdexcept>
#include <string>

#include "units/run_trace.h"

namespace saarcor::units {
namespace {

using F = ff::fp24;

TEST(RequestTraceLine, FormatsAndParsesBothModelsLines) {
  TraceLine l;
  l.cycle = 1234;
  l.dynrtp = 1;
  l.thread = 70;
  l.packet = 42;
  l.seq = 7;
  l.unit = UnitId::kTraversal;
  l.phase = Phase::kTraverse;
  l.item = 311;
  l.steps = 1;
  l.mask = 0xb;
  l.kind = RayKind::kShadow;
  l.txn = "L0=3f0000,000000,3f0000,000000,3f8000->1,0,3f0000,3f0000";
  const std::string text = format_trace_line(l);
  EXPECT_EQ(text,
            "1234 1 70 42 7 traversal traverse 311 1 0xb shadow "
            "L0=3f0000,000000,3f0000,000000,3f8000->1,0,3f0000,3f0000");
  EXPECT_EQ(parse_trace_line(text), l);
  TraceLine f;  // the functional model's: no cycle, DynRTP, thread, item, transactions
  f.packet = 3;
  f.unit = UnitId::kRgs;
  f.phase = Phase::kShadeSurface;
  f.steps = 1;
  f.mask = 0xf;
  EXPECT_EQ(format_trace_line(f), "- - - 3 0 rgs shade_surface - 1 0xf primary -");
  EXPECT_EQ(parse_trace_line(format_trace_line(f)), f);
  EXPECT_TRUE(same_request(l, [&] {
    TraceLine g = l;
    g.cycle = kNoCycle;
    g.thread = 5;
    return g;
  }()));
}

TEST(RequestTraceLine, RejectsWhatIsNotALine) {
  const auto err = [](const std::string& s) {
    try {
      parse_trace_line(s);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(err("1 2 3").rfind("trace line: expected at least 12 columns, got 3", 0), 0u);
  EXPECT_NE(err("- - - 0 0 warp traverse 1 1 0xf primary -").find("unknown name 'warp'"),
            std::string::npos);
  EXPECT_NE(err("- - - 0 0 traversal traverse 1 1 f primary -").find("bad mask f"),
            std::string::npos);
  EXPECT_NE(err("- - - x 0 traversal traverse 1 1 0xf primary -").find("bad number 'x'"),
            std::string::npos);
}

// The tokens of each unit's transactions, with lanes, flags and a matrix printed once per change.
TEST(RequestTraceTap, WritesEachUnitsTransactionsAsHexTokens) {
  TraceTap<F> tap;
  const F one = F::one(), two = F::from_double(2.0), zero{};
  tap.begin();
  tap.traversal(2, one, zero, two, zero, two, true, false, F::from_double(0.5), two);
  EXPECT_EQ(tap.take(), "L2=3f0000,000000,400000,000000,400000->1,0,3e0000,400000");
  tap.begin();
  const Mat34<F> m = {{{one, zero, zero, two}, {zero, one, zero, zero}, {zero, zero, one, zero}}};
  tap.transformation(-1, m, {one, one, one}, true, {F::from_double(3.0), one, one});
  tap.transformation(0, m, {zero, zero, one}, false, {zero, zero, one});
  EXPECT_EQ(tap.take(),
            "M=3f0000,000000,000000,400000,000000,3f0000,000000,000000,000000,000000,3f0000,"
            "000000 S.o=3f0000,3f0000,3f0000->408000,3f0000,3f0000 "
            "L0.d=000000,000000,3f0000->000000,000000,3f0000");
  tap.begin();
  Ray<F> r;
  r.o = {zero, zero, two};
  r.d = {zero, zero, F::from_double(-1.0)};
  Candidate<F> c;
  c.t = two;
  c.c = F::from_double(-1.0);
  c.inside = true;
  tap.intersection(3, r, c);
  EXPECT_EQ(tap.take(),
            "L3=000000,000000,400000,000000,000000,bf0000->400000,000000,000000,bf0000,1");
}

// Hand-made records: stages in order, empty ones left out, chained requests without a pipeline
// stage, ids by entry, retire ids by exit, cycles as C= then deltas.
TEST(KonataWriter, WritesRecordsInCycleOrder) {
  RunTracer::Record a;  // a node step: queued 10, fetch 11, hit, issued 14, depth 12
  a.unit = UnitId::kTraversal;
  a.phase = Phase::kTraverse;
  a.thread = 3;
  a.packet = 1;
  a.seq = 4;
  a.item = 9;
  a.steps = 1;
  a.mask = 0xf;
  a.queued = 10;
  a.accepted = 11;
  a.fetched = 11;
  a.ready = 13;
  a.issued = 14;
  a.done_at = 26;
  a.left = 26;
  RunTracer::Record b;  // a chained clip face: issued 12, the next face at 13
  b.unit = UnitId::kTraversal;
  b.phase = Phase::kClipTop;
  b.thread = 5;
  b.packet = 2;
  b.item = 1;
  b.steps = 1;
  b.issued = 12;
  b.left = 13;
  std::ostringstream out;
  write_konata(out, {a, b}, 64);
  EXPECT_EQ(out.str(),
            "Kanata\t0004\n"
            "C=\t10\n"
            "I\t0\t0\t3\n"
            "L\t0\t0\t1.4 traversal traverse 9\n"
            "L\t0\t1\tdynrtp 0 thread 3 packet 1 request 4 steps 1 mask 0xf primary\n"
            "S\t0\t0\tqueue\n"
            "C\t1\n"
            "E\t0\t0\tqueue\n"
            "S\t0\t0\tfetch\n"
            "C\t1\n"
            "E\t0\t0\tfetch\n"
            "S\t0\t0\twait\n"
            "I\t1\t1\t5\n"
            "L\t1\t0\t2.0 traversal clip_top 1\n"
            "L\t1\t1\tdynrtp 0 thread 5 packet 2 request 0 steps 1 mask 0x0 primary\n"
            "S\t1\t0\tissue\n"
            "C\t1\n"
            "E\t0\t0\twait\n"
            "S\t0\t0\tready\n"
            "E\t1\t0\tissue\n"
            "R\t1\t0\t0\n"
            "C\t1\n"
            "E\t0\t0\tready\n"
            "S\t0\t0\tissue\n"
            "C\t1\n"
            "E\t0\t0\tissue\n"
            "S\t0\t0\tpipe\n"
            "C\t11\n"
            "E\t0\t0\tpipe\n"
            "R\t0\t1\t0\n");
}

}  // namespace
}  // namespace saarcor::units
