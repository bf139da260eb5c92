// Runs that survive a kill (testbench/run_journal.h, docs/runs.md): the journal's records, a torn
// last record dropped and the file cut back, a damaged record or another run's folder refused;
// then the binary end to end: a sweep and a frame sequence stopped by SIGTERM after some records,
// and killed by SIGKILL in the middle of one, resume to the bytes of an uninterrupted run (every
// file of the folder but host.json, which holds the host's wall clock).
#include "testbench/run_journal.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "testbench/frame_sequence.h"
#include "testbench/testing.h"

namespace saarcor {
namespace {

namespace fs = std::filesystem;
using test_support::error_of;
using test_support::expect_one_line_error;
using test_support::run_saarcor;
using test_support::scratch_dir;

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

const nlohmann::json kIdentity = {{"command", "test"}, {"res", "32x24"}};

TEST(RunJournal, TornLastRecordIsDroppedAndTheFileCutBack) {
  const fs::path d = scratch_dir("journal_torn") / "run";
  fs::remove_all(d);
  {
    RunJournal j(d.string(), kIdentity, {"saarcor", "test"});
    j.append("a", "{\"x\":1}");
    j.append("b", "{\"x\":2}");
    j.append("c", "{\"x\":3}");
  }
  const fs::path file = d / "journal.txt";
  const std::string whole = slurp(file);
  // The header and two records survive; the third is cut in the middle (no newline).
  const std::size_t third = whole.find("\nc ") + 1;
  fs::resize_file(file, third + 9);
  RunJournal j = RunJournal::resume(d.string(), kIdentity);
  EXPECT_TRUE(j.torn_dropped());
  ASSERT_EQ(j.records().size(), 2u);
  EXPECT_EQ(j.records()[1].key, "b");
  EXPECT_EQ(j.records()[1].payload, "{\"x\":2}");
  EXPECT_EQ(j.argv(), (std::vector<std::string>{"saarcor", "test"}));
  EXPECT_EQ(fs::file_size(file), third);  // cut back to the last whole record
  j.append("c", "{\"x\":3}");
  EXPECT_EQ(slurp(file), whole);  // appended again: the bytes the run would have written
}

TEST(RunJournal, SealSortsTheRecordsByKey) {
  const fs::path a = scratch_dir("journal_seal") / "a", b = scratch_dir("journal_seal") / "b";
  {
    RunJournal j(a.string(), kIdentity, {"saarcor"});
    j.append("point0001", "1");
    j.append("point0000", "0");
    j.seal();
  }
  {
    RunJournal j(b.string(), kIdentity, {"saarcor"});
    j.append("point0000", "0");
    j.append("point0001", "1");
    j.seal();
  }
  EXPECT_EQ(slurp(a / "journal.txt"), slurp(b / "journal.txt"));
  // A record line: key, payload length, FNV-1a of the payload, payload.
  EXPECT_EQ(journal_line("point0000", "0"), "point0000 1 44bd5bd473cd4929 0\n");
}

TEST(RunJournal, AnotherRunOrADamagedRecordIsOneLine) {
  const fs::path d = scratch_dir("journal_other") / "run";
  fs::remove_all(d);
  {
    RunJournal j(d.string(), kIdentity, {"saarcor"});
    j.append("a", "1");
    j.append("b", "2");
  }
  nlohmann::json other = kIdentity;
  other["res"] = "64x48";
  EXPECT_EQ(error_of([&] { RunJournal::resume(d.string(), other); }),
            "--resume '" + d.string() +
                "': the folder holds another run (its value, this command's: res: \"32x24\", "
                "\"64x48\")");
  // A record damaged before the last one is not a kill's work: refused.
  std::string text = slurp(d / "journal.txt");
  text[text.find("\na ") + 6] ^= 1;
  std::ofstream(d / "journal.txt", std::ios::binary) << text;
  EXPECT_NE(error_of([&] { RunJournal::resume(d.string(), kIdentity); }).find("damaged at line 2"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              RunJournal::resume((d / "none").string(), kIdentity);
            }).find("no journal.txt"),
            std::string::npos);
}

TEST(RunJournal, FrameRecordsKeepEveryBit) {
  FrameRecord r;
  r.row.index = 3;
  r.row.time = 0.1 + 0.2;  // not a short decimal
  r.row.frame_bank = 1;
  r.row.top_copy = 1;
  r.row.upload_bytes = 1234;
  r.row.cycles = 98765;
  r.row.fps = std::numeric_limits<double>::quiet_NaN();
  r.row.figures.value[2] = 1.0 / 3.0;
  r.row.digest = 0xfedcba9876543210ull;
  r.row.gap = true;
  r.next_upload_cycles = 777;
  r.gap_cycles = 55;
  const FrameRecord back = parse_frame_record(frame_record_text(r));
  EXPECT_EQ(frame_record_text(back), frame_record_text(r));
  EXPECT_EQ(back.row.time, 0.1 + 0.2);
  EXPECT_TRUE(std::isnan(back.row.fps));
  EXPECT_EQ(back.row.figures.value[2], 1.0 / 3.0);
  EXPECT_EQ(back.row.digest, 0xfedcba9876543210ull);
  EXPECT_EQ(back.next_upload_cycles, 777u);
  EXPECT_NE(error_of([] { parse_frame_record("{\"index\":1}"); }).find("damaged"),
            std::string::npos);
}

// Every file of the folder, by name (host.json left out: the host's wall clock).
std::map<std::string, std::string> folder_files(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename() != "host.json") files[e.path().filename().string()] = slurp(e.path());
  return files;
}

