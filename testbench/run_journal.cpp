// The run folder's journal and the stop signals (testbench/run_journal.h, docs/runs.md).
#include "testbench/run_journal.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "testbench/image_io.h"
#include "testbench/report.h"

namespace saarcor {
namespace {

constexpr const char* kHeaderKey = "saarcor-journal-1";
constexpr const char* kFileName = "journal.txt";

// Written by the signal handler (lock-free, async-signal-safe), read by the run's threads.
std::atomic<int> g_stop{0};
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void on_stop_signal(int signo) {
  if (g_stop.load() != 0) {
    // The second signal: the default action (the process ends as the signal says).
    std::signal(signo, SIG_DFL);
    std::raise(signo);
    return;
  }
  g_stop.store(signo);
}

struct sigaction g_old_int, g_old_term;

std::uint64_t fnv1a(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (const unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

int env_count(const char* name) {
  const char* v = std::getenv(name);
  return v == nullptr ? 0 : std::atoi(v);
}

// The first key whose values differ between the two identities, as "KEY: A, B".
std::string identity_difference(const nlohmann::json& have, const nlohmann::json& want) {
  for (const auto& [key, value] : want.items()) {
    if (!have.contains(key)) return key + ": absent, " + value.dump();
    if (have[key] != value) return key + ": " + have[key].dump() + ", " + value.dump();
  }
  for (const auto& [key, value] : have.items())
    if (!want.contains(key)) return key + ": " + value.dump() + ", absent";
  return "";
}

}  // namespace

StopOnSignal::StopOnSignal() {
  g_stop.store(0);
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &g_old_int);
  sigaction(SIGTERM, &sa, &g_old_term);
}

StopOnSignal::~StopOnSignal() {
  sigaction(SIGINT, &g_old_int, nullptr);
  sigaction(SIGTERM, &g_old_term, nullptr);
  g_stop.store(0);
}

int stop_signal() {
  return g_stop.load();
}

std::string signal_name(int signo) {
  if (signo == SIGINT) return "SIGINT";
  if (signo == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(signo);
}

std::string journal_line(const std::string& key, const std::string& payload) {
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(fnv1a(payload)));
  return key + " " + std::to_string(payload.size()) + " " + hash + " " + payload + "\n";
}

bool parse_journal_line(const std::string& line, JournalRecord& out) {
  const std::size_t a = line.find(' ');
  const std::size_t b = a == std::string::npos ? a : line.find(' ', a + 1);
  const std::size_t c = b == std::string::npos ? b : line.find(' ', b + 1);
  if (c == std::string::npos || a == 0) return false;
  const std::string length = line.substr(a + 1, b - a - 1);
  if (length.empty() || length.size() > 12 ||
      length.find_first_not_of("0123456789") != std::string::npos)
    return false;
  JournalRecord r{line.substr(0, a), line.substr(c + 1)};
  if (r.payload.size() != std::stoull(length)) return false;
  if (journal_line(r.key, r.payload) != line + "\n") return false;  // the hash
  out = std::move(r);
  return true;
}

std::string double_bits(double v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx",
                static_cast<unsigned long long>(std::bit_cast<std::uint64_t>(v)));
  return buf;
}

double bits_double(const std::string& hex) {
  return std::bit_cast<double>(static_cast<std::uint64_t>(std::stoull(hex, nullptr, 16)));
}

RunJournal::RunJournal(const std::string& dir, const nlohmann::json& identity,
                       const std::vector<std::string>& argv)
    : dir_(dir), argv_(argv) {
  std::filesystem::create_directories(dir);
  header_ = journal_line(kHeaderKey, nlohmann::json{{"identity", identity}, {"argv", argv}}.dump());
  write_text_file(path(), header_);
  open_for_append();
}

RunJournal RunJournal::resume(const std::string& dir, const nlohmann::json& identity) {
  RunJournal j;
  j.dir_ = dir;
  if (!std::filesystem::is_regular_file(j.path()))
    throw std::runtime_error("--resume '" + dir + "': no " + kFileName +
                             " (not a run folder, or one written without --out-dir)");
  const std::string text = slurp(j.path());
  std::size_t at = 0, good_end = 0;
  for (int n = 0; at < text.size(); ++n) {
    const std::size_t nl = text.find('\n', at);
    JournalRecord r;
    const bool whole = nl != std::string::npos && parse_journal_line(text.substr(at, nl - at), r);
    if (!whole && (nl == std::string::npos || nl + 1 == text.size()) && n > 0) {
      j.torn_ = true;  // the last record, cut short by a kill: dropped
      break;
    }
    if (!whole || (n == 0) != (r.key == kHeaderKey))
      throw std::runtime_error("--resume '" + dir + "': " + kFileName + " is damaged at line " +
                               std::to_string(n + 1));
    if (n == 0) {
      const nlohmann::json h = nlohmann::json::parse(r.payload);
      if (const std::string d = identity_difference(h.at("identity"), identity); !d.empty())
        throw std::runtime_error(
            "--resume '" + dir +
            "': the folder holds another run (its value, this command's: " + d + ")");
      j.header_ = text.substr(0, nl + 1);
      j.argv_ = h.at("argv").get<std::vector<std::string>>();
    } else {
      j.records_.push_back(std::move(r));
    }
    at = good_end = nl + 1;
  }
  if (j.torn_) std::filesystem::resize_file(j.path(), good_end);
  j.open_for_append();
  return j;
}

RunJournal::RunJournal(RunJournal&& o) noexcept
    : dir_(std::move(o.dir_)),
      header_(std::move(o.header_)),
      argv_(std::move(o.argv_)),
      records_(std::move(o.records_)),
      torn_(o.torn_),
      fd_(o.fd_),
      appended_(o.appended_),
      kill_at_(o.kill_at_),
      signal_at_(o.signal_at_) {
  o.fd_ = -1;
}

RunJournal::~RunJournal() {
  if (fd_ >= 0) ::close(fd_);
}

std::string RunJournal::path() const {
  return run_file(dir_, kFileName);
}

void RunJournal::open_for_append() {
  fd_ = ::open(path().c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (fd_ < 0) throw std::runtime_error("cannot append to " + path());
  kill_at_ = env_count("SAARCOR_TEST_JOURNAL_KILL");
  signal_at_ = env_count("SAARCOR_TEST_JOURNAL_SIGNAL");
}

void RunJournal::append(const std::string& key, const std::string& payload) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const std::string line = journal_line(key, payload);
  ++appended_;
  const std::size_t bytes = appended_ == kill_at_ ? line.size() / 2 : line.size();
  for (std::size_t done = 0; done < bytes;) {
    const ssize_t n = ::write(fd_, line.data() + done, bytes - done);
    if (n <= 0) throw std::runtime_error("cannot append to " + path());
    done += static_cast<std::size_t>(n);
  }
  ::fdatasync(fd_);
  if (appended_ == kill_at_) std::raise(SIGKILL);
  records_.push_back({key, payload});
  if (appended_ == signal_at_) std::raise(SIGTERM);
}

void RunJournal::seal() {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::vector<JournalRecord> sorted = records_;
  std::ranges::stable_sort(sorted, {}, &JournalRecord::key);
  std::string text = header_;
  for (const JournalRecord& r : sorted)
    text += journal_line(r.key, r.payload);
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  write_text_file(path(), text);
}

}  // namespace saarcor
