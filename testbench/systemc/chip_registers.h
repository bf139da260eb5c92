// The register map of the chip's host side as a SystemC TLM-2.0 target sees it (docs/systemc.md):
// a control block, the frame registers the host writes before each frame (paper section 4: the
// board sits on the PCI bus; memif/image_format.h FrameRegisters and SceneRegions, which travel
// with every upload), and the six SRAM banks. Byte addresses, 32-bit words; plain C++ (no SystemC)
// so the map can be read and tested without a simulator.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "memif/image_format.h"

namespace saarcor::vp {

// ---- control block (words at kControlBase + 4 * index) ----------------------------------------
inline constexpr std::uint64_t kControlBase = 0x0000'0000;
enum ControlWord : std::uint32_t {
  kId = 0,            // R  kChipId
  kControl = 1,       // W  bit 0: START (latch the frame registers, begin the frame); reads 0
  kStatus = 2,        // R  kStatusBusy | kStatusDone | kStatusError
  kFrames = 3,        // R  frames finished since reset
  kCyclesLo = 4,      // R  the last frame's cycles (its render, at clock_mhz)
  kCyclesHi = 5,      //
  kUploadLo = 6,      // R  cycles from the last frame's start until the writes posted beside it
  kUploadHi = 7,      //    were stored (0: none)
  kLoadLo = 8,        // R  cycles the writes posted before the last START took, nothing
  kLoadHi = 9,        //    rendering, before its frame began (0: none)
  kRaysLo = 10,       // R  rays the last frame issued, all kinds
  kRaysHi = 11,       //
  kControlWords = 12  //
};
inline constexpr std::uint32_t kChipId = 0x5343'4F52u;  // "SCOR"
inline constexpr std::uint32_t kStart = 1u;
inline constexpr std::uint32_t kStatusBusy = 1u;   // a frame started and has not ended
inline constexpr std::uint32_t kStatusDone = 2u;   // a frame ended since the last START (= irq)
inline constexpr std::uint32_t kStatusError = 4u;  // the last frame failed (message: stderr)

// ---- frame registers (words at kFrameRegisterBase + 4 * index) --------------------------------
// FrameRegisters field by field in declaration order, then SceneRegions (base[3], count[3]).
inline constexpr std::uint64_t kFrameRegisterBase = 0x0000'0100;
inline constexpr std::uint32_t kFrameRegisterWords = 38;
static_assert(kFrameRegisterWords * 4 ==
                  sizeof(memif::FrameRegisters) + sizeof(memif::SceneRegions),
              "every frame register and scene-region word has an address");
// The register of word i, as docs/systemc.md names it ("cam_r[1]", "regions.count[2]").
std::string frame_register_name(std::uint32_t index);

using FrameRegisterWords = std::array<std::uint32_t, kFrameRegisterWords>;
FrameRegisterWords encode_frame_registers(const memif::FrameRegisters& r,
                                          const memif::SceneRegions& g);
void decode_frame_registers(const FrameRegisterWords& w, memif::FrameRegisters& r,
                            memif::SceneRegions& g);

// ---- SRAM banks (bank b at kBankBase + b * kBankStride) ---------------------------------------
inline constexpr std::uint64_t kBankBase = 0x1000'0000;
inline constexpr std::uint64_t kBankStride = 0x0400'0000;  // 64 MB windows: banks up to 64 MB
inline constexpr std::uint64_t kMaxBankBytes = kBankStride;

inline constexpr std::uint64_t bank_address(int bank, std::uint32_t word = 0) {
  return kBankBase + static_cast<std::uint64_t>(bank) * kBankStride + 4ull * word;
}

// Where an access of `bytes` bytes at `address` lands, or why it lands nowhere.
struct Decoded {
  enum class Region { kControl, kFrameRegisters, kBank } region = Region::kControl;
  int bank = 0;               // kBank
  std::uint32_t word = 0;     // first word within the region
  std::uint32_t words = 0;    // words accessed
  std::string error;          // non-empty: the access is refused (one line)
  bool length_error = false;  // the error is the length's (TLM_BURST_ERROR_RESPONSE)
};
// `bank_words`: the words of one SRAM bank. An access must be word-aligned, a non-zero multiple of
// 4 bytes long, and lie inside one region.
Decoded decode_address(std::uint64_t address, std::uint64_t bytes, std::uint32_t bank_words);

}  // namespace saarcor::vp
