// The host bus (paper section 4: the prototype sits on a PCI board; DESIGN.md section 6;
// DIGEST D40: upload at a configurable bandwidth, default 132 MB/s = 32-bit PCI at 33 MHz).
//
// The host queues words to upload (between frames: upload() is called between kernel runs, not
// from a module's evaluate); the bus sends them to the memory controller as write bursts of up
// to `burst_words` words, no faster than the configured bandwidth: a burst of w words may leave
// in cycle t once the credit accrued over cycles t0..t (t0 = the cycle the queue became
// non-empty) covers all bytes sent so far plus 4w. Traffic is counted under its own client.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "hw/kernel.h"
#include "memif/memory_controller.h"

namespace saarcor::memif {

struct HostBusConfig {
  double mb_per_s = 132.0;   // MB = 2^20 bytes (D39)
  double clock_hz = 90.0e6;  // the modelled core clock
  int burst_words = 4;       // 1..kMaxRequestWords
};

class HostBus : public hw::Module {
 public:
  // Throws std::runtime_error for a bad configuration.
  HostBus(hw::Kernel& kernel, std::string name, MemoryController& controller,
          HostBusConfig config = {});

  // Throws std::runtime_error (one line) if the configuration is refused; returns the name.
  static std::string check(std::string name, const HostBusConfig& config);

  // Queues words for bank `bank` from word `offset` on. Throws std::runtime_error (one line) if
  // the range lies outside the bank.
  void upload(int bank, std::uint32_t offset, const std::vector<std::uint32_t>& words);
  bool idle() const { return queue_.empty(); }
  std::uint64_t bytes_sent() const { return sent_->value; }
  std::uint16_t client() const { return client_; }

  int evaluate() override;
  std::uint64_t next_wakeup(std::uint64_t now) const override;
  std::string dump_state() const override;

 private:
  struct Burst {
    int bank;
    std::uint32_t offset;
    int words;
    std::array<std::uint32_t, kMaxRequestWords> data;
  };
  std::uint64_t earliest_send() const;  // cycle at which the front burst has enough credit

  MemoryController& controller_;
  MemoryController::Port& port_;
  std::uint16_t client_;
  HostBusConfig config_;
  std::uint64_t bytes_per_second_;  // bandwidth
  std::uint64_t clock_;             // cycles per second
  std::deque<Burst> queue_;
  std::uint64_t start_ = 0;  // t0
  std::uint64_t spent_ = 0;  // bytes sent since t0
  hw::Counter* sent_;
};

}  // namespace saarcor::memif
