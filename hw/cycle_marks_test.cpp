// CycleMarks: marks, counts and finds cycles across word and window boundaries, against a set of
// cycles kept beside it.
#include "hw/cycle_marks.h"

#include <gtest/gtest.h>

#include <random>
#include <set>

namespace saarcor::hw {
namespace {

TEST(CycleMarks, MarksCountsAndClearsAcrossWords) {
  CycleMarks m(128);
  EXPECT_EQ(m.window(), 128u);
  EXPECT_TRUE(m.mark(5));
  EXPECT_FALSE(m.mark(5));  // already marked
  m.mark(60, 70);           // spans the first word's end
  EXPECT_EQ(m.next(0, 128), 5u);
  EXPECT_EQ(m.next(6, 128), 60u);
  EXPECT_EQ(m.next(70, 128), kNever);
  EXPECT_EQ(m.take(0, 64), 5u);  // 5 and 60..63
  EXPECT_EQ(m.take(0, 64), 0u);  // cleared
  EXPECT_TRUE(m.take(64));
  EXPECT_FALSE(m.take(64));
  EXPECT_EQ(m.take(64, 128), 5u);  // 65..69
  EXPECT_EQ(m.next(0, 128), kNever);
}

TEST(CycleMarks, WrapsAroundTheWindow) {
  CycleMarks m(128);
  // From cycle 1000 on, the window covers 1000..1127: bits wrap past the ring's end.
  m.mark(1020, 1030);
  m.mark(1100);
  m.mark(1126, 1128);
  EXPECT_EQ(m.next(1000, 1128), 1020u);
  EXPECT_EQ(m.next(1030, 1128), 1100u);
  EXPECT_EQ(m.next(1101, 1128), 1126u);
  // A range longer than the window counts one window only.
  EXPECT_EQ(m.take(1000, 5000), 13u);
  EXPECT_EQ(m.next(1000, 1128), kNever);
  // A whole word at once.
  m.mark(1152, 1216);
  EXPECT_EQ(m.take(1128, 1256), 64u);
}

TEST(CycleMarks, AgreesWithASetOfCycles) {
  std::mt19937_64 rng(7);
  CycleMarks m(256);
  std::set<std::uint64_t> ref;
  std::uint64_t from = 0;  // the first cycle not yet taken; marks stay within the window from it
  for (int step = 0; step < 20000; ++step) {
    const std::uint64_t a = from + rng() % 256;
    switch (rng() % 4) {
      case 0:
        EXPECT_EQ(m.mark(a), ref.insert(a).second);
        break;
      case 1: {
        const std::uint64_t b = std::min(a + rng() % 80, from + 256);
        m.mark(a, b);
        for (std::uint64_t c = a; c < b; ++c) {
          ref.insert(c);
        }
        break;
      }
      case 2: {
        const auto it = ref.lower_bound(a);
        EXPECT_EQ(m.next(a, from + 256), it == ref.end() ? kNever : *it);
        break;
      }
      default: {
        // Time passes: the cycles up to `to` are counted and cleared.
        const std::uint64_t to = from + rng() % 100;
        std::uint64_t n = 0;
        while (!ref.empty() && *ref.begin() < to) {
          ref.erase(ref.begin());
          ++n;
        }
        ASSERT_EQ(m.take(from, to), n);
        from = to;
        break;
      }
    }
  }
}

}  // namespace
}  // namespace saarcor::hw
