// The terminal heartbeat (testbench/heartbeat.h).
#include "testbench/heartbeat.h"

#include <unistd.h>

#include <cstdlib>

namespace saarcor {

bool heartbeat_wanted(bool stderr_is_tty, const char* ci_env) {
  return stderr_is_tty && ci_env == nullptr;
}

bool heartbeat_enabled() {
  return heartbeat_wanted(isatty(fileno(stderr)) != 0, std::getenv("CI"));
}

Heartbeat::Heartbeat(std::string label, bool enabled, std::FILE* out,
                     std::chrono::milliseconds period)
    : label_(std::move(label)),
      enabled_(enabled),
      out_(out),
      period_(period),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {}

Heartbeat::~Heartbeat() {
  finish();
}

double Heartbeat::seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Heartbeat::write_locked(const std::string& status) {
  // "\r" back to the line's start, ESC[K clears what a longer previous status left behind.
  std::fprintf(out_, "\r\033[K%s: %s", label_.c_str(), status.c_str());
  std::fflush(out_);
  written_ = true;
}

void Heartbeat::beat(const std::string& status) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  status_ = status;
  if (written_ && now - last_ < period_) return;
  last_ = now;
  write_locked(status);
}

void Heartbeat::finish(const std::string& status) {
  if (!enabled_) return;
  const std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (!status.empty()) status_ = status;
  if (!written_ && status_.empty()) return;
  write_locked(status_);
  std::fprintf(out_, "\n");
  std::fflush(out_);
}

std::string Heartbeat::cycle_status(std::uint64_t cycles, int packets_done, int packets_total,
                                    double seconds) {
  char buf[160];
  const double khz = seconds > 0.0 ? static_cast<double>(cycles) / seconds / 1e3 : 0.0;
  std::snprintf(buf, sizeof buf, "packets %d / %d, %llu cycles, %.0f kHz simulated", packets_done,
                packets_total, static_cast<unsigned long long>(cycles), khz);
  return buf;
}

}  // namespace saarcor
