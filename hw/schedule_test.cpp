// The kernel's schedule (hw/schedule.h): due exactly at the wake cycles, wakes only lower, stale
// wheel bits dropped, wakes beyond the wheel's span and more than 64 modules.
#include "hw/schedule.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <random>
#include <set>
#include <vector>

#include "hw/kernel.h"

namespace saarcor::hw {
namespace {

// The slots due in each cycle of [from, to), taken cycle by cycle.
std::map<std::uint64_t, std::set<std::size_t>> take_all(Schedule& s, std::uint64_t from,
                                                        std::uint64_t to) {
  std::map<std::uint64_t, std::set<std::size_t>> due;
  std::vector<std::uint64_t> words(s.words());
  for (std::uint64_t c = from; c < to; ++c) {
    s.take(c, words.data());
    for (std::size_t w = 0; w < words.size(); ++w)
      for (std::size_t b = 0; b < 64; ++b)
        if (words[w] >> b & 1) due[c].insert(w * 64 + b);
  }
  return due;
}

TEST(Schedule, ASlotIsDueOnlyAtItsLowestWakeAndTheSinkNever) {
  Schedule s;
  s.resize(4);
  s.wake(1, 10, 0);
  s.wake(1, 5, 0);   // lowers: 10 becomes a stale bit
  s.wake(1, 7, 0);   // not lower: ignored
  s.wake(2, 63, 0);  // the last cycle the wheel holds
  s.wake(0, 3, 0);   // the sink (undeclared channel ends)
  const auto due = take_all(s, 0, 70);
  const std::map<std::uint64_t, std::set<std::size_t>> want{{5, {1}}, {63, {2}}};
  EXPECT_EQ(due, want);
}

TEST(Schedule, WakesBeyondTheSpanEnterTheWheelInTime) {
  Schedule s;
  s.resize(3);
  s.wake(1, 64, 0);    // one past the span
  s.wake(2, 1000, 0);  // far
  auto due = take_all(s, 0, 1100);
  const std::map<std::uint64_t, std::set<std::size_t>> want{{64, {1}}, {1000, {2}}};
  EXPECT_EQ(due, want);
  // A far wake lowered to a near one is due at the near one only.
  s.wake(1, 5000, 1100);
  s.wake(1, 1120, 1100);
  due = take_all(s, 1100, 6000);
  const std::map<std::uint64_t, std::set<std::size_t>> want2{{1120, {1}}};
  EXPECT_EQ(due, want2);
}

// Random wakes over 150 slots (three words) against a plain model: every slot is due exactly at
// its lowest pending wake, and a taken slot can be woken again.
TEST(Schedule, RandomWakesMatchAPlainModel) {
  constexpr std::size_t kSlots = 150;
  Schedule s;
  s.resize(kSlots);
  std::vector<std::uint64_t> model(kSlots, kNever);
  std::mt19937_64 rng(7);
  std::vector<std::uint64_t> words(s.words());
  int checked = 0;
  for (std::uint64_t c = 0; c < 5000; ++c) {
    for (int k = 0; k < 4; ++k) {
      const std::size_t slot = 1 + rng() % (kSlots - 1);
      const std::uint64_t ahead = rng() % 4 == 0 ? rng() % 300 : rng() % 8;
      const std::uint64_t at = c + ahead;
      s.wake(slot, at, c);
      model[slot] = std::min(model[slot], at);
    }
    s.take(c, words.data());
    for (std::size_t slot = 1; slot < kSlots; ++slot) {
      const bool due = (words[slot / 64] >> (slot % 64) & 1) != 0;
      ASSERT_EQ(due, model[slot] == c) << "slot " << slot << " cycle " << c;
      if (due) {
        model[slot] = kNever;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 10000);
}

// A long channel latency (beyond the wheel) and a consumer that sleeps: the item arrives exactly
// at push + latency, with and without idle skipping.
TEST(Schedule, ALongLatencyWakesASleepingConsumerExactly) {
  for (const bool skip : {true, false}) {
    Kernel k({.idle_skip = skip});
    Channel<int> ch(k, "long", 2, 200);
    struct Producer : Module {
      Producer(Kernel& k, Channel<int>& c) : Module(k, "producer"), c_(c) {
        sleep_when_idle();
        produces(c_);
      }
      int evaluate() override {
        if (sent_ || now() != 3) return 0;
        c_.push(42);
        sent_ = true;
        return 1;
      }
      std::uint64_t next_wakeup(std::uint64_t now) const override {
        return sent_ || now >= 3 ? kNever : 3;
      }
      Channel<int>& c_;
      bool sent_ = false;
    } producer(k, ch);
    struct Consumer : Module {
      Consumer(Kernel& k, Channel<int>& c) : Module(k, "consumer"), c_(c) {
        sleep_when_idle();
        consumes(c_);
      }
      int evaluate() override {
        if (!c_.can_pop()) return 0;
        got_ = c_.pop();
        at_ = now();
        return 1;
      }
      std::uint64_t next_wakeup(std::uint64_t) const override { return kNever; }
      Channel<int>& c_;
      int got_ = 0;
      std::uint64_t at_ = 0;
    } consumer(k, ch);
    k.run_to_completion([&] { return consumer.got_ != 0; }, 1000);
    EXPECT_EQ(consumer.got_, 42);
    EXPECT_EQ(consumer.at_, 203u) << (skip ? "with" : "without") << " idle skip";
    if (skip) {
      EXPECT_LT(k.module_evaluations(), 10u);  // asleep through the latency
    }
  }
}

}  // namespace
}  // namespace saarcor::hw
