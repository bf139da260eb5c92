// Bit fields of Verilated ports: Verilator gives a port of up to 64 bits as an integer and a
// wider one as a VlWide (32-bit words, bit 0 first); a packed array [n-1:0][w-1:0] is one such
// port with element k at bit k * w. The harnesses put and get fields at a bit offset.
#pragma once

#include <cstdint>
#include <type_traits>

namespace saarcor::rtl {

// The field of `width` (<= 64) bits at `lsb` of `port` becomes `v`.
template <class T>
void put_bits(T& port, int lsb, int width, std::uint64_t v) {
  if constexpr (std::is_integral_v<T>) {
    const std::uint64_t m = width >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << width) - 1;
    std::uint64_t p = static_cast<std::uint64_t>(port);
    p = (p & ~(m << lsb)) | ((v & m) << lsb);
    port = static_cast<T>(p);
  } else {
    for (int b = 0; b < width; ++b) {
      const int bit = lsb + b;
      auto& w = port[static_cast<std::size_t>(bit / 32)];
      const std::uint32_t m = std::uint32_t{1} << (bit % 32);
      w = ((v >> b) & 1u) != 0 ? (w | m) : (w & ~m);
    }
  }
}

// The field of `width` (<= 64) bits at `lsb` of `port`.
template <class T>
std::uint64_t get_bits(const T& port, int lsb, int width) {
  const std::uint64_t m = width >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << width) - 1;
  if constexpr (std::is_integral_v<T>) {
    return (static_cast<std::uint64_t>(port) >> lsb) & m;
  } else {
    std::uint64_t v = 0;
    for (int b = 0; b < width; ++b) {
      const int bit = lsb + b;
      v |= static_cast<std::uint64_t>((port[static_cast<std::size_t>(bit / 32)] >> (bit % 32)) & 1u)
           << b;
    }
    return v;
  }
}

// Thread-id bits of a unit with `threads` threads (the SystemVerilog's TW).
inline int thread_bits(int threads) {
  int b = 0;
  while ((1 << b) < threads)
    ++b;
  return b < 1 ? 1 : b;
}

}  // namespace saarcor::rtl
