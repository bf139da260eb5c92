// The terminal heartbeat: when it shows (a terminal and CI unset), what a beat writes, the rate
// limit, and the cycle model's status line.
#include "testbench/heartbeat.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <string>

#include "testbench/testing.h"

namespace saarcor {
namespace {

// What the heartbeat wrote into a temporary file.
std::string contents(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string s;
  for (int c = std::fgetc(f); c != EOF; c = std::fgetc(f))
    s += static_cast<char>(c);
  return s;
}

TEST(Heartbeat, ShowsOnATerminalOnlyAndNeverUnderCi) {
  EXPECT_TRUE(heartbeat_wanted(true, nullptr));
  EXPECT_FALSE(heartbeat_wanted(false, nullptr));  // a file, a pipe
  EXPECT_FALSE(heartbeat_wanted(true, "true"));    // CI set (GitHub, GitLab: "true")
  EXPECT_FALSE(heartbeat_wanted(true, ""));        // set, even empty
  EXPECT_FALSE(heartbeat_wanted(false, "1"));
}

TEST(Heartbeat, DisabledWritesNothing) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    Heartbeat beat("render", false, f, std::chrono::milliseconds(0));
    EXPECT_FALSE(beat.enabled());
    beat.beat("packets 1 / 2");
    beat.finish("packets 2 / 2");
  }
  EXPECT_EQ(contents(f), "");
  std::fclose(f);
}

TEST(Heartbeat, BeatsRewriteOneLineAtMostOncePerPeriod) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    Heartbeat beat("sweep", true, f, std::chrono::hours(1));
    beat.beat("points 1 / 3");  // the first beat shows at once
    beat.beat("points 2 / 3");  // within the period: kept, not written
    beat.finish();              // the last status, then the line ends
  }
  EXPECT_EQ(contents(f), "\r\033[Ksweep: points 1 / 3\r\033[Ksweep: points 2 / 3\n");
  std::fclose(f);

  f = std::tmpfile();
  {
    Heartbeat beat("precision", true, f, std::chrono::milliseconds(0));
    beat.beat("formats 0 / 2");
    beat.beat("formats 1 / 2");
    beat.finish("formats 2 / 2");
    beat.beat("formats 3 / 2");  // after finish: nothing
  }                              // the destructor's finish writes nothing more
  EXPECT_EQ(contents(f),
            "\r\033[Kprecision: formats 0 / 2\r\033[Kprecision: formats 1 / 2"
            "\r\033[Kprecision: formats 2 / 2\n");
  std::fclose(f);
}

TEST(Heartbeat, CycleStatusGivesSimulatedKilohertz) {
  EXPECT_EQ(Heartbeat::cycle_status(1234567, 120, 3072, 2.0),
            "packets 120 / 3072, 1234567 cycles, 617 kHz simulated");
  EXPECT_EQ(Heartbeat::cycle_status(0, 0, 16, 0.0), "packets 0 / 16, 0 cycles, 0 kHz simulated");
}

// End to end: stderr captured in a file, so not one heartbeat byte reaches it.
TEST(Heartbeat, QuietWhenStderrIsAFile) {
  const test_support::CliRun r =
      test_support::run_saarcor("render builtin:cube --model cycle --res 16x12 --out " +
                                (test_support::scratch_dir("heartbeat") / "cube").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
}

}  // namespace
}  // namespace saarcor
