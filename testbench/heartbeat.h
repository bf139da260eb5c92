// A progress heartbeat on the terminal: one status line rewritten in place ("\r") while a long
// run works, so a person at a terminal sees it move, and nothing at all when stderr is a file, a
// pipe or a CI log (a log full of carriage returns is noise and no byte of it is deterministic).
// The one implementation behind `saarcor render` (packets, simulated cycles, simulated kHz),
// `saarcor sweep` (points done / total) and `saarcor precision` (formats done / total).
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>

namespace saarcor {

// The decision: a heartbeat shows when stderr is a terminal and the environment variable CI is
// not set (CI=anything, even empty, silences it: CI systems set it and often give a pseudo-tty).
bool heartbeat_wanted(bool stderr_is_tty, const char* ci_env);
// heartbeat_wanted for this process (isatty(stderr), getenv("CI")).
bool heartbeat_enabled();

// Thread-safe: the sweep's workers beat one heartbeat. A beat is written at most once per
// `period` (the first one at once); finish() writes the last status and ends the line. A disabled
// heartbeat writes nothing, ever.
class Heartbeat {
 public:
  explicit Heartbeat(std::string label, bool enabled = heartbeat_enabled(), std::FILE* out = stderr,
                     std::chrono::milliseconds period = std::chrono::milliseconds(250));
  Heartbeat(const Heartbeat&) = delete;
  Heartbeat& operator=(const Heartbeat&) = delete;
  ~Heartbeat();

  bool enabled() const { return enabled_; }
  void beat(const std::string& status);
  // Writes `status` (or the last beat's when empty) and a newline, if anything was written.
  void finish(const std::string& status = {});
  // Seconds since construction (the rate figures divide by it).
  double seconds() const;

  // "packets 120 / 3072, 1234567 cycles, 5432 kHz simulated": the cycle model's status at
  // `seconds` of wall time.
  static std::string cycle_status(std::uint64_t cycles, int packets_done, int packets_total,
                                  double seconds);

 private:
  void write_locked(const std::string& status);

  std::string label_;
  bool enabled_;
  std::FILE* out_;
  std::chrono::milliseconds period_;
  std::chrono::steady_clock::time_point start_, last_;
  bool written_ = false;
  bool finished_ = false;
  std::string status_;
  std::mutex mutex_;
};

}  // namespace saarcor
