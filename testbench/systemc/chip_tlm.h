// The SaarCOR chip as a SystemC TLM-2.0 target (docs/systemc.md): the cycle model's chip
// (testbench/chip.h) behind a loosely-timed target socket for the host side, as the prototype sits
// on the PCI bus (paper section 4). The host writes the SRAM banks and the frame registers and
// starts a frame; the chip renders it with the cycle model and signals the frame's end at the
// modelled time: sc_time_stamp() at the frame's start + cycles / clock_mhz.
//
// Writes are posted into the chip's host bus (memif/host_bus.h), which times them as the frame
// sequence does (docs/frames.md): the writes posted while no frame is in flight are stored, with
// nothing rendering, when START comes and the frame begins once they are; the writes posted
// after START, before the chip begins the frame (the initiator's quantum: in loosely-timed terms,
// before it synchronises), are the next frame's upload and go to the banks beside the frame,
// competing with its reads. Reads are not timed. DMI is refused: every write must pass the host
// bus model, and a frame buffer holds the frame only from the frame's end on.
#pragma once

#include <tlm_utils/simple_target_socket.h>
#include <cstdint>
#include <string>
#include <systemc>
#include <tlm>
#include <vector>

#include "memif/host_bus.h"
#include "memif/image_format.h"
#include "testbench/chip.h"
#include "testbench/systemc/chip_registers.h"
#include "units/cycle_params.h"

namespace saarcor::vp {

struct ChipConfig {
  units::CycleParams params;      // the chip's configuration (clock_mhz, host bus, units)
  CycleRunOptions run;            // shading options and how the thread programs run
  ff::Format format = ff::kFp24;  // the datapaths' format (fp24; e7m23 for the width study)
  std::uint32_t bank_words = memif::kDefaultBankWords;  // words per SRAM bank
};

// One frame as the chip ran it: its SystemC times and the cycle model's frame.
struct ChipFrame {
  sc_core::sc_time start_requested;  // when START was written
  sc_core::sc_time start, end;       // the frame's render: end = start + cycles at clock_mhz
  std::uint64_t load_cycles = 0;     // the writes posted before START, stored alone first
  CycleFrame frame;                  // cycles, upload_cycles, figures, image
};

class ChipTlm : public sc_core::sc_module {
 public:
  tlm_utils::simple_target_socket<ChipTlm> socket;
  // The interrupt line: high from a frame's end until the next START. Optional to bind.
  sc_core::sc_port<sc_core::sc_signal_inout_if<bool>, 1, sc_core::SC_ZERO_OR_MORE_BOUND> irq;

  // Throws std::runtime_error (one line) for a configuration the cycle model refuses.
  ChipTlm(sc_core::sc_module_name name, ChipConfig config);

  // Notified at each frame's end (and at a failed frame's start, with kStatusError set).
  const sc_core::sc_event& frame_end_event() const { return frame_end_; }
  // The frames finished so far, in order.
  const std::vector<ChipFrame>& frames() const { return frames_; }
  // The last refused transaction's or failed frame's message ("" if none).
  const std::string& last_error() const { return error_; }
  // The chip's SRAM as it is now (the frame buffers hold the frames that ended).
  const memif::MemoryImage& memory() const { return board_; }
  // cycles at clock_mhz, rounded to the simulator's time resolution.
  sc_core::sc_time cycles_time(std::uint64_t cycles) const;

 private:
  enum class State { kIdle, kStarted, kRendering };
  void b_transport(tlm::tlm_generic_payload& tx, sc_core::sc_time& delay);
  bool get_direct_mem_ptr(tlm::tlm_generic_payload& tx, tlm::tlm_dmi& dmi);
  tlm::tlm_response_status access(tlm::tlm_generic_payload& tx, const sc_core::sc_time& at);
  tlm::tlm_response_status write_control(const Decoded& d, const std::uint32_t* w,
                                         const sc_core::sc_time& at);
  tlm::tlm_response_status start(const sc_core::sc_time& at);
  void write_bank(const Decoded& d, const std::uint32_t* w);
  void write_frame_registers(const Decoded& d, const std::uint32_t* w);
  tlm::tlm_response_status read(const Decoded& d, std::uint32_t* w);
  std::uint32_t control_word(std::uint32_t index) const;
  std::string check_start() const;
  void refuse(const std::string& message);
  void frame_thread();
  void drive_irq();
  void render(ChipFrame& f);
  memif::HostUpload& posting();

  ChipConfig config_;
  memif::MemoryImage board_;
  FrameRegisterWords shadow_{};  // what the host wrote; START latches it
  memif::HostUpload posted_;     // posted while idle: stored alone at START
  memif::HostUpload beside_;     // posted after START before the frame began: beside the frame
  State state_ = State::kIdle;
  sc_core::sc_time start_requested_;
  sc_core::sc_time upload_stored_ = sc_core::SC_ZERO_TIME;  // the last beside upload is stored
  bool scene_written_ = false;  // a word of banks 2-5 has been written since reset
  bool done_ = false, failed_ = false;
  sc_core::sc_event start_, frame_end_, irq_changed_;
  std::vector<ChipFrame> frames_;
  std::string error_;
};

}  // namespace saarcor::vp
