// The memory image file (memif/image_file.h, docs/memory-image.md "Image file"): little-endian
// 32-bit words throughout, so the file is the same on every host that runs the reference.
#include "memif/image_file.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <vector>

namespace saarcor::memif {
namespace {

// The frame registers in the file's order (FrameRegisters' declaration order).
std::vector<std::uint32_t*> register_fields(FrameRegisters& r) {
  std::vector<std::uint32_t*> f{&r.width, &r.height};
  for (auto* v : {&r.cam_r, &r.cam_u, &r.cam_d, &r.cam_p})
    for (auto& w : *v)
      f.push_back(&w);
  f.push_back(&r.top_root);
  for (auto* v : {&r.scene_min, &r.scene_max})
    for (auto& w : *v)
      f.push_back(&w);
  for (auto* w : {&r.instance_row_base, &r.instance_count, &r.material_base, &r.shading_record_base,
                  &r.light_base, &r.light_count, &r.ambient_rgb, &r.background_rgb, &r.epsilon,
                  &r.max_depth, &r.frame_bank})
    f.push_back(w);
  return f;
}

// FNV-1a over the bytes before the checksum: detects a flipped or lost byte anywhere.
std::uint32_t checksum(const std::vector<std::uint8_t>& bytes, std::size_t n) {
  std::uint32_t h = 2166136261u;
  for (std::size_t i = 0; i < n; ++i)
    h = (h ^ bytes[i]) * 16777619u;
  return h;
}

void put(std::vector<std::uint8_t>& b, std::uint32_t w) {
  for (int i = 0; i < 4; ++i)
    b.push_back(static_cast<std::uint8_t>(w >> (8 * i)));
}

// Sequential reader over the file's bytes; running past the end is a truncated file.
class Reader {
 public:
  Reader(const std::vector<std::uint8_t>& b, const std::string& what) : b_(b), what_(what) {}
  std::uint32_t word() {
    if (pos_ + 4 > b_.size()) fail("truncated");
    std::uint32_t w = 0;
    for (int i = 0; i < 4; ++i)
      w |= static_cast<std::uint32_t>(b_[pos_ + static_cast<std::size_t>(i)]) << (8 * i);
    pos_ += 4;
    return w;
  }
  std::size_t pos() const { return pos_; }
  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error("memory image file " + what_ + ": " + why);
  }

 private:
  const std::vector<std::uint8_t>& b_;
  const std::string& what_;
  std::size_t pos_ = 0;
};

// The header's checks: the magic, the version, a format with operators, a bank size that fits
// the words each bank stores.
MemoryImage read_header(Reader& r, const std::vector<std::uint8_t>& bytes) {
  if (bytes.size() < sizeof kImageFileMagic ||
      std::memcmp(bytes.data(), kImageFileMagic, sizeof kImageFileMagic) != 0)
    r.fail("not a saarcor memory image (no SAARCORI magic)");
  r.word();
  r.word();
  const std::uint32_t version = r.word();
  if (version != kImageFileVersion)
    r.fail("version " + std::to_string(version) + "; this reader reads version " +
           std::to_string(kImageFileVersion));
  ff::Format f;
  f.exp_bits = static_cast<int>(r.word());
  f.man_bits = static_cast<int>(r.word());
  if (!f.valid()) r.fail("an invalid float format");
  const std::uint32_t bank_words = r.word();
  if (bank_words == 0 || bank_words > (1u << 28)) r.fail("a bank size out of range");
  MemoryImage image(f, bank_words);
  for (auto& v : image.regions().base)
    v = r.word();
  for (auto& v : image.regions().count)
    v = r.word();
  for (std::uint32_t* w : register_fields(image.registers()))
    *w = r.word();
  return image;
}

// Regions and registers that point outside the banks would send the model's reads astray.
void check_layout(const MemoryImage& image, const Reader& r) {
  const SceneRegions& g = image.regions();
  for (int t = 0; t < kItemTypes; ++t) {
    const std::uint64_t per_bank = (std::uint64_t{g.count[t]} + kSceneBanks - 1) / kSceneBanks;
    const auto words = static_cast<std::uint64_t>(image.item_words(static_cast<ItemType>(t)));
    if (g.base[t] + per_bank * words > image.bank_words())
      r.fail(std::string("a ") + item_type_name(static_cast<ItemType>(t)) +
             " region beyond its banks");
  }
  const FrameRegisters& f = image.registers();
  if (f.width < 1 || f.height < 1 || f.width > 16384 || f.height > 16384)
    r.fail("a resolution outside 1..16384 per side");
  const std::uint64_t rows = std::uint64_t{f.instance_row_base} + kInstanceRows * f.instance_count;
  if (rows > g.count[static_cast<int>(ItemType::kRow)]) r.fail("instances beyond its rows");
  if (g.count[0] > 0 && f.top_root >= g.count[0]) r.fail("the root beyond the nodes");
  if (f.frame_bank != kFrameBank0 && f.frame_bank != kFrameBank1)
    r.fail("a frame bank other than 0 or 1");
}

}  // namespace

