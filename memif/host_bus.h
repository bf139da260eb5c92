// The host bus (paper section 4: the prototype sits on a PCI board; docs/memif.md;
// decision D40: upload at a configurable bandwidth, default 132 MB/s = 32-bit PCI at 33 MHz).
//
// The host queues words to upload (between frames: upload() is called between kernel runs, not
// from a module's evaluate); the bus sends them to the memory controller as write bursts of up
// to `burst_words` words, no faster than the configured bandwidth: a burst of w words may leave
// in cycle t once the credit accrued over cycles t0..t (t0 = the cycle the queue became
// non-empty) covers all bytes sent so far plus 4w. Traffic is counted under its own client.
//
// Frame sequences (paper section 5: "uploading changes to the scene between frames ... can be
// performed in parallel to rendering"; docs/frames.md): while a frame renders, the host uploads
// the next frame's changes. That is safe only into memory the frame in flight does not read, so
// the bus can be told which words those are (protect) and refuses an upload into them; the next
// frame's registers travel over the same bus (upload_registers) into the chip's shadow registers,
// which the frame swap latches.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "hw/kernel.h"
#include "memif/memory_controller.h"

namespace saarcor::memif {

// What the host sends while a frame renders: runs of SRAM words, the next frame's registers, and
// the words the frame in flight reads (protected for the upload's duration).
struct HostUpload {
  std::vector<UploadRun> runs;
  std::uint32_t register_words = 0;
  std::vector<BankRange> frame_reads;
  std::uint64_t sram_bytes() const {
    std::uint64_t n = 0;
    for (const UploadRun& r : runs)
      n += 4ull * r.words.size();
    return n;
  }
  std::uint64_t bytes() const { return sram_bytes() + 4ull * register_words; }
};

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
  // the range lies outside the bank or overlaps a protected range.
  void upload(int bank, std::uint32_t offset, const std::vector<std::uint32_t>& words);
  // Queues every run of `u` and its registers, after protecting u.frame_reads (throws, queueing
  // nothing, when a run overlaps one of them).
  void upload(const HostUpload& u);
  // The words the frame in flight reads: an upload() into any of them is refused from now on
  // (replaces the previous set; an empty set lifts the protection).
  void protect(std::vector<BankRange> ranges);
  // Queues `words` words for the chip's frame registers: they take bus time like SRAM words and
  // are counted in bytes_sent(), but go to no bank (the frame swap latches them).
  void upload_registers(std::uint32_t words);
  bool idle() const { return queue_.empty(); }
  // Every queued word has left the bus and every SRAM word is stored in its bank (the controller
  // counts a write under the bus's client when it stores it).
  bool stored() const;
  std::uint64_t bytes_sent() const { return sent_->value; }
  std::uint64_t register_bytes_sent() const { return register_sent_; }
  std::uint16_t client() const { return client_; }

  int evaluate() override;
  std::uint64_t next_wakeup(std::uint64_t now) const override;
  std::string dump_state() const override;

 private:
  struct Burst {
    int bank;  // kRegisters: the chip's register file, not a bank
    std::uint32_t offset;
    int words;
    std::array<std::uint32_t, kMaxRequestWords> data;
  };
  static constexpr int kRegisters = -1;
  std::uint64_t earliest_send() const;  // cycle at which the front burst has enough credit
  void check_protected(int bank, std::uint32_t offset, std::size_t words) const;

  MemoryController& controller_;
  MemoryController::Port& port_;
  std::uint16_t client_;
  HostBusConfig config_;
  std::uint64_t bytes_per_second_;  // bandwidth
  std::uint64_t clock_;             // cycles per second
  std::deque<Burst> queue_;
  std::uint64_t start_ = 0;  // t0
  std::uint64_t spent_ = 0;  // bytes sent since t0
  std::uint64_t register_sent_ = 0;
  std::vector<BankRange> protected_;
  hw::Counter* sent_;
};

}  // namespace saarcor::memif
