// The register map of the chip's host side (docs/systemc.md).
#include "testbench/systemc/chip_registers.h"

#include <cstdio>

namespace saarcor::vp {
namespace {

// The frame registers' words in the map's order, as pointers into the two structures.
template <class R, class G, class W>
std::array<W*, kFrameRegisterWords> register_slots(R& r, G& g) {
  std::array<W*, kFrameRegisterWords> s{};
  std::size_t i = 0;
  const auto put = [&](W& w) { s[i++] = &w; };
  put(r.width);
  put(r.height);
  for (auto* v : {&r.cam_r, &r.cam_u, &r.cam_d, &r.cam_p})
    for (W& w : *v)
      put(w);
  put(r.top_root);
  for (W& w : r.scene_min)
    put(w);
  for (W& w : r.scene_max)
    put(w);
  for (W* w : {&r.instance_row_base, &r.instance_count, &r.material_base, &r.shading_record_base,
               &r.light_base, &r.light_count, &r.ambient_rgb, &r.background_rgb, &r.epsilon,
               &r.max_depth, &r.frame_bank})
    put(*w);
  for (W& w : g.base)
    put(w);
  for (W& w : g.count)
    put(w);
  return s;
}

constexpr const char* kNames[] = {"width",
                                  "height",
                                  "cam_r[0]",
                                  "cam_r[1]",
                                  "cam_r[2]",
                                  "cam_u[0]",
                                  "cam_u[1]",
                                  "cam_u[2]",
                                  "cam_d[0]",
                                  "cam_d[1]",
                                  "cam_d[2]",
                                  "cam_p[0]",
                                  "cam_p[1]",
                                  "cam_p[2]",
                                  "top_root",
                                  "scene_min[0]",
                                  "scene_min[1]",
                                  "scene_min[2]",
                                  "scene_max[0]",
                                  "scene_max[1]",
                                  "scene_max[2]",
                                  "instance_row_base",
                                  "instance_count",
                                  "material_base",
                                  "shading_record_base",
                                  "light_base",
                                  "light_count",
                                  "ambient_rgb",
                                  "background_rgb",
                                  "epsilon",
                                  "max_depth",
                                  "frame_bank",
                                  "regions.base[0]",
                                  "regions.base[1]",
                                  "regions.base[2]",
                                  "regions.count[0]",
                                  "regions.count[1]",
                                  "regions.count[2]"};
static_assert(std::size(kNames) == kFrameRegisterWords);

std::string hex(std::uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "0x%08llx", static_cast<unsigned long long>(v));
  return buf;
}

// The region an address falls in: its base and size in bytes, or nothing.
Decoded region_of(std::uint64_t address, std::uint32_t bank_words, std::uint64_t& base,
                  std::uint64_t& size) {
  Decoded d;
  if (address < kControlBase + 4ull * kControlWords) {
    base = kControlBase;
    size = 4ull * kControlWords;
  } else if (address >= kFrameRegisterBase &&
             address < kFrameRegisterBase + 4ull * kFrameRegisterWords) {
    d.region = Decoded::Region::kFrameRegisters;
    base = kFrameRegisterBase;
    size = 4ull * kFrameRegisterWords;
  } else if (address >= kBankBase && address < bank_address(memif::kNumBanks) &&
             (address - kBankBase) % kBankStride < 4ull * bank_words) {
    d.region = Decoded::Region::kBank;
    d.bank = static_cast<int>((address - kBankBase) / kBankStride);
    base = bank_address(d.bank);
    size = 4ull * bank_words;
  } else {
    d.error = "address " + hex(address) + " lies outside the register map";
  }
  return d;
}

}  // namespace

std::string frame_register_name(std::uint32_t index) {
  return index < kFrameRegisterWords ? kNames[index] : "?";
}

FrameRegisterWords encode_frame_registers(const memif::FrameRegisters& r,
                                          const memif::SceneRegions& g) {
  FrameRegisterWords w{};
  const auto slots =
      register_slots<const memif::FrameRegisters, const memif::SceneRegions, const std::uint32_t>(
          r, g);
  for (std::size_t i = 0; i < w.size(); ++i)
    w[i] = *slots[i];
  return w;
}

void decode_frame_registers(const FrameRegisterWords& w, memif::FrameRegisters& r,
                            memif::SceneRegions& g) {
  const auto slots =
      register_slots<memif::FrameRegisters, memif::SceneRegions, std::uint32_t>(r, g);
  for (std::size_t i = 0; i < w.size(); ++i)
    *slots[i] = w[i];
}

Decoded decode_address(std::uint64_t address, std::uint64_t bytes, std::uint32_t bank_words) {
  std::uint64_t base = 0, size = 0;
  Decoded d = region_of(address, bank_words, base, size);
  if (!d.error.empty()) return d;
  if (address % 4 != 0) {
    d.error = "address " + hex(address) + " is not word-aligned";
  } else if (bytes == 0 || bytes % 4 != 0) {
    d.error = "a transaction of " + std::to_string(bytes) + " bytes at " + hex(address) +
              ": the chip's registers and banks take whole 32-bit words";
    d.length_error = true;
  } else if (address + bytes > base + size) {
    d.error = "a transaction of " + std::to_string(bytes) + " bytes at " + hex(address) +
              " runs past the end of its region (" + hex(base + size - 1) + ")";
  }
  d.word = static_cast<std::uint32_t>((address - base) / 4);
  d.words = static_cast<std::uint32_t>(bytes / 4);
  return d;
}

}  // namespace saarcor::vp
