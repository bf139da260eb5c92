// The host of the example virtual platform (docs/systemc.md).
#include "testbench/systemc/host_initiator.h"

#include <algorithm>
#include <exception>
#include <stdexcept>
#include <utility>

#include "host/frame_upload.h"
#include "testbench/systemc/chip_registers.h"

namespace saarcor::vp {
namespace {

const char* response_name(tlm::tlm_response_status s) {
  switch (s) {
    case tlm::TLM_ADDRESS_ERROR_RESPONSE:
      return "address error";
    case tlm::TLM_BURST_ERROR_RESPONSE:
      return "burst error";
    case tlm::TLM_COMMAND_ERROR_RESPONSE:
      return "command error";
    case tlm::TLM_BYTE_ENABLE_ERROR_RESPONSE:
      return "byte-enable error";
    default:
      return "generic error";
  }
}

void store_runs(memif::MemoryImage& image, const std::vector<memif::UploadRun>& runs) {
  for (const memif::UploadRun& r : runs)
    std::copy(r.words.begin(), r.words.end(), image.bank(r.bank).begin() + r.offset);
}

}  // namespace

HostInitiator::HostInitiator(sc_core::sc_module_name name, PlatformSpec spec,
                             const sc_core::sc_event& frame_end)
    : sc_core::sc_module(name), socket("socket"), spec_(std::move(spec)), frame_end_(frame_end) {
  // The scene is loaded and its image built before the simulation starts, so a bad scene is an
  // error of the platform's elaboration, not of a running process.
  RenderSettings s = spec_.settings;
  s.time = spec_.start;
  // Two copies: the next frame's top level goes into the copy in flight's twin.
  s.top_level_buffers = spec_.frame_gap ? 1 : 2;
  prep_ = prepare_scene(spec_.scene, s, ff::kFp24);
  SC_HAS_PROCESS(HostInitiator);
  SC_THREAD(run);
}

void HostInitiator::run() {
  try {
    sequence();
  } catch (const std::runtime_error& e) {  // bad input, a refused transaction, a failed frame
    error_ = e.what();
  }
}

void HostInitiator::transfer(tlm::tlm_command command, std::uint64_t address, std::uint32_t* words,
                             std::size_t count) {
  tlm::tlm_generic_payload tx;
  sc_core::sc_time delay = sc_core::SC_ZERO_TIME;
  tx.set_command(command);
  tx.set_address(address);
  tx.set_data_ptr(reinterpret_cast<unsigned char*>(words));
  tx.set_data_length(static_cast<unsigned>(4 * count));
  tx.set_streaming_width(static_cast<unsigned>(4 * count));
  tx.set_byte_enable_ptr(nullptr);
  tx.set_dmi_allowed(false);
  tx.set_response_status(tlm::TLM_INCOMPLETE_RESPONSE);
  socket->b_transport(tx, delay);
  if (tx.is_response_error())
    throw std::runtime_error(std::string("the chip refused a ") +
                             (command == tlm::TLM_READ_COMMAND ? "read" : "write") + " of " +
                             std::to_string(4 * count) + " bytes at " + std::to_string(address) +
                             " (" + response_name(tx.get_response_status()) + ")");
  if (delay != sc_core::SC_ZERO_TIME) sc_core::wait(delay);  // the target's annotated time
}

void HostInitiator::write(std::uint64_t address, const std::uint32_t* words, std::size_t count) {
  std::vector<std::uint32_t> copy(words, words + count);  // the payload's buffer is writable
  transfer(tlm::TLM_WRITE_COMMAND, address, copy.data(), count);
}

std::uint32_t HostInitiator::read_word(std::uint64_t address) {
  std::uint32_t w = 0;
  transfer(tlm::TLM_READ_COMMAND, address, &w, 1);
  return w;
}

std::uint64_t HostInitiator::read_pair(std::uint32_t lo_index) {
  std::uint32_t w[2] = {0, 0};
  transfer(tlm::TLM_READ_COMMAND, kControlBase + 4ull * lo_index, w, 2);
  return w[0] | (std::uint64_t{w[1]} << 32);
}

// The words that changed, a run per transaction, then the frame registers: what the frame
// sequence's host bus sends (runs, then registers). Returns the bytes sent.
std::uint64_t HostInitiator::post(const std::vector<memif::UploadRun>& runs,
                                  const memif::FrameRegisters& registers,
                                  const memif::SceneRegions& regions) {
  std::uint64_t bytes = 0;
  for (const memif::UploadRun& r : runs) {
    write(bank_address(r.bank, r.offset), r.words.data(), r.words.size());
    bytes += 4ull * r.words.size();
  }
  const FrameRegisterWords w = encode_frame_registers(registers, regions);
  write(kFrameRegisterBase, w.data(), w.size());
  return bytes + 4ull * w.size();
}

// The frame's counts from the chip's registers and its image from the frame-buffer bank.
void HostInitiator::read_back(HostFrame& f, int width, int height) {
  if ((read_word(kControlBase + 4ull * kStatus) & kStatusError) != 0)
    throw std::runtime_error("frame " + std::to_string(f.index) + " failed in the chip");
  f.cycles = read_pair(kCyclesLo);
  f.rays = read_pair(kRaysLo);
  f.load_cycles = read_pair(kLoadLo);
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  std::vector<std::uint32_t> fb(pixels);
  transfer(tlm::TLM_READ_COMMAND, bank_address(f.frame_bank), fb.data(), pixels);
  f.image = {width, height, std::vector<std::uint8_t>(3 * pixels)};
  for (std::size_t i = 0; i < pixels; ++i)
    for (std::size_t k = 0; k < 3; ++k)
      f.image.rgb[3 * i + k] = static_cast<std::uint8_t>((fb[i] >> (8 * k)) & 255u);
}

// The initial load: every data word of banks 2-5 and frame 0's registers (the board's mirror
// `board` then holds what the chip holds).
HostFrame HostInitiator::load(PreparedScene& prep, memif::MemoryImage& board) {
  host::BuiltImage& built = prep.built;
  std::vector<memif::UploadRun> runs;
  for (const memif::BankRange& r : host::data_words(built)) {
    const auto& src = built.image.bank(r.bank);
    runs.push_back({r.bank, r.begin, {src.begin() + r.begin, src.begin() + r.end}});
  }
  built.image.registers().frame_bank = memif::kFrameBank0;
  HostFrame f;
  f.time = prep.scene.time;
  f.upload_bytes = post(runs, built.image.registers(), built.image.regions());
  store_runs(board, runs);
  return f;
}

// Frame `index`'s rebuild while the frame before renders: its changed words (`runs`), posted at
// once unless they touch what the frame in flight reads (`reads`; then they wait: a gap).
HostFrame HostInitiator::prepare(PreparedScene& prep, const memif::MemoryImage& board,
                                 const std::vector<memif::BankRange>& reads, int index, double dt,
                                 std::vector<memif::UploadRun>& runs) {
  host::BuiltImage& built = prep.built;
  HostFrame next;
  next.index = index;
  next.frame_bank = index % 2 == 0 ? memif::kFrameBank0 : memif::kFrameBank1;
  prep.scene.set_time(spec_.start + index * dt);
  next.time = prep.scene.time;
  host::rebuild_top_level(built, prep.scene);
  built.image.registers().frame_bank = static_cast<std::uint32_t>(next.frame_bank);
  runs = host::changed_words(board, built.image);
  next.gap = host::overlaps(runs, reads);
  if (!next.gap) next.upload_bytes = post(runs, built.image.registers(), built.image.regions());
  return next;
}

void HostInitiator::sequence() {
  PreparedScene& prep = prep_;
  const memif::FrameRegisters& regs = prep.built.image.registers();
  const int width = static_cast<int>(regs.width), height = static_cast<int>(regs.height);
  const double dt = spec_.dt >= 0 ? spec_.dt : prep.scene.animation_seconds / spec_.frames;
  memif::MemoryImage board(prep.built.image.format(), prep.built.image.bank_words());
  HostFrame f = load(prep, board);
  for (int k = 0; k < spec_.frames; ++k) {
    const std::vector<memif::BankRange> reads = host::frame_reads(prep.built, f.frame_bank);
    const std::uint32_t start = kStart;
    write(kControlBase + 4ull * kControl, &start, 1);
    f.start_written = sc_core::sc_time_stamp();
    const bool more = k + 1 < spec_.frames;
    std::vector<memif::UploadRun> runs;
    HostFrame next;
    if (more) next = prepare(prep, board, reads, k + 1, dt, runs);
    sc_core::wait(frame_end_);
    f.end_seen = sc_core::sc_time_stamp();
    read_back(f, width, height);
    // The upload that brought this frame's changes, as `render --frames` reports it (frame 0's,
    // the initial load, is reported apart): one in a gap took the frame before and then its own
    // time alone.
    if (f.gap) f.upload_cycles = frames_.back().cycles + f.load_cycles;
    if (more) {
      next.upload_cycles = read_pair(kUploadLo);
      if (next.gap) next.upload_bytes = post(runs, regs, prep.built.image.regions());
      store_runs(board, runs);
    }
    frames_.push_back(std::move(f));
    f = std::move(next);
  }
}

}  // namespace saarcor::vp
