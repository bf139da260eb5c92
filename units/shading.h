// The fixed-function shader of the RGS (paper sections 3.2 and 4.2; docs/shading.md;
// docs/shading.md): integer colour arithmetic, texture addressing and filtering, and the reads of
// the shading bank. The float steps of shading (normal transform, dot products, cosines) run in
// units/thread_program.h on the transformation unit and the RGS FP helper; this file is integer
// only, so the float reference can share its formulas line by line.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "fixedfloat/float.h"
#include "memif/image_format.h"

namespace saarcor::units {

using Rgb8 = std::array<std::uint32_t, 3>;

inline Rgb8 unpack_rgb(std::uint32_t w) {
  return {w & 255u, (w >> 8) & 255u, (w >> 16) & 255u};
}
inline std::uint32_t mul8(std::uint32_t a, std::uint32_t b) {
  return (a * b + 127u) / 255u;
}

// Float to unsigned fixed point with `frac_bits` fraction bits, clamped to [0, 1]: a shifter on
// the encoding in hardware, exact here (docs/shading.md: fix8, fix16). NaN gives 0.
inline std::uint32_t to_unit_fixed(double x, int frac_bits) {
  // 2^frac_bits as a shift (frac_bits <= 16): the same double as ldexp(1, frac_bits), without a
  // libm call per texel coordinate and cosine.
  const auto one = static_cast<double>(std::uint32_t{1} << frac_bits);
  if (!(x > 0.0)) return 0;
  if (x >= 1.0) return static_cast<std::uint32_t>(one);
  return static_cast<std::uint32_t>(std::floor(x * one + 0.5));
}
// The RGS's shifter on the encoding: a normal value is decoded inline; exponent field 0 (zero, or
// a subnormal, which to_double reads as zero) gives 0 without the general decode, as it would
// through it; infinities and NaN take the general decode.
template <class F>
inline std::uint32_t to_unit_fixed_of(F x, int frac_bits) {
  constexpr std::uint32_t kExpMax = F::kFormat.exp_field_max();
  const std::uint32_t e = (x.bits >> F::kManBits) & kExpMax;
  if (e - 1u < kExpMax - 1u) [[likely]]
    return to_unit_fixed(ff::fast::decode_normal<F::kExpBits, F::kManBits>(x.bits), frac_bits);
  if (e == 0) return 0;
  return to_unit_fixed(x.to_double(), frac_bits);
}
template <class F>
inline std::uint32_t fix8(F x) {
  return to_unit_fixed_of(x, 8);
}
template <class F>
inline std::uint32_t fix16(F x) {
  return to_unit_fixed_of(x, 16);
}

// The shading bank's records (docs/shading.md section 5).
inline memif::ShadingRecord read_shading_record(const memif::MemoryImage& image,
                                                std::uint32_t record) {
  const auto& regs = image.registers();
  const std::uint32_t a = regs.shading_record_base + memif::kShadingRecordWords * record;
  std::array<std::uint32_t, 4> w{};
  for (std::uint32_t i = 0; i < 4; ++i)
    w[i] = image.word(memif::kShadingBank, a + i);
  return memif::decode_shading(w.data());
}
inline memif::MaterialRecord read_material(const memif::MemoryImage& image,
                                           std::uint32_t material) {
  const std::uint32_t a = image.registers().material_base + memif::kMaterialWords * material;
  std::array<std::uint32_t, memif::kMaterialWords> w{};
  for (std::uint32_t i = 0; i < memif::kMaterialWords; ++i)
    w[i] = image.word(memif::kShadingBank, a + i);
  return memif::decode_material(w.data());
}

// Texture colour at barycentrics (bu, bv) in 0.16 fixed point (docs/shading.md section 5).
// texel(x, y) returns the RGBA8 word of texel (x, y).
template <class TexelFn>
inline Rgb8 sample_texture(const memif::ShadingRecord& rec, const memif::MaterialRecord& mat,
                           std::uint32_t bu, std::uint32_t bv, TexelFn&& texel) {
  const std::int64_t bw = std::max<std::int64_t>(0, 65536 - std::int64_t{bu} - std::int64_t{bv});
  const std::int64_t s = std::int64_t{rec.tex_u[0]} * bu + std::int64_t{rec.tex_u[1]} * bv +
                         std::int64_t{rec.tex_u[2]} * bw;
  const std::int64_t tt = std::int64_t{rec.tex_v[0]} * bu + std::int64_t{rec.tex_v[1]} * bv +
                          std::int64_t{rec.tex_v[2]} * bw;
  const std::int64_t wmask = (std::int64_t{1} << mat.log2_width) - 1;
  const std::int64_t hmask = (std::int64_t{1} << mat.log2_height) - 1;
  if (!mat.bilinear) {
    const std::int64_t x = ((s << mat.log2_width) >> 28) & wmask;
    const std::int64_t y = ((tt << mat.log2_height) >> 28) & hmask;
    return unpack_rgb(texel(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y)));
  }
  const std::int64_t X = (s << mat.log2_width) - (std::int64_t{1} << 27);
  const std::int64_t Y = (tt << mat.log2_height) - (std::int64_t{1} << 27);
  const auto x0 = static_cast<std::uint32_t>((X >> 28) & wmask);
  const auto y0 = static_cast<std::uint32_t>((Y >> 28) & hmask);
  const auto x1 = static_cast<std::uint32_t>((x0 + 1) & wmask);
  const auto y1 = static_cast<std::uint32_t>((y0 + 1) & hmask);
  const auto fx = static_cast<std::uint32_t>((X >> 20) & 255);
  const auto fy = static_cast<std::uint32_t>((Y >> 20) & 255);
  const Rgb8 c00 = unpack_rgb(texel(x0, y0)), c10 = unpack_rgb(texel(x1, y0));
  const Rgb8 c01 = unpack_rgb(texel(x0, y1)), c11 = unpack_rgb(texel(x1, y1));
  Rgb8 out{};
  for (int c = 0; c < 3; ++c) {
    const std::uint32_t top = c00[c] * (256 - fx) + c10[c] * fx;
    const std::uint32_t bot = c01[c] * (256 - fx) + c11[c] * fx;
    out[c] = (top * (256 - fy) + bot * fy + 32768u) >> 16;
  }
  return out;
}

