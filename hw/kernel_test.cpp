// Kernel semantics (docs/hw.md): evaluation-order independence, idle skipping that
// changes no figure, the watchdog and its report, cycle limits, time series.
#include "hw/kernel.h"

#include <gtest/gtest.h>

#include <sstream>

#include "hw/test_designs.h"

namespace saarcor::hw {
namespace {

using testing::DesignA;
using testing::DesignB;

struct Outcome {
  std::uint64_t cycles;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> log;
  std::string stats;
};

Outcome run_design_a(std::uint64_t seed, bool skip) {
  Kernel k({.idle_skip = skip, .watchdog_cycles = 1000, .shuffle_seed = seed});
  DesignA d(k);
  const std::uint64_t cycles = k.run_to_completion([&] { return d.done(); }, 100000);
  return {cycles, d.sink.log, k.stats().json()};
}

TEST(Kernel, RandomEvaluationOrdersGiveIdenticalCyclesOutputsAndStatistics) {
  const Outcome ref = run_design_a(0, false);
  ASSERT_EQ(ref.log.size(), 200u);
  // The first outputs, worked out by hand: the source's first value 1 (count 0) leaves at cycle
  // 1 (cycle 0 is a bubble: 0*7+0 = 0 mod 5), reaches the doubler at 3, which adds the source's
  // committed count (2 by then): 1*2+2 = 4, xor 0x5A5A in the joiner.
  EXPECT_EQ(ref.log.front().second, 4u ^ 0x5A5Au);
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const Outcome o = run_design_a(seed, seed % 2 == 0);
    EXPECT_EQ(o.cycles, ref.cycles) << "seed " << seed;
    EXPECT_EQ(o.log, ref.log) << "seed " << seed;
    EXPECT_EQ(o.stats, ref.stats) << "seed " << seed;
  }
}

// The negative control: two modules that communicate through a plain variable instead of a
// register do see different results in different orders, so the test above can fail.
TEST(Kernel, ShuffleReallyChangesTheOrderAnUnregisteredWireWouldExposeIt) {
  auto run = [](std::uint64_t seed) {
    Kernel k({.shuffle_seed = seed});
    int wire = 0;
    std::vector<int> seen;
    class Writer : public Module {
     public:
      Writer(Kernel& k, int& w) : Module(k, "writer"), w_(w) {}
      int evaluate() override { return ++w_, 1; }
      int& w_;
    } writer(k, wire);
    class Reader : public Module {
     public:
      Reader(Kernel& k, int& w, std::vector<int>& s) : Module(k, "reader"), w_(w), s_(s) {}
      int evaluate() override { return s_.push_back(w_), 1; }
      int& w_;
      std::vector<int>& s_;
    } reader(k, wire, seen);
    for (int c = 0; c < 64; ++c)
      k.step();
    return seen;
  };
  EXPECT_NE(run(1), run(2));
}

TEST(Kernel, IdleSkipGivesTheSameStatisticsTimeSeriesAndOutputsAsSteppingEveryCycle) {
  auto run = [](bool skip, std::uint64_t seed, Kernel** out_kernel = nullptr) {
    (void)out_kernel;
    Kernel k({.idle_skip = skip,
              .watchdog_cycles = 5000,
              .shuffle_seed = seed,
              .time_series_period = 250});
    DesignB d(k);
    std::ostringstream vcd;
    k.trace_vcd(vcd, 100, 2000);
    const std::uint64_t cycles = k.run_to_completion([&] { return d.done(); }, 1000000);
    k.finish_trace();
    struct R {
      std::uint64_t cycles, skipped, evaluated;
      std::string stats, series, vcd;
      std::vector<std::pair<std::uint64_t, std::uint32_t>> log;
    };
    return R{cycles,           k.skipped_cycles(),           k.evaluated_cycles(),
             k.stats().json(), k.stats().time_series_json(), vcd.str(),
             d.sink.log};
  };
  const auto step = run(false, 0);
  const auto skip = run(true, 0);
  const auto skip_shuffled = run(true, 9);
  EXPECT_EQ(step.skipped, 0u);
  EXPECT_EQ(step.evaluated, step.cycles);
  EXPECT_GT(skip.skipped, step.cycles / 2) << "the bursty design should be mostly idle";
  EXPECT_EQ(skip.skipped + skip.evaluated, skip.cycles);
  for (const auto* r : {&skip, &skip_shuffled}) {
    EXPECT_EQ(r->cycles, step.cycles);
    EXPECT_EQ(r->log, step.log);
    EXPECT_EQ(r->stats, step.stats);
    EXPECT_EQ(r->series, step.series);
    EXPECT_EQ(r->vcd, step.vcd);
  }
  // Exact timing of the first item: pushed at 10, request latency 50 -> memory takes it at 60,
  // answers at 97, response latency 20 -> sink at 117.
  ASSERT_FALSE(step.log.empty());
  EXPECT_EQ(step.log.front(), (std::pair<std::uint64_t, std::uint32_t>{117, 1000}));
  // The per-cycle counter kept through skipped(): 30 requests, each in service for the 37 cycles
  // after the one that accepted it.
  EXPECT_NE(step.stats.find("\"b.memory.wait_cycles\": {\"kind\": \"counter\", \"unit\": "
                            "\"cycles\", \"desc\": \"cycles with a request in service (counted "
                            "per cycle)\", \"value\": 1110}"),
            std::string::npos)
      << step.stats;
}

// Event scheduling (Module::sleep_when_idle): modules that sleep between events give the same
// cycles, outputs, statistics, time series and VCD as evaluating every module every cycle, with
// fewer evaluations.
TEST(Kernel, SleepingModulesGiveTheSameFiguresAsSteppingEveryCycle) {
  struct R {
    std::uint64_t cycles, evaluations;
    std::vector<std::pair<std::uint64_t, std::uint32_t>> log;
    std::string stats, series, vcd;
  };
  auto run_a = [](bool sleep, bool skip, std::uint64_t seed) {
    Kernel k({.idle_skip = skip,
              .watchdog_cycles = 1000,
              .shuffle_seed = seed,
              .time_series_period = 37});
    DesignA d(k, 300, sleep);
    std::ostringstream vcd;
    k.trace_vcd(vcd, 50, 400);
    const std::uint64_t cycles = k.run_to_completion([&] { return d.done(); }, 100000);
    k.finish_trace();
    return R{cycles,           k.module_evaluations(),       d.sink.log,
             k.stats().json(), k.stats().time_series_json(), vcd.str()};
  };
  auto run_b = [](bool sleep, bool skip, std::uint64_t seed) {
    Kernel k({.idle_skip = skip,
              .watchdog_cycles = 5000,
              .shuffle_seed = seed,
              .time_series_period = 250});
    DesignB d(k, 5, sleep);
    std::ostringstream vcd;
    k.trace_vcd(vcd, 100, 2000);
    const std::uint64_t cycles = k.run_to_completion([&] { return d.done(); }, 1000000);
    k.finish_trace();
    return R{cycles,           k.module_evaluations(),       d.sink.log,
             k.stats().json(), k.stats().time_series_json(), vcd.str()};
  };
  for (auto run : {+run_a, +run_b}) {
    const R ref = run(false, false, 0);
    const R sleep = run(true, true, 0);
    const R sleep_shuffled = run(true, true, 5);
    const R sleep_no_skip = run(true, false, 0);  // idle_skip off: sleepers evaluated too
    ASSERT_FALSE(ref.log.empty());
    for (const R* r : {&sleep, &sleep_shuffled, &sleep_no_skip}) {
      EXPECT_EQ(r->cycles, ref.cycles);
      EXPECT_EQ(r->log, ref.log);
      EXPECT_EQ(r->stats, ref.stats);
      EXPECT_EQ(r->series, ref.series);
      EXPECT_EQ(r->vcd, ref.vcd);
    }
    EXPECT_EQ(sleep_no_skip.evaluations, ref.evaluations);
    EXPECT_LT(sleep.evaluations, run(false, true, 0).evaluations) << "sleepers skip evaluations";
  }
}

// A sleeper's channel ends are declared once: a second module claiming the same end is a model
// bug.
TEST(Kernel, AChannelEndHasOneModule) {
  Kernel k;
  Channel<int> c(k, "c", 2);
  struct M : Module {
    M(Kernel& k, std::string n, Channel<int>& c, bool consume) : Module(k, std::move(n)) {
      if (consume)
        consumes(c);
      else
        produces(c);
    }
    int evaluate() override { return 0; }
  };
  M a(k, "a", c, true), b(k, "b", c, false);
  EXPECT_EQ(c.consumer(), &a);
  EXPECT_EQ(c.producer(), &b);
  EXPECT_THROW(M(k, "x", c, true), std::logic_error);
  EXPECT_THROW(M(k, "y", c, false), std::logic_error);
}

TEST(Kernel, WatchdogStopsADeadlockAtTheSameCycleWithAndWithoutSkipAndReportsEveryone) {
  for (bool skip : {false, true}) {
    Kernel k({.idle_skip = skip, .watchdog_cycles = 1000});
    Channel<int> ab(k, "ring.ab", 2, 1), ba(k, "ring.ba", 2, 1);
    // Each waits for a token from the other before it sends; a sends 2 first and then waits for
    // 3 tokens, which never come.
    class Node : public Module {
     public:
      Node(Kernel& k, std::string n, Channel<int>& in, Channel<int>& out, int tokens)
          : Module(k, std::move(n)), in_(in), out_(out), tokens_(tokens) {}
      int evaluate() override {
        if (tokens_.get() > 0 && out_.can_push()) {
          out_.push(1);
          tokens_.set(tokens_.get() - 1);
          return 1;
        }
        if (received_.get() < 3 && in_.can_pop()) {
          in_.pop();
          received_.set(received_.get() + 1);
          return 1;
        }
        return 0;
      }
      void commit() override {
        tokens_.commit();
        received_.commit();
      }
      std::uint64_t next_wakeup(std::uint64_t) const override { return kNever; }
      std::string dump_state() const override {
        return "waiting for token " + std::to_string(received_.get() + 1) + " of 3";
      }
      Channel<int>&in_, &out_;
      Reg<int> tokens_, received_{0};
    };
    Node a(k, "ring.a", ba, ab, 2), b(k, "ring.b", ab, ba, 0);
    const RunResult r = k.run([] { return false; });
    EXPECT_EQ(r.status, RunResult::Status::kWatchdog);
    // Last progress: b pops a's second token at cycle 2; the watchdog counts from cycle 3.
    EXPECT_EQ(r.cycles, 3u + 1000u) << "skip " << skip;
    EXPECT_NE(r.report.find("module ring.a: waiting for token 1 of 3"), std::string::npos)
        << r.report;
    EXPECT_NE(r.report.find("module ring.b: waiting for token 3 of 3"), std::string::npos);
    EXPECT_NE(r.report.find("channel ring.ab: 0/2"), std::string::npos);
    EXPECT_THROW(k.run_to_completion([] { return false; }), std::runtime_error);
  }
}

TEST(Kernel, ADeadlockWithoutWatchdogOrLimitStopsInsteadOfHanging) {
  Kernel k({.idle_skip = true, .watchdog_cycles = 0});
  DesignB d(k, 0);  // no bursts: nothing will ever happen
  const RunResult r = k.run([] { return false; });
  EXPECT_EQ(r.status, RunResult::Status::kWatchdog);
  EXPECT_EQ(r.cycles, 1u);
  EXPECT_NE(r.report.find("nothing can change"), std::string::npos);
}

TEST(Kernel, CycleLimitStopsARunThatStillProgresses) {
  Kernel k;
  DesignA d(k, 100000);
  const RunResult r = k.run([&] { return d.done(); }, 500);
  EXPECT_EQ(r.status, RunResult::Status::kCycleLimit);
  EXPECT_EQ(r.cycles, 500u);
  EXPECT_THROW(k.run_to_completion([&] { return d.done(); }, 10), std::runtime_error);
}

TEST(Kernel, BusyAndStallCyclesAreCountedPerModule) {
  Kernel k({.idle_skip = false});
  DesignA d(k, 50);
  const std::uint64_t cycles = k.run_to_completion([&] { return d.done(); }, 10000);
  const Stats& s = k.stats();
  EXPECT_EQ(s.value("a.sink.busy_cycles"), 50.0);
  EXPECT_EQ(s.value("a.source.busy_cycles"), 50.0);
  EXPECT_GT(s.value("a.source.stall_cycles"), 0.0);
  EXPECT_EQ(s.value("a.ch_e.pushes"), 50.0);
  EXPECT_LE(s.value("a.ch_e.max_occupancy"), 4.0);
  EXPECT_GT(s.value("a.ch_e.avg_occupancy"), 0.0);
  EXPECT_LT(s.value("a.ch_e.avg_occupancy"), 4.0);
  EXPECT_LT(s.value("a.sink.busy_cycles") + s.value("a.sink.stall_cycles"),
            static_cast<double>(cycles) + 1);
}

TEST(Kernel, OwnsModulesAndChannelsMadeThroughIt) {
  Kernel k;
  auto& a = k.make_channel<std::uint32_t>("a.ch_a", 3, 2);
  auto& b = k.make_channel<std::uint32_t>("a.ch_b", 2, 1);
  auto& src = k.make<testing::Source>(a, 10u);
  auto& dbl = k.make<testing::Doubler>(a, b, src);
  std::vector<std::uint32_t> got;
  class Collect : public Module {
   public:
    Collect(Kernel& k, Channel<std::uint32_t>& in, std::vector<std::uint32_t>& out)
        : Module(k, "collect"), in_(in), out_(out) {}
    int evaluate() override {
      if (!in_.can_pop()) return 0;
      out_.push_back(in_.pop());
      return 1;
    }
    Channel<std::uint32_t>& in_;
    std::vector<std::uint32_t>& out_;
  };
  k.make<Collect>(b, got);
  k.run_to_completion([&] { return got.size() == 10; }, 1000);
  EXPECT_EQ(k.modules().size(), 3u);
  EXPECT_EQ(k.channels().size(), 2u);
  EXPECT_EQ(dbl.name(), "a.doubler");
  EXPECT_EQ(got.front(), 1u * 2u + 2u);  // value 1, plus the source's committed count then
}

TEST(Kernel, ModulesWithTheDefaultWakeupAreNeverSkipped) {
  Kernel k;
  int calls = 0;
  class Counting : public Module {
   public:
    Counting(Kernel& k, int& c) : Module(k, "counting"), c_(c) {}
    int evaluate() override { return ++c_, 0; }
    int& c_;
  } m(k, calls);
  const RunResult r = k.run([] { return false; }, 300);
  EXPECT_EQ(r.status, RunResult::Status::kCycleLimit);
  EXPECT_EQ(calls, 300);
  EXPECT_EQ(k.skipped_cycles(), 0u);
}

}  // namespace
}  // namespace saarcor::hw