void expect_same_folders(const fs::path& a, const fs::path& b) {
  const auto fa = folder_files(a), fb = folder_files(b);
  ASSERT_EQ(fa.size(), fb.size());
  for (const auto& [name, bytes] : fa) {
    ASSERT_TRUE(fb.contains(name)) << name;
    EXPECT_TRUE(fb.at(name) == bytes) << name << " differs";
  }
}

// Runs `args` with `env=value` set for the child (a test hook of testbench/run_journal.h).
test_support::CliRun run_with(const char* env, const char* value, const std::string& args) {
  setenv(env, value, 1);
  const test_support::CliRun r = run_saarcor(args);
  unsetenv(env);
  return r;
}

// The run, uninterrupted, kept as the reference; then the same command into the same folder
// (command.txt names it), stopped or killed by the hook, resumed, and compared with the reference.
void check_resume(const std::string& tag, const std::string& command, const char* hook,
                  const char* at, int stopped_status, const std::string& stopped_message) {
  const fs::path base = scratch_dir(tag), run = base / "run", reference = base / "reference";
  fs::remove_all(run);
  fs::remove_all(reference);
  const std::string args = command + " --out-dir " + run.string();
  const test_support::CliRun whole = run_saarcor(args);
  ASSERT_EQ(whole.status, 0) << whole.err;
  fs::rename(run, reference);
  const test_support::CliRun stopped = run_with(hook, at, args);
  EXPECT_EQ(stopped.status, stopped_status) << stopped.err;
  EXPECT_NE(stopped.err.find(stopped_message), std::string::npos) << stopped.err;
  EXPECT_FALSE(fs::exists(run / "report.json"));  // only the journal (and images) so far
  const std::string journal = slurp(run / "journal.txt");
  // Killed in the middle of a record: the file ends inside it; stopped: after a whole one.
  EXPECT_EQ(journal.back() == '\n', stopped_status != 137);
  const test_support::CliRun resumed = run_saarcor(command + " --resume " + run.string());
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_NE(resumed.out.find("resumed:"), std::string::npos) << resumed.out;
  expect_same_folders(reference, run);
}

const std::string kSweep =
    "sweep builtin:room --res 32x24 --vary threads=4,8,16 --vary packet=1,4 --jobs 2";

// SIGTERM after the second point's record: the running points finish and are kept, the exit is
// 128 + 15 with one line saying what was kept.
TEST(SweepResume, StoppedBySigtermResumesToTheUninterruptedBytes) {
  check_resume("resume_sweep_term", kSweep, "SAARCOR_TEST_JOURNAL_SIGNAL", "2", 143,
               "saarcor: sweep stopped by SIGTERM: ");
}

// SIGKILL with half of the third record written (the shell reports 128 + 9): the torn record is
// dropped on resume.
TEST(SweepResume, KilledMidRecordResumesToTheUninterruptedBytes) {
  check_resume("resume_sweep_kill", kSweep, "SAARCOR_TEST_JOURNAL_KILL", "3", 137, "");
}

const std::string kFrames = "render builtin:dynamic --model cycle --res 32x24 --frames 4";

TEST(FramesResume, StoppedBySigtermResumesToTheUninterruptedBytes) {
  check_resume("resume_frames_term", kFrames, "SAARCOR_TEST_JOURNAL_SIGNAL", "2", 143,
               "saarcor: render --frames stopped by SIGTERM: 2 of 4 frames kept");
}

TEST(FramesResume, KilledMidRecordResumesToTheUninterruptedBytes) {
  check_resume("resume_frames_kill", kFrames, "SAARCOR_TEST_JOURNAL_KILL", "2", 137, "");
}

TEST(RunResume, AnotherCommandOrConfigurationIsOneErrorLine) {
  const fs::path d = scratch_dir("resume_bad") / "run";
  fs::remove_all(d);
  ASSERT_EQ(run_saarcor(kSweep + " --out-dir " + d.string()).status, 0);
  expect_one_line_error(run_saarcor(kSweep + " --set mem.latency=6 --resume " + d.string()),
                        "the folder holds another run (its value, this command's: set: [], "
                        "[\"mem.latency=6\"])");
  expect_one_line_error(run_saarcor(kFrames + " --resume " + d.string()),
                        "command: \"sweep\", \"render --frames\"");
  expect_one_line_error(run_saarcor(kSweep + " --resume " + (d / "none").string()),
                        "no journal.txt");
  expect_one_line_error(run_saarcor("render builtin:room --res 16x12 --resume " + d.string()),
                        "--resume need --frames N");
  expect_one_line_error(
      run_saarcor(kSweep + " --out-dir " + d.string() + "x --resume " + d.string()),
      "name two folders");
}

}  // namespace
}  // namespace saarcor