// Base colour of a hit: the material's diffuse colour, modulated by the texture when it has one.
// `on_texel(address)` sees the shading-bank address of every texel read, in the order read.
template <class OnTexel>
inline Rgb8 base_colour(const memif::MemoryImage& image, const memif::ShadingRecord& rec,
                        const memif::MaterialRecord& mat, std::uint32_t bu, std::uint32_t bv,
                        OnTexel&& on_texel) {
  const Rgb8 diffuse = unpack_rgb(mat.diffuse_rgba);
  if (mat.texture == memif::kNone) return diffuse;
  const std::uint32_t w = 1u << mat.log2_width;
  const Rgb8 tex = sample_texture(rec, mat, bu, bv, [&](std::uint32_t x, std::uint32_t y) {
    const std::uint32_t a = mat.texture + y * w + x;
    on_texel(a);
    return image.word(memif::kShadingBank, a);
  });
  return {mul8(diffuse[0], tex[0]), mul8(diffuse[1], tex[1]), mul8(diffuse[2], tex[2])};
}
inline Rgb8 base_colour(const memif::MemoryImage& image, const memif::ShadingRecord& rec,
                        const memif::MaterialRecord& mat, std::uint32_t bu, std::uint32_t bv) {
  return base_colour(image, rec, mat, bu, bv, [](std::uint32_t) {});
}

// p = 256, then `shininess` times p = (p*ws + 128) >> 8 (docs/shading.md section 6.6).
inline std::uint32_t specular_power(std::uint32_t ws, std::uint32_t shininess) {
  std::uint32_t p = 256;
  for (std::uint32_t i = 0; i < shininess && p != 0; ++i)
    p = (p * ws + 128u) >> 8;
  return p;
}

}  // namespace saarcor::units
