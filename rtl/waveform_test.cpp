// The waveform window of saarcor-rtl lockstep (rtl/waveform.h): at a divergence the binary writes
// a VCD of the RTL from 64 cycles before it to 16 after and prints the command that replays to
// it; a replay that stops at that divergence writes the same window again. The VCD is read here by
// a parser of its own (the value-change-dump grammar: declarations, then `#time` lines), not by
// Verilator's writer.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "rtl/units_testing.h"

namespace saarcor::rtl {
namespace {

struct Outcome {
  int exit = -1;
  std::string text;
};

Outcome run(const std::string& args) {
  const std::string cmd = std::string(SAARCOR_BIN_DIR) + "/saarcor-rtl " + args + " 2>&1";
  Outcome r;
  FILE* p = ::popen(cmd.c_str(), "r");
  char buf[512];
  while (p && std::fgets(buf, sizeof buf, p))
    r.text += buf;
  const int status = p ? ::pclose(p) : -1;
  r.exit = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// What a VCD holds for these checks: the declared signal names and the dump times.
struct Vcd {
  bool header_closed = false;
  std::vector<std::string> signals;
  std::vector<std::uint64_t> times;
};

Vcd read_vcd(const std::string& path) {
  Vcd v;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string first;
    words >> first;
    if (!v.header_closed && first == "$var") {  // $var wire 1 ! clk $end
      std::string type, width, id, name;
      words >> type >> width >> id >> name;
      v.signals.push_back(name);
    } else if (first == "$enddefinitions") {
      v.header_closed = true;
    } else if (v.header_closed && line.size() > 1 && line[0] == '#') {
      // A time is a line of its own; an identifier may begin with '#' too ("b0101 #5").
      v.times.push_back(std::stoull(line.substr(1)));
    }
  }
  return v;
}

// The text after the declarations: the value changes.
std::string dumps(const std::string& path) {
  std::ifstream in(path);
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t end = all.find("$enddefinitions");
  return end == std::string::npos ? std::string() : all.substr(end);
}

bool has_signal(const Vcd& v, const std::string& name) {
  for (const std::string& s : v.signals)
    if (s == name) return true;
  return false;
}

// Two time units per cycle (2c clock low, 2c + 1 high): every dump of the window [from, to]
// lies in [2 from, 2 to + 1], and the window's first and last cycles are there.
void expect_window(const Vcd& v, std::uint64_t from, std::uint64_t to) {
  ASSERT_TRUE(v.header_closed);
  EXPECT_TRUE(has_signal(v, "clk"));
  EXPECT_TRUE(has_signal(v, "out_valid"));  // the traversal unit's output port
  ASSERT_FALSE(v.times.empty());
  for (std::uint64_t t : v.times) {
    EXPECT_GE(t, 2 * from);
    EXPECT_LE(t, 2 * to + 1);
  }
  EXPECT_LE(v.times.front(), 2 * from + 1);
  EXPECT_GE(v.times.back(), 2 * to);
}

// The traversal pipeline one cycle short diverges at the unit's first output; the binary says
// where, writes the window around it and a replay command that stops at the same divergence.
TEST(Waveform, DivergenceWritesTheWindowAndTheReplayStopsThere) {
  const std::string wave = testing::temp_path("divergence.vcd");
  const std::string replay_wave = testing::temp_path("replay.vcd");
  std::filesystem::remove(wave);
  std::filesystem::remove(replay_wave);
  const Outcome r =
      run("lockstep builtin:room --res 24x18 --units traversal --fault short-pipeline "
          "--wave '" +
          wave + "'");
  ASSERT_EQ(r.exit, 2) << r.text;
  // The replay line: "... --until CYCLE --wave FILE" (no <regex>: GCC 12's -Wmaybe-uninitialized
  // false positive in it, bug 105562, stops the sanitizer build).
  const std::size_t until = r.text.find("--until ");
  ASSERT_NE(until, std::string::npos) << r.text;
  std::istringstream replay_line(r.text.substr(until + 8));
  std::uint64_t cycle = 0;
  std::string wave_flag, wave_arg;
  replay_line >> cycle >> wave_flag >> wave_arg;
  EXPECT_EQ(wave_flag, "--wave");
  EXPECT_EQ(wave_arg, wave);
  EXPECT_NE(r.text.find("waveform: " + wave), std::string::npos) << r.text;
  const std::uint64_t from = cycle > 64 ? cycle - 64 : 0;  // from reset, if that is nearer
  expect_window(read_vcd(wave), from, cycle + 16);

  const Outcome replay =
      run("lockstep builtin:room --res 24x18 --units traversal --fault "
          "short-pipeline --until " +
          std::to_string(cycle) + " --wave '" + replay_wave + "'");
  EXPECT_EQ(replay.exit, 2) << replay.text;
  EXPECT_NE(replay.text.find("--until " + std::to_string(cycle)), std::string::npos) << replay.text;
  // It diverges at the same cycle, so it writes the same window again: the same dumps, bit for
  // bit (the header's date aside).
  const Vcd a = read_vcd(wave), b = read_vcd(replay_wave);
  expect_window(b, from, cycle + 16);
  EXPECT_EQ(a.signals, b.signals);
  EXPECT_EQ(dumps(wave), dumps(replay_wave));
}

}  // namespace
}  // namespace saarcor::rtl
