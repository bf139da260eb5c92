// The chip's TLM-2.0 target (chip_tlm.h): bad transactions refused with the TLM response each
// deserves and one message, register reads, DMI refused, and a frame against the cycle model run
// directly on the same image, at the modelled time. A process elaborates one platform, so one
// simulation (Script below, run once per process) serves every test here.
#include "testbench/systemc/chip_tlm.h"

#include <gtest/gtest.h>

#include <tlm_utils/simple_initiator_socket.h>
#include <cmath>
#include <string>
#include <vector>

#include "host/frame_upload.h"
#include "testbench/render_cmd.h"

namespace saarcor::vp {
namespace {

struct Refusal {
  tlm::tlm_response_status status = tlm::TLM_INCOMPLETE_RESPONSE;
  std::string message;
};

// What the scripted host saw.
struct Seen {
  std::uint32_t id = 0;
  Refusal no_scene, outside, three_bytes, unaligned, read_only, past_bank, byte_enable, streaming,
      unknown_bits, busy_start, fb_in_flight;
  bool dmi = true;
  FrameRegisterWords registers_read{};
  std::uint32_t status_in_flight = 0, status_after = 0;
  bool irq_in_flight = true, irq_after = false;
  std::uint64_t cycles = 0, load_cycles = 0;
  sc_core::sc_time start_written, end_seen;
  std::vector<std::uint32_t> frame_buffer;
};

// A small frame of the animated scene: its image built as `saarcor render` builds it.
PreparedScene scene() {
  RenderSettings s;
  s.res = {16, 12};
  return prepare_scene("builtin:dynamic", s);
}

struct Script : sc_core::sc_module {
  tlm_utils::simple_initiator_socket<Script> socket{"socket"};
  sc_core::sc_signal<bool> irq{"irq"};
  const ChipTlm& chip;
  const PreparedScene& prep;
  Seen seen;

  Script(sc_core::sc_module_name n, const ChipTlm& c, const PreparedScene& p)
      : sc_core::sc_module(n), chip(c), prep(p) {
    SC_HAS_PROCESS(Script);
    SC_THREAD(run);
  }

  tlm::tlm_response_status go(tlm::tlm_command cmd, std::uint64_t address, std::uint32_t* words,
                              unsigned bytes, unsigned char* byte_enable = nullptr,
                              unsigned streaming = 0) {
    tlm::tlm_generic_payload tx;
    sc_core::sc_time delay = sc_core::SC_ZERO_TIME;
    tx.set_command(cmd);
    tx.set_address(address);
    tx.set_data_ptr(reinterpret_cast<unsigned char*>(words));
    tx.set_data_length(bytes);
    tx.set_streaming_width(streaming == 0 ? bytes : streaming);
    tx.set_byte_enable_ptr(byte_enable);
    tx.set_byte_enable_length(byte_enable != nullptr ? 4 : 0);
    tx.set_response_status(tlm::TLM_INCOMPLETE_RESPONSE);
    socket->b_transport(tx, delay);
    return tx.get_response_status();
  }
  Refusal refused(tlm::tlm_command cmd, std::uint64_t address, std::uint32_t* words, unsigned bytes,
                  unsigned char* byte_enable = nullptr, unsigned streaming = 0) {
    Refusal r;
    r.status = go(cmd, address, words, bytes, byte_enable, streaming);
    r.message = chip.last_error();
    return r;
  }
  std::uint32_t word(std::uint64_t address) {
    std::uint32_t w = 0;
    go(tlm::TLM_READ_COMMAND, address, &w, 4);
    return w;
  }
  void write(std::uint64_t address, std::vector<std::uint32_t> w) {
    go(tlm::TLM_WRITE_COMMAND, address, w.data(), static_cast<unsigned>(4 * w.size()));
  }

