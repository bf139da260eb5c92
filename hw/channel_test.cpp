// Channel and pipeline semantics (docs/hw.md): exact cycle counts with mock neighbours,
// capacity, back-pressure, port width, no loss and no duplication, misuse detection.
#include "hw/channel.h"

#include <gtest/gtest.h>

#include <functional>
#include <random>
#include <vector>

#include "hw/kernel.h"

namespace saarcor::hw {
namespace {

// A mock neighbour whose evaluate() is a test lambda.
class FnModule : public Module {
 public:
  FnModule(Kernel& k, std::string name, std::function<int()> f)
      : Module(k, std::move(name)), f_(std::move(f)) {}
  int evaluate() override { return f_(); }

 private:
  std::function<int()> f_;
};

TEST(Channel, ItemPushedInCycleCIsPoppableExactlyAtCPlusLatency) {
  for (int latency : {1, 2, 3, 7}) {
    Kernel k;
    Channel<int> ch(k, "ch", latency + 1, latency);
    std::uint64_t popped_at = kNever;
    int value = 0;
    FnModule prod(k, "prod", [&] {
      if (k.now() != 0) return 0;
      ch.push(42);
      return 1;
    });
    FnModule cons(k, "cons", [&] {
      if (!ch.can_pop()) return 0;
      popped_at = k.now();
      value = ch.pop();
      return 1;
    });
    for (int c = 0; c < 20; ++c)
      k.step();
    EXPECT_EQ(popped_at, static_cast<std::uint64_t>(latency)) << "latency " << latency;
    EXPECT_EQ(value, 42);
    EXPECT_EQ(ch.total_pushes(), 1u);
  }
}

TEST(Channel, PushIsInvisibleInTheSameCycleEvenWhenConsumerEvaluatesLater) {
  Kernel k;
  Channel<int> ch(k, "ch", 2, 1);
  bool saw_same_cycle = false;
  FnModule prod(k, "prod", [&] {
    if (k.now() == 0) ch.push(1);
    return k.now() == 0;
  });
  FnModule cons(k, "cons", [&] {  // evaluated after the producer
    if (k.now() == 0 && (ch.can_pop() || ch.occupancy() != 0)) saw_same_cycle = true;
    return 0;
  });
  k.step();
  EXPECT_FALSE(saw_same_cycle);
  EXPECT_EQ(ch.occupancy(), 1);
  EXPECT_TRUE(ch.valid());  // cycle 1 now
}

TEST(Channel, FullChannelBackPressuresAndFreedSlotIsUsableOneCycleAfterThePop) {
  Kernel k;
  Channel<int> ch(k, "ch", 2, 1);
  std::vector<std::uint64_t> pushed_at;
  bool consumer_on = false;
  std::uint64_t popped_at = kNever;
  FnModule prod(k, "prod", [&] {
    if (!ch.can_push()) return 0;
    ch.push(static_cast<int>(pushed_at.size()));
    pushed_at.push_back(k.now());
    return 1;
  });
  FnModule cons(k, "cons", [&] {
    if (!consumer_on || popped_at != kNever || !ch.can_pop()) return 0;
    EXPECT_EQ(ch.pop(), 0);
    popped_at = k.now();
    return 1;
  });
  for (int c = 0; c < 5; ++c)
    k.step();  // cycles 0..4
  EXPECT_EQ(pushed_at, (std::vector<std::uint64_t>{0, 1}));
  EXPECT_FALSE(ch.ready());
  consumer_on = true;
  k.step();  // cycle 5: pop; the producer still sees a full channel
  EXPECT_EQ(popped_at, 5u);
  EXPECT_EQ(pushed_at.size(), 2u);
  k.step();  // cycle 6: the slot is free
  EXPECT_EQ(pushed_at, (std::vector<std::uint64_t>{0, 1, 6}));
}

TEST(Channel, CapacityLatencyPlusOneSustainsOneItemPerCycleAndLessDoesNot) {
  // Streams 100 items through a channel with an always-ready consumer; counts cycles until the
  // last arrives. Capacity L+1: one per cycle, so the last item (pushed at 99) arrives at 99+L.
  // Capacity L: each slot is busy L+1 cycles, so L items per L+1 cycles.
  for (int latency : {1, 3}) {
    for (int extra : {0, 1}) {
      Kernel k;
      const int cap = latency + extra;
      Channel<int> ch(k, "ch", cap, latency);
      int sent = 0, received = 0;
      std::uint64_t last_arrival = 0;
      FnModule prod(k, "prod", [&] {
        if (sent == 100 || !ch.can_push()) return 0;
        ch.push(sent++);
        return 1;
      });
      FnModule cons(k, "cons", [&] {
        if (!ch.can_pop()) return 0;
        EXPECT_EQ(ch.pop(), received++);
        last_arrival = k.now();
        return 1;
      });
      k.run_to_completion([&] { return received == 100; }, 1000);
      if (extra == 1) {
        EXPECT_EQ(last_arrival, static_cast<std::uint64_t>(99 + latency));
      } else {
        // Item i is pushed at floor(i/L)*(L+1) + i%L, arrives L later.
        const int i = 99;
        EXPECT_EQ(last_arrival,
                  static_cast<std::uint64_t>(i / cap * (latency + 1) + i % cap + latency))
            << "latency " << latency;
      }
    }
  }
}

TEST(Channel, PortWidthLimitsPushesAndPopsPerCycle) {
  Kernel k;
  Channel<int> ch(k, "ch", 8, 1, 2);
  FnModule prod(k, "prod", [&] {
    if (k.now() != 0) return 0;
    ch.push(1);
    ch.push(2);
    EXPECT_FALSE(ch.can_push());
    EXPECT_THROW(ch.push(3), std::logic_error);
    return 2;
  });
  std::vector<int> got;
  FnModule cons(k, "cons", [&] {
    int n = 0;
    while (ch.can_pop()) {
      got.push_back(ch.pop());
      ++n;
    }
    return n;
  });
  k.step();
  k.step();
  EXPECT_EQ(got, (std::vector<int>{1, 2}));
}

TEST(Channel, MisuseThrowsNamingTheChannel) {
  Kernel k;
  Channel<int> ch(k, "dynrtp0.list.in", 1, 2);
  FnModule m(k, "m", [&] {
    if (k.now() == 0) {
      EXPECT_THROW(ch.pop(), std::logic_error);
      EXPECT_THROW((void)ch.peek(), std::logic_error);
      ch.push(5);
      try {
        ch.push(6);
        ADD_FAILURE() << "push on a full channel did not throw";
      } catch (const std::logic_error& e) {
        EXPECT_NE(std::string(e.what()).find("dynrtp0.list.in"), std::string::npos);
      }
    }
    if (k.now() == 1) {
      EXPECT_THROW(ch.pop(), std::logic_error);  // latency not elapsed
    }
    if (k.now() == 2) {
      EXPECT_EQ(ch.pop(), 5);
    }
    return 1;
  });
  for (int c = 0; c < 3; ++c)
    k.step();
  EXPECT_TRUE(ch.empty());
  EXPECT_THROW(Channel<int>(k, "bad", 0, 1), std::logic_error);
  EXPECT_THROW(Channel<int>(k, "bad2", 1, 0), std::logic_error);
}

// drop() is pop() without the copy: the same slot, the same hand-shake, misuse included.
TEST(Channel, DropTakesTheFrontItemLikePop) {
  Kernel k;
  Channel<int> ch(k, "ch", 4, 1, 2);
  std::vector<int> seen;
  FnModule m(k, "m", [&] {
    if (k.now() == 0) {
      EXPECT_THROW(ch.drop(), std::logic_error);
      ch.push(1);
      ch.push(2);
    }
    if (k.now() == 1) {
      seen.push_back(ch.peek());
      ch.drop();
      seen.push_back(ch.pop());  // the second port of the same cycle sees the next item
      EXPECT_FALSE(ch.can_pop());
    }
    return 1;
  });
  k.step();
  k.step();
  EXPECT_EQ(seen, (std::vector<int>{1, 2}));
  EXPECT_TRUE(ch.empty());
}

TEST(Channel, RandomTrafficNeitherLosesNorDuplicatesAndKeepsOrder) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    Kernel k;
    const int latency = 1 + static_cast<int>(rng() % 5);
    const int cap = 1 + static_cast<int>(rng() % 6);
    const int width = 1 + static_cast<int>(rng() % 2);
    Channel<std::uint32_t> ch(k, "ch", cap, latency, width);
    std::uint32_t next_send = 0, next_expect = 0;
    std::vector<std::uint64_t> push_cycle;
    std::mt19937 prng(static_cast<unsigned>(trial));
    std::mt19937 crng(static_cast<unsigned>(trial + 100));
    constexpr std::uint32_t kItems = 2000;
    FnModule prod(k, "prod", [&] {
      int n = 0;
      while (next_send < kItems && ch.can_push() && prng() % 3 != 0) {
        push_cycle.push_back(k.now());
        ch.push(next_send++);
        ++n;
      }
      return n;
    });
    FnModule cons(k, "cons", [&] {
      int n = 0;
      while (ch.can_pop() && crng() % 4 != 0) {
        const std::uint32_t v = ch.pop();
        EXPECT_EQ(v, next_expect);
        EXPECT_GE(k.now(), push_cycle[v] + static_cast<std::uint64_t>(latency));
        ++next_expect;
        ++n;
      }
      return n;
    });
    k.run_to_completion([&] { return next_expect == kItems; }, 100000);
    EXPECT_EQ(ch.total_pushes(), kItems);
    EXPECT_TRUE(ch.empty());
    EXPECT_LE(k.stats().value("ch.max_occupancy"), cap);
  }
}

