// The host bus: rate-limited uploads into the SRAM banks (paper section 4; decision D40).
#include "memif/host_bus.h"

#include <cmath>
#include <stdexcept>

namespace saarcor::memif {

std::string HostBus::check(std::string name, const HostBusConfig& config) {
  if (!(config.mb_per_s > 0) || !std::isfinite(config.mb_per_s)) {
    throw std::runtime_error("host bus '" + name + "': mb_per_s must be > 0");
  }
  if (!(config.clock_hz >= 1) || !std::isfinite(config.clock_hz)) {
    throw std::runtime_error("host bus '" + name + "': clock_hz must be >= 1");
  }
  if (config.burst_words < 1 || config.burst_words > kMaxRequestWords) {
    throw std::runtime_error("host bus '" + name + "': burst_words must be 1.." +
                             std::to_string(kMaxRequestWords));
  }
  return name;
}

HostBus::HostBus(hw::Kernel& kernel, std::string name, MemoryController& controller,
                 HostBusConfig config)
    : hw::Module(kernel, check(std::move(name), config)),
      controller_(controller),
      port_(controller.add_port(this->name())),
      client_(controller.add_client(this->name())),
      config_(config) {
  bytes_per_second_ = static_cast<std::uint64_t>(std::llround(config.mb_per_s * 1048576.0));
  if (bytes_per_second_ == 0) bytes_per_second_ = 1;
  clock_ = static_cast<std::uint64_t>(std::llround(config.clock_hz));
  sleep_when_idle();  // upload() comes between runs, and every run starts by waking all modules
  produces(port_.requests);
  sent_ =
      &stats().counter(this->name() + ".bytes_uploaded", "bytes", "bytes sent over the host bus");
}

void HostBus::check_protected(int bank, std::uint32_t offset, std::size_t words) const {
  if (bank < 0 || bank >= kNumBanks ||
      static_cast<std::uint64_t>(offset) + words > controller_.image().bank(bank).size()) {
    throw std::runtime_error("host bus: upload of " + std::to_string(words) + " words at bank " +
                             std::to_string(bank) + " offset " + std::to_string(offset) +
                             " lies outside the bank");
  }
  const std::uint64_t end = static_cast<std::uint64_t>(offset) + words;
  for (const BankRange& r : protected_) {
    if (r.bank != bank || words == 0 || end <= r.begin || offset >= r.end) continue;
    throw std::runtime_error("host bus: upload of " + std::to_string(words) + " words at bank " +
                             std::to_string(bank) + " words " + std::to_string(offset) + ".." +
                             std::to_string(end - 1) + " overlaps " + r.what + " (bank " +
                             std::to_string(r.bank) + " words " + std::to_string(r.begin) + ".." +
                             std::to_string(r.end - 1) + "), which the frame in flight reads");
  }
}

void HostBus::protect(std::vector<BankRange> ranges) {
  protected_ = std::move(ranges);
}

void HostBus::upload(const HostUpload& u) {
  protect(u.frame_reads);
  for (const UploadRun& r : u.runs)  // all checked before anything is queued
    check_protected(r.bank, r.offset, r.words.size());
  for (const UploadRun& r : u.runs)
    upload(r.bank, r.offset, r.words);
  upload_registers(u.register_words);
}

void HostBus::upload_registers(std::uint32_t words) {
  if (words == 0) return;
  if (queue_.empty()) {
    start_ = now();
    spent_ = 0;
  }
  for (std::uint32_t i = 0; i < words;) {
    Burst b{kRegisters, 0, 0, {}};
    while (b.words < config_.burst_words && i < words) {
      ++b.words;
      ++i;
    }
    queue_.push_back(b);
  }
}

bool HostBus::stored() const {
  return queue_.empty() && controller_.client_bytes(client_) == sent_->value - register_sent_;
}

void HostBus::upload(int bank, std::uint32_t offset, const std::vector<std::uint32_t>& words) {
  check_protected(bank, offset, words.size());
  controller_.close_lanes();  // the upload's writes may reach a lane's bank
  if (queue_.empty()) {
    start_ = now();
    spent_ = 0;
  }
  for (std::size_t i = 0; i < words.size();) {
    Burst b{bank, offset + static_cast<std::uint32_t>(i), 0, {}};
    while (b.words < config_.burst_words && i < words.size()) {
      b.data[static_cast<std::size_t>(b.words++)] = words[i++];
    }
    queue_.push_back(b);
  }
}

std::uint64_t HostBus::earliest_send() const {
  // Credit after cycle t (inclusive): (t - start + 1) * B / clock bytes. Need >= spent + cost.
  const std::uint64_t need =
      (spent_ + 4u * static_cast<std::uint64_t>(queue_.front().words)) * clock_;
  const std::uint64_t cycles = (need + bytes_per_second_ - 1) / bytes_per_second_;
  return start_ + (cycles == 0 ? 0 : cycles - 1);
}

int HostBus::evaluate() {
  if (queue_.empty() || now() < earliest_send()) return 0;
  if (queue_.front().bank == kRegisters) {  // into the chip's shadow registers, not a bank
    const std::uint64_t bytes = 4u * static_cast<std::uint64_t>(queue_.front().words);
    spent_ += bytes;
    *sent_ += bytes;
    register_sent_ += bytes;
    queue_.pop_front();
    return 1;
  }
  if (!port_.requests.can_push()) {
    stall();
    return 0;
  }
  const Burst& b = queue_.front();
  MemRequest r;
  r.client = client_;
  r.bank = static_cast<std::uint8_t>(b.bank);
  r.offset = b.offset;
  r.words = static_cast<std::uint8_t>(b.words);
  r.write = true;
  r.data = b.data;
  port_.requests.push(r);
  spent_ += 4u * static_cast<std::uint64_t>(b.words);
  *sent_ += 4u * static_cast<std::uint64_t>(b.words);
  queue_.pop_front();
  return 1;
}

std::uint64_t HostBus::next_wakeup(std::uint64_t now) const {
  if (queue_.empty()) return hw::kNever;
  const std::uint64_t t = earliest_send();
  return t > now ? t : hw::kNever;  // ready but blocked: only the port channel can wake it
}

std::string HostBus::dump_state() const {
  return std::to_string(queue_.size()) + " bursts queued, " + std::to_string(spent_) +
         " bytes sent since cycle " + std::to_string(start_);
}

}  // namespace saarcor::memif