void write_image_file(const MemoryImage& image, std::ostream& out) {
  std::vector<std::uint8_t> b(std::begin(kImageFileMagic), std::end(kImageFileMagic));
  put(b, kImageFileVersion);
  put(b, static_cast<std::uint32_t>(image.format().exp_bits));
  put(b, static_cast<std::uint32_t>(image.format().man_bits));
  put(b, image.bank_words());
  for (std::uint32_t v : image.regions().base)
    put(b, v);
  for (std::uint32_t v : image.regions().count)
    put(b, v);
  FrameRegisters regs = image.registers();
  for (const std::uint32_t* w : register_fields(regs))
    put(b, *w);
  for (int k = 0; k < kNumBanks; ++k) {
    const std::vector<std::uint32_t>& bank = image.bank(k);
    const auto last = std::find_if(bank.rbegin(), bank.rend(), [](std::uint32_t w) { return w; });
    const auto used = static_cast<std::uint32_t>(bank.rend() - last);
    put(b, used);
    for (std::uint32_t i = 0; i < used; ++i)
      put(b, bank[i]);
  }
  put(b, checksum(b, b.size()));
  out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
  if (!out) throw std::runtime_error("memory image file: writing failed");
}

void write_image_file(const MemoryImage& image, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("memory image file " + path + ": cannot open for writing");
  write_image_file(image, out);
  out.close();
  if (!out) throw std::runtime_error("memory image file " + path + ": writing failed");
}

MemoryImage read_image_file(std::istream& in, const std::string& what) {
  const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in),
                                        std::istreambuf_iterator<char>()};
  Reader r(bytes, what);
  // The checksum first: nothing a corrupt header says (a bank size, a count) is acted on.
  const std::size_t body = bytes.size() >= 4 ? bytes.size() - 4 : 0;
  if (bytes.size() >= sizeof kImageFileMagic + 4 &&
      std::memcmp(bytes.data(), kImageFileMagic, sizeof kImageFileMagic) == 0) {
    std::uint32_t stored = 0;
    for (std::size_t i = 0; i < 4; ++i)
      stored |= static_cast<std::uint32_t>(bytes[body + i]) << (8 * i);
    if (stored != checksum(bytes, body)) r.fail("checksum mismatch (corrupt or truncated file)");
  }
  MemoryImage image = read_header(r, bytes);
  for (int k = 0; k < kNumBanks; ++k) {
    const std::uint32_t used = r.word();
    if (used > image.bank_words()) r.fail("more words in a bank than the bank holds");
    if (r.pos() + std::uint64_t{used} * 4u > body) r.fail("truncated");
    std::vector<std::uint32_t>& bank = image.bank(k);
    for (std::uint32_t i = 0; i < used; ++i)
      bank[i] = r.word();
  }
  if (r.pos() != body) r.fail("bytes after the last bank");
  check_layout(image, r);
  return image;
}

MemoryImage read_image_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("memory image file " + path + ": cannot open");
  return read_image_file(in, path);
}

}  // namespace saarcor::memif