TEST(Pipeline, DepthEightIssuesEveryCycleAndEachResultAppearsEightCyclesLater) {
  Kernel k;
  Pipeline<int> div(k, "div", 8);
  std::vector<std::uint64_t> out_cycle;
  int issued = 0;
  FnModule unit(k, "unit", [&] {
    int p = 0;
    if (div.can_pop()) {  // retire first: this cycle's issue is independent of it anyway
      EXPECT_EQ(div.pop(), static_cast<int>(out_cycle.size()));
      out_cycle.push_back(k.now());
      ++p;
    }
    if (issued < 20) {
      EXPECT_TRUE(div.can_push()) << "cycle " << k.now();
      div.push(issued++);
      ++p;
    }
    return p;
  });
  k.run_to_completion([&] { return out_cycle.size() == 20; }, 100);
  for (int i = 0; i < 20; ++i)
    EXPECT_EQ(out_cycle[i], static_cast<std::uint64_t>(i + 8));
  EXPECT_EQ(div.depth(), 8);
}

TEST(Pipeline, UntakenResultsStallIssueInsteadOfBeingLost) {
  Kernel k;
  Pipeline<int> mul(k, "mul", 3);
  int issued = 0;
  FnModule unit(k, "unit", [&] {
    if (!mul.can_push()) {
      return 0;
    }
    mul.push(issued++);
    return 1;
  });
  for (int c = 0; c < 10; ++c)
    k.step();
  EXPECT_EQ(issued, 4);  // depth + 1 results held
  EXPECT_EQ(mul.occupancy(), 4);
}

}  // namespace
}  // namespace saarcor::hw
