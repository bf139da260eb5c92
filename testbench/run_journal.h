// Runs that survive a kill (docs/runs.md "Runs that survive a kill"): a sweep's points and a frame
// sequence's frames are each written to the run folder's journal as they finish, so a run ended by
// SIGTERM, SIGINT, a cluster's time limit or SIGKILL keeps what finished, and `--resume DIR` runs
// only what is missing and ends with the bytes an uninterrupted run leaves.
//
// The journal (DIR/journal.txt) is append-only text, one record per line:
//   KEY LENGTH HASH PAYLOAD\n
// LENGTH is the payload's bytes and HASH its FNV-1a (16 hex digits), so a record cut short by a
// kill (no newline, a short payload, a wrong hash) is found; only the last record can be cut
// (records are appended one at a time, each flushed to the disk before the next), and that one is
// dropped and the file cut back to the last whole record. The first record (key
// `saarcor-journal-1`) names the run: its identity, what must be equal to resume it (the command,
// the scene, the model, every option that changes a result), and the command line that began it
// (command.txt keeps that one). No record holds a wall-clock figure.
#pragma once

#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace saarcor {

// SIGINT and SIGTERM while one lives: the first signal asks the run to stop (stop_signal() returns
// it; the run starts nothing new, keeps what finishes and throws Interrupted), a second one ends
// the process as the signal's default action does. The previous handlers come back after.
class StopOnSignal {
 public:
  StopOnSignal();
  ~StopOnSignal();
  StopOnSignal(const StopOnSignal&) = delete;
  StopOnSignal& operator=(const StopOnSignal&) = delete;
};
// 0, or the signal (SIGINT, SIGTERM) that asked the run to stop.
int stop_signal();
// "SIGINT", "SIGTERM" or "signal N".
std::string signal_name(int signo);

// A run stopped by a signal after keeping what finished; main prints the message on one line and
// exits with 128 + the signal (the shell's convention for a process a signal ended).
class Interrupted : public std::runtime_error {
 public:
  Interrupted(int signo, const std::string& what) : std::runtime_error(what), signo_(signo) {}
  int signo() const { return signo_; }

 private:
  int signo_;
};

struct JournalRecord {
  std::string key;
  std::string payload;  // one line (no '\n')
};

class RunJournal {
 public:
  // A new journal in `dir` (created when missing), replacing one that is there.
  RunJournal(const std::string& dir, const nlohmann::json& identity,
             const std::vector<std::string>& argv);
  // The journal of `dir` to go on with. Throws one line when there is none, when it is damaged
  // before its last record, or when its identity differs from `identity` (naming the first key
  // that differs). A torn last record is dropped (torn_dropped()).
  static RunJournal resume(const std::string& dir, const nlohmann::json& identity);
  ~RunJournal();
  RunJournal(RunJournal&&) noexcept;
  RunJournal& operator=(RunJournal&&) = delete;
  RunJournal(const RunJournal&) = delete;
  RunJournal& operator=(const RunJournal&) = delete;

  // The whole records of the run (not the header), in the order they were written.
  const std::vector<JournalRecord>& records() const { return records_; }
  // The command line of the run that began the journal.
  const std::vector<std::string>& argv() const { return argv_; }
  bool torn_dropped() const { return torn_; }
  std::string path() const;

  // Appends a record, on the disk (fdatasync) before it returns; thread-safe. Test hooks, read
  // once from the environment: SAARCOR_TEST_JOURNAL_KILL=K writes half of the K-th record of
  // this process and raises SIGKILL (a kill in the middle of a write); SAARCOR_TEST_JOURNAL_SIGNAL
  // =K raises SIGTERM after the K-th (a kill after some records).
  void append(const std::string& key, const std::string& payload);
  // Rewrites the journal (atomically) with its records sorted by key: a resumed run and an
  // uninterrupted one end with the same bytes, whatever order their records finished in.
  void seal();

 private:
  RunJournal() = default;
  void open_for_append();

  std::string dir_;
  std::string header_;
  std::vector<std::string> argv_;
  std::vector<JournalRecord> records_;
  bool torn_ = false;
  int fd_ = -1;
  int appended_ = 0;
  int kill_at_ = 0, signal_at_ = 0;
  std::mutex mutex_;
};

// One record line (with its '\n') and its parse (false: torn or damaged).
std::string journal_line(const std::string& key, const std::string& payload);
bool parse_journal_line(const std::string& line, JournalRecord& out);

// Doubles as the 16 hex digits of their bits (exact, NaN included) and back.
std::string double_bits(double v);
double bits_double(const std::string& hex);

}  // namespace saarcor
