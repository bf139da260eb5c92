// The SaarCOR chip as a SystemC TLM-2.0 target (docs/systemc.md).
#include "testbench/systemc/chip_tlm.h"

#include <cstring>
#include <exception>
#include <iostream>
#include <stdexcept>
#include <utility>
#include <vector>

namespace saarcor::vp {
namespace {

ChipConfig checked(ChipConfig c) {
  units::check_cycle_params(c.params);
  if (c.bank_words == 0 || 4ull * c.bank_words > kMaxBankBytes)
    throw std::runtime_error("SystemC chip: a bank of " + std::to_string(c.bank_words) +
                             " words does not fit the map's 64 MB bank windows");
  if (c.format != ff::kFp24 && c.format != ff::Format{7, 23})
    throw std::runtime_error(
        "SystemC chip: the cycle model is built for fp24 (e7m16) and e7m23, "
        "not " +
        ff::format_name(c.format));
  return c;
}

bool empty(const memif::HostUpload& u) {
  return u.runs.empty() && u.register_words == 0;
}

}  // namespace

ChipTlm::ChipTlm(sc_core::sc_module_name name, ChipConfig config)
    : sc_core::sc_module(name),
      socket("socket"),
      irq("irq"),
      config_(checked(std::move(config))),
      board_(config_.format, config_.bank_words) {
  socket.register_b_transport(this, &ChipTlm::b_transport);
  socket.register_get_direct_mem_ptr(this, &ChipTlm::get_direct_mem_ptr);
  SC_HAS_PROCESS(ChipTlm);
  SC_THREAD(frame_thread);
  // The line is driven by one process (a signal takes one driver); START, which comes in the
  // initiator's process, and the frame's end only tell it to.
  SC_METHOD(drive_irq);
  sensitive << irq_changed_;
  dont_initialize();
}

void ChipTlm::drive_irq() {
  if (irq.size() > 0) irq->write(done_);
}

sc_core::sc_time ChipTlm::cycles_time(std::uint64_t cycles) const {
  return sc_core::sc_time(static_cast<double>(cycles) / config_.params.clock_mhz, sc_core::SC_US);
}

void ChipTlm::b_transport(tlm::tlm_generic_payload& tx, sc_core::sc_time& delay) {
  // Writes are posted (the host bus model times them) and reads are not timed: the delay stays.
  tx.set_response_status(access(tx, sc_core::sc_time_stamp() + delay));
}

// DMI is refused: a pointer into the banks would bypass the host bus's timing, and a frame
// buffer holds its frame only from the frame's end on.
bool ChipTlm::get_direct_mem_ptr(tlm::tlm_generic_payload&, tlm::tlm_dmi& dmi) {
  dmi.allow_none();
  return false;
}

void ChipTlm::refuse(const std::string& message) {
  error_ = message;
  std::cerr << name() << ": " << message << "\n";
}

tlm::tlm_response_status ChipTlm::access(tlm::tlm_generic_payload& tx, const sc_core::sc_time& at) {
  if (tx.is_read() == tx.is_write()) return tlm::TLM_OK_RESPONSE;  // TLM_IGNORE_COMMAND
  if (tx.get_byte_enable_ptr() != nullptr) {
    refuse("byte enables are not supported: the chip takes whole 32-bit words");
    return tlm::TLM_BYTE_ENABLE_ERROR_RESPONSE;
  }
  if (tx.get_streaming_width() < tx.get_data_length()) {
    refuse("streaming transactions are not supported: each word has its own address");
    return tlm::TLM_BURST_ERROR_RESPONSE;
  }
  const Decoded d = decode_address(tx.get_address(), tx.get_data_length(), config_.bank_words);
  if (!d.error.empty()) {
    refuse(d.error);
    return d.length_error ? tlm::TLM_BURST_ERROR_RESPONSE : tlm::TLM_ADDRESS_ERROR_RESPONSE;
  }
  std::vector<std::uint32_t> w(d.words);
  if (tx.is_read()) {
    const tlm::tlm_response_status s = read(d, w.data());
    if (s == tlm::TLM_OK_RESPONSE) std::memcpy(tx.get_data_ptr(), w.data(), 4ull * d.words);
    return s;
  }
  std::memcpy(w.data(), tx.get_data_ptr(), 4ull * d.words);
  switch (d.region) {
    case Decoded::Region::kControl:
      return write_control(d, w.data(), at);
    case Decoded::Region::kFrameRegisters:
      write_frame_registers(d, w.data());
      return tlm::TLM_OK_RESPONSE;
    case Decoded::Region::kBank:
      write_bank(d, w.data());
      return tlm::TLM_OK_RESPONSE;
  }
  return tlm::TLM_ADDRESS_ERROR_RESPONSE;
}

// The writes go with the next START (stored alone before its frame) unless a frame has been
// started and not yet begun: then they are its upload, beside it.
memif::HostUpload& ChipTlm::posting() {
  return state_ == State::kStarted ? beside_ : posted_;
}

void ChipTlm::write_bank(const Decoded& d, const std::uint32_t* w) {
  memif::UploadRun run{d.bank, d.word, std::vector<std::uint32_t>(w, w + d.words)};
  // Words posted while no frame waits to begin are visible at once; START stores them again
  // over the host bus (the same values) to time them.
  if (state_ != State::kStarted)
    std::copy(run.words.begin(), run.words.end(), board_.bank(d.bank).begin() + d.word);
  if (d.bank >= memif::kShadingBank) scene_written_ = true;
  posting().runs.push_back(std::move(run));
}

void ChipTlm::write_frame_registers(const Decoded& d, const std::uint32_t* w) {
  std::copy(w, w + d.words, shadow_.begin() + d.word);
  posting().register_words += d.words;
}

tlm::tlm_response_status ChipTlm::write_control(const Decoded& d, const std::uint32_t* w,
                                                const sc_core::sc_time& at) {
  if (d.word != kControl || d.words != 1) {
    refuse("the control block is read-only but for CONTROL (0x00000004), written alone");
    return tlm::TLM_COMMAND_ERROR_RESPONSE;
  }
  if ((w[0] & ~kStart) != 0) {
    refuse("CONTROL takes bit 0 (START) only, not " + std::to_string(w[0]));
    return tlm::TLM_GENERIC_ERROR_RESPONSE;
  }
  return w[0] == kStart ? start(at) : tlm::TLM_OK_RESPONSE;
}

// Why START cannot begin a frame with the registers and banks as they are ("" if it can).
std::string ChipTlm::check_start() const {
  if (state_ != State::kIdle)
    return "START while a frame is in flight (wait for its end: the frame-end event, the irq or "
           "STATUS)";
  if (!scene_written_)
    return "START with no scene: no word of the shading and scene banks (2-5) has been written";
  memif::FrameRegisters r;
  memif::SceneRegions g;
  decode_frame_registers(shadow_, r, g);
  if (r.width == 0 || r.height == 0)
    return "START with no frame: the frame registers hold a " + std::to_string(r.width) + "x" +
           std::to_string(r.height) + " frame";
  if (r.frame_bank != memif::kFrameBank0 && r.frame_bank != memif::kFrameBank1)
    return "START with frame_bank " + std::to_string(r.frame_bank) +
           ": the frame buffers are banks 0 and 1";
  if (std::uint64_t{r.width} * r.height > config_.bank_words)
    return "START with a " + std::to_string(r.width) + "x" + std::to_string(r.height) +
           " frame: a frame-buffer bank holds " + std::to_string(config_.bank_words) + " pixels";
  return "";
}

tlm::tlm_response_status ChipTlm::start(const sc_core::sc_time& at) {
  if (const std::string why = check_start(); !why.empty()) {
    refuse(why);
    return tlm::TLM_GENERIC_ERROR_RESPONSE;
  }
  decode_frame_registers(shadow_, board_.registers(), board_.regions());  // the swap latches them
  state_ = State::kStarted;
  done_ = failed_ = false;
  start_requested_ = at;
  irq_changed_.notify(sc_core::SC_ZERO_TIME);
  start_.notify(at - sc_core::sc_time_stamp());
  return tlm::TLM_OK_RESPONSE;
}

tlm::tlm_response_status ChipTlm::read(const Decoded& d, std::uint32_t* w) {
  switch (d.region) {
    case Decoded::Region::kControl:
      for (std::uint32_t i = 0; i < d.words; ++i)
        w[i] = control_word(d.word + i);
      break;
    case Decoded::Region::kFrameRegisters:
      std::copy(shadow_.begin() + d.word, shadow_.begin() + d.word + d.words, w);
      break;
    case Decoded::Region::kBank:
      if (state_ != State::kIdle && d.bank == static_cast<int>(board_.registers().frame_bank)) {
        refuse("bank " + std::to_string(d.bank) +
               " is the frame buffer of the frame in flight: read it after the frame's end");
        return tlm::TLM_GENERIC_ERROR_RESPONSE;
      }
      std::copy(board_.bank(d.bank).begin() + d.word,
                board_.bank(d.bank).begin() + d.word + d.words, w);
      break;
  }
  return tlm::TLM_OK_RESPONSE;
}

std::uint32_t ChipTlm::control_word(std::uint32_t index) const {
  const CycleFrame* f = frames_.empty() ? nullptr : &frames_.back().frame;
  const std::uint64_t load = frames_.empty() ? 0 : frames_.back().load_cycles;
  const auto half = [](std::uint64_t v, bool hi) {
    return static_cast<std::uint32_t>(hi ? v >> 32 : v & 0xFFFF'FFFFu);
  };
  const bool hi = index % 2 == 1;
  switch (index) {
    case kId:
      return kChipId;
    case kStatus:
      return (state_ != State::kIdle ? kStatusBusy : 0u) | (done_ ? kStatusDone : 0u) |
             (failed_ ? kStatusError : 0u);
    case kFrames:
      return static_cast<std::uint32_t>(frames_.size());
    case kCyclesLo:
    case kCyclesHi:
      return f ? half(f->cycles, hi) : 0u;
    case kUploadLo:
    case kUploadHi:
      return f ? half(f->upload_cycles, hi) : 0u;
    case kLoadLo:
    case kLoadHi:
      return half(load, hi);
    case kRaysLo:
    case kRaysHi:
      return f ? half(f->rays, hi) : 0u;
    default:
      return 0u;  // CONTROL reads 0
  }
}

// The frame: the writes posted before START stored alone, then the cycle model's frame with the
// writes posted after START beside it.
void ChipTlm::render(ChipFrame& f) {
  memif::HostUpload load = std::exchange(posted_, {});
  const memif::HostUpload beside = std::exchange(beside_, {});
  state_ = State::kRendering;
  f.load_cycles = empty(load) ? 0 : run_upload(board_, config_.params, std::move(load));
  f.start = sc_core::sc_time_stamp() + cycles_time(f.load_cycles);
  f.frame = run_cycle(board_, config_.params, config_.run, beside);
  f.end = f.start + cycles_time(f.frame.cycles);
  if (!empty(beside)) upload_stored_ = f.start + cycles_time(f.frame.upload_cycles);
}

void ChipTlm::frame_thread() {
  for (;;) {
    sc_core::wait(start_);
    ChipFrame f;
    f.start_requested = start_requested_;
    // The previous frame's upload still on the bus: the frame waits for its last word.
    if (sc_core::sc_time_stamp() < upload_stored_)
      sc_core::wait(upload_stored_ - sc_core::sc_time_stamp());
    bool failed = false;
    try {
      render(f);
    } catch (const std::exception& e) {  // the cycle model's one-line errors (watchdog, image)
      refuse("frame " + std::to_string(frames_.size()) + ": " + e.what());
      failed = true;
    }
    if (!failed) sc_core::wait(f.end - sc_core::sc_time_stamp());
    state_ = State::kIdle;
    done_ = true;
    failed_ = failed;
    if (!failed) frames_.push_back(std::move(f));
    irq_changed_.notify(sc_core::SC_ZERO_TIME);
    frame_end_.notify(sc_core::SC_ZERO_TIME);
  }
}

}  // namespace saarcor::vp