  void bad_transactions() {
    std::uint32_t w[4] = {kStart, 0, 0, 0};
    const auto W = tlm::TLM_WRITE_COMMAND;
    seen.no_scene = refused(W, kControlBase + 4 * kControl, w, 4);
    seen.outside = refused(W, 0x0800'0000, w, 4);
    seen.three_bytes = refused(W, kFrameRegisterBase, w, 3);
    seen.unaligned = refused(W, kFrameRegisterBase + 2, w, 4);
    seen.read_only = refused(W, kControlBase + 4 * kStatus, w, 4);
    const std::uint32_t last = chip.memory().bank_words() - 1;
    seen.past_bank = refused(W, bank_address(2, last), w, 8);
    unsigned char enable[4] = {0xFF, 0xFF, 0, 0};
    seen.byte_enable = refused(W, kFrameRegisterBase, w, 4, enable);
    seen.streaming = refused(W, kFrameRegisterBase, w, 8, nullptr, 4);
    w[0] = 6;
    seen.unknown_bits = refused(W, kControlBase + 4 * kControl, w, 4);
    tlm::tlm_generic_payload tx;
    tlm::tlm_dmi dmi;
    tx.set_address(bank_address(2));
    seen.dmi = socket->get_direct_mem_ptr(tx, dmi);
  }

  // The scene's initial load and frame 0's registers, START, and the frame read back.
  void frame() {
    for (const memif::BankRange& r : host::data_words(prep.built)) {
      const auto& src = prep.built.image.bank(r.bank);
      write(bank_address(r.bank, r.begin), {src.begin() + r.begin, src.begin() + r.end});
    }
    const FrameRegisterWords regs =
        encode_frame_registers(prep.built.image.registers(), prep.built.image.regions());
    write(kFrameRegisterBase, {regs.begin(), regs.end()});
    go(tlm::TLM_READ_COMMAND, kFrameRegisterBase, seen.registers_read.data(), 4 * 38);
    write(kControlBase + 4 * kControl, {kStart});
    seen.start_written = sc_core::sc_time_stamp();
    std::uint32_t w = kStart;
    seen.busy_start = refused(tlm::TLM_WRITE_COMMAND, kControlBase + 4 * kControl, &w, 4);
    seen.fb_in_flight = refused(tlm::TLM_READ_COMMAND, bank_address(0), &w, 4);
    seen.status_in_flight = word(kControlBase + 4 * kStatus);
    sc_core::wait(sc_core::SC_ZERO_TIME);  // the chip begins the frame; it ends later
    seen.irq_in_flight = irq.read();
    sc_core::wait(chip.frame_end_event());
    seen.end_seen = sc_core::sc_time_stamp();
    sc_core::wait(sc_core::SC_ZERO_TIME);  // the irq signal's update
    seen.irq_after = irq.read();
    seen.status_after = word(kControlBase + 4 * kStatus);
    seen.cycles = word(kControlBase + 4 * kCyclesLo) |
                  (std::uint64_t{word(kControlBase + 4 * kCyclesHi)} << 32);
    seen.load_cycles = word(kControlBase + 4 * kLoadLo);
    const auto& r = prep.built.image.registers();
    seen.frame_buffer.resize(std::size_t{r.width} * r.height);
    go(tlm::TLM_READ_COMMAND, bank_address(0), seen.frame_buffer.data(),
       static_cast<unsigned>(4 * seen.frame_buffer.size()));
  }

  void run() {
    seen.id = word(kControlBase + 4 * kId);
    bad_transactions();
    frame();
  }
};

struct Simulation {
  PreparedScene prep = scene();
  ChipConfig config;
  Seen seen;
  std::vector<ChipFrame> frames;
  std::string last_error;
  sc_core::sc_time cycle_1, cycle_90;  // 1 and 90 cycles at the chip's clock
};

// The platform, once per process (SystemC elaborates once).
const Simulation& simulation() {
  static const Simulation s = [] {
    Simulation sim;
    ChipTlm chip("chip", sim.config);
    Script script("script", chip, sim.prep);
    script.socket.bind(chip.socket);
    chip.irq.bind(script.irq);
    sc_core::sc_start();
    sim.seen = script.seen;
    sim.frames = chip.frames();
    sim.last_error = chip.last_error();
    sim.cycle_1 = chip.cycles_time(1);
    sim.cycle_90 = chip.cycles_time(90);
    return sim;
  }();
  return s;
}

TEST(ChipTlm, RefusesBadTransactionsWithOneMessageEach) {
  const Seen& s = simulation().seen;
  EXPECT_EQ(s.id, kChipId);
  EXPECT_EQ(s.no_scene.status, tlm::TLM_GENERIC_ERROR_RESPONSE);
  EXPECT_EQ(s.no_scene.message,
            "START with no scene: no word of the shading and scene banks (2-5) has been written");
  EXPECT_EQ(s.outside.status, tlm::TLM_ADDRESS_ERROR_RESPONSE);
  EXPECT_EQ(s.outside.message, "address 0x08000000 lies outside the register map");
  EXPECT_EQ(s.three_bytes.status, tlm::TLM_BURST_ERROR_RESPONSE);
  EXPECT_EQ(s.unaligned.status, tlm::TLM_ADDRESS_ERROR_RESPONSE);
  EXPECT_EQ(s.read_only.status, tlm::TLM_COMMAND_ERROR_RESPONSE);
  EXPECT_EQ(s.read_only.message,
            "the control block is read-only but for CONTROL (0x00000004), written alone");
  // Bank 2's last word is 0x1800_0000 + 4 * (2^20 - 1) = 0x183F_FFFC; 8 bytes run past it.
  EXPECT_EQ(s.past_bank.status, tlm::TLM_ADDRESS_ERROR_RESPONSE);
  EXPECT_EQ(s.past_bank.message,
            "a transaction of 8 bytes at 0x183ffffc runs past the end of its region (0x183fffff)");
  EXPECT_EQ(s.byte_enable.status, tlm::TLM_BYTE_ENABLE_ERROR_RESPONSE);
  EXPECT_EQ(s.streaming.status, tlm::TLM_BURST_ERROR_RESPONSE);
  EXPECT_EQ(s.unknown_bits.status, tlm::TLM_GENERIC_ERROR_RESPONSE);
  EXPECT_EQ(s.unknown_bits.message, "CONTROL takes bit 0 (START) only, not 6");
  EXPECT_FALSE(s.dmi);
  EXPECT_EQ(s.busy_start.status, tlm::TLM_GENERIC_ERROR_RESPONSE);
  EXPECT_EQ(s.busy_start.message,
            "START while a frame is in flight (wait for its end: the frame-end event, the irq or "
            "STATUS)");
  EXPECT_EQ(s.fb_in_flight.status, tlm::TLM_GENERIC_ERROR_RESPONSE);
  EXPECT_EQ(s.fb_in_flight.message,
            "bank 0 is the frame buffer of the frame in flight: read it after the frame's end");
}

TEST(ChipTlm, StatusAndInterruptFollowTheFrame) {
  const Seen& s = simulation().seen;
  EXPECT_EQ(s.status_in_flight, kStatusBusy);
  EXPECT_FALSE(s.irq_in_flight);
  EXPECT_EQ(s.status_after, kStatusDone);
  EXPECT_TRUE(s.irq_after);
  const Simulation& sim = simulation();
  EXPECT_EQ(s.registers_read, encode_frame_registers(sim.prep.built.image.registers(),
                                                     sim.prep.built.image.regions()));
}

TEST(ChipTlm, FrameEqualsTheCycleModelOnTheSameImageAtTheModelledTime) {
  const Simulation& sim = simulation();
  ASSERT_EQ(sim.frames.size(), 1u) << sim.last_error;
  // The cycle model run directly: the load over the host bus alone, then the frame.
  memif::MemoryImage board(sim.prep.built.image.format(), sim.prep.built.image.bank_words());
  memif::HostUpload load;
  for (const memif::BankRange& r : host::data_words(sim.prep.built)) {
    const auto& src = sim.prep.built.image.bank(r.bank);
    load.runs.push_back({r.bank, r.begin, {src.begin() + r.begin, src.begin() + r.end}});
  }
  load.register_words = kFrameRegisterWords;
  const std::uint64_t load_cycles = run_upload(board, sim.config.params, load);
  board.registers() = sim.prep.built.image.registers();
  board.regions() = sim.prep.built.image.regions();
  const CycleFrame direct = run_cycle(board, sim.config.params, sim.config.run);
  const Seen& s = sim.seen;
  EXPECT_EQ(s.load_cycles, load_cycles);
  EXPECT_EQ(s.cycles, direct.cycles);
  ASSERT_EQ(s.frame_buffer.size(), direct.frame.pixels.size());
  for (std::size_t i = 0; i < s.frame_buffer.size(); ++i)
    for (std::size_t k = 0; k < 3; ++k)
      ASSERT_EQ((s.frame_buffer[i] >> (8 * k)) & 255u, direct.frame.rgb[3 * i + k]) << i;
  // Times at 90 MHz: a cycle is 1e6 / 90 = 11,111.1 ps, rounded to the 1 ps resolution 11,111 ps;
  // 90 cycles are 1 us. The load, then the frame, each rounded so.
  EXPECT_EQ(sim.cycle_1.value(), 11111u);
  EXPECT_EQ(sim.cycle_90, sc_core::sc_time(1, sc_core::SC_US));
  const auto ps = [](std::uint64_t cycles) {
    return static_cast<sc_dt::uint64>(std::llround(static_cast<double>(cycles) * 1e6 / 90.0));
  };
  const ChipFrame& f = sim.frames.front();
  EXPECT_EQ(f.start.value() - s.start_written.value(), ps(load_cycles));
  EXPECT_EQ(f.end.value() - f.start.value(), ps(direct.cycles));
  EXPECT_EQ(s.end_seen, f.end);
}

}  // namespace
}  // namespace saarcor::vp

// SystemC's main() calls sc_main: GoogleTest runs from here.
int sc_main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
