// Parameterised binary floating-point formats: the runtime description (Format, Mode) and the one
// round-and-pack routine every operation ends in (docs/fixedfloat.md).
//
// An encoding holds sign | exponent (E bits, bias 2^(E-1)-1) | mantissa (M stored bits) in the low
// 1+E+M bits of a uint32_t. Exponent all-ones is +-inf (mantissa 0) or NaN (mantissa != 0), as in
// IEEE 754. Every op is computed in binary64 together with the sign of its exact error (obtained
// with error-free transformations), then rounded once into the target format. That is exact for
// every format with M <= 51, for both rounding modes, not only where the double-rounding theorem
// (53 >= 2(M+1)+2) applies. Formats are limited to E <= 8 and M <= 23 so that every intermediate
// value stays a normal binary64 number and the error terms are exact.
#pragma once

#include <cstdint>
#include <string>

namespace saarcor::ff {

enum class Rounding : std::uint8_t {
  kNearestEven,  // IEEE round to nearest, ties to even (default)
  kTowardZero,   // truncation: the cheap-FPGA alternative
};

enum class Subnormals : std::uint8_t {
  kFlush,  // subnormal inputs read as zero, subnormal results written as zero; sign kept (default)
  kKeep,   // gradual underflow as in IEEE 754
};

// How an op rounds. A hardware unit is built with one Mode; it is a parameter, not a constant.
struct Mode {
  Rounding rounding = Rounding::kNearestEven;
  Subnormals subnormals = Subnormals::kFlush;
  friend bool operator==(const Mode&, const Mode&) = default;
};

// The IEEE-binary32-compatible mode (used for the Float<8,23> self-check against the host FPU).
inline constexpr Mode kIeeeMode{Rounding::kNearestEven, Subnormals::kKeep};

// A format described at run time: E exponent bits, M stored mantissa bits.
struct Format {
  int exp_bits = 7;
  int man_bits = 16;

  constexpr int bits() const { return 1 + exp_bits + man_bits; }
  constexpr int bias() const { return (1 << (exp_bits - 1)) - 1; }
  constexpr int emin() const { return 1 - bias(); }  // unbiased exponent of the smallest normal
  constexpr int emax() const { return bias(); }      // unbiased exponent of the largest finite
  constexpr std::uint32_t exp_field_max() const { return (1u << exp_bits) - 1u; }
  constexpr std::uint32_t man_mask() const { return (1u << man_bits) - 1u; }
  constexpr std::uint32_t sign_mask() const { return 1u << (exp_bits + man_bits); }
  constexpr std::uint32_t bits_mask() const {
    return bits() == 32 ? 0xFFFFFFFFu : ((1u << bits()) - 1u);
  }
  constexpr std::uint32_t inf_bits() const { return exp_field_max() << man_bits; }
  constexpr std::uint32_t nan_bits() const { return inf_bits() | (1u << (man_bits - 1)); }
  constexpr std::uint32_t max_finite_bits() const { return inf_bits() - 1u; }
  constexpr std::uint32_t one_bits() const {
    return static_cast<std::uint32_t>(bias()) << man_bits;
  }
  constexpr bool valid() const {
    return exp_bits >= 2 && exp_bits <= 8 && man_bits >= 1 && man_bits <= 23;
  }
  friend bool operator==(const Format&, const Format&) = default;
};

inline constexpr Format kFp24{7, 16};
inline constexpr Format kFp32{8, 23};

// Parses "e7m16" (also "fp24", "fp32"). Returns false on anything else or an unsupported format.
bool parse_format(const std::string& text, Format* out);
std::string format_name(const Format& f);  // "e7m16"
// The modes by name, as `saarcor float-calc` and the DPI-C reference take them: rounding "rne" or
// "rtz", subnormals "flush" or "keep". Throws std::runtime_error (one line) on anything else.
Mode parse_mode(const std::string& round, const std::string& subnormals);

// --- the core: every op ends here ------------------------------------------------------------

// Rounds v into `f`. `dir` is the sign of (exact result - v): -1, 0 or +1; v itself must be the
// binary64 value nearest the exact result in the direction-consistent sense (i.e. exact result
// lies strictly between v and its binary64 neighbour in direction `dir`). NaN gives the canonical
// NaN. Subnormal results are flushed to zero (sign kept) *after* rounding when mode says kFlush.
std::uint32_t round_pack(double v, int dir, const Format& f, const Mode& mode);

// Exact binary64 value of an encoding; in kFlush mode a subnormal encoding reads as +-0.
double decode(std::uint32_t bits, const Format& f, Subnormals subnormals);

// Classification helpers on encodings.
bool is_nan(std::uint32_t bits, const Format& f);
bool is_inf(std::uint32_t bits, const Format& f);
bool is_zero(std::uint32_t bits, const Format& f);
bool is_subnormal(std::uint32_t bits, const Format& f);

// Ops on encodings (runtime format): used by the command-line tools and by Float<E,M>.
std::uint32_t op_add(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m);
std::uint32_t op_sub(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m);
std::uint32_t op_mul(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m);
std::uint32_t op_div(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m);
std::uint32_t op_sqrt(std::uint32_t a, const Format& f, const Mode& m);
// Compares are false when either side is NaN; -0 == +0.
bool op_lt(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m);
bool op_le(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m);
bool op_eq(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m);
// A comparator and a multiplexer, as hardware builds them: min = (b < a) ? b : a and
// max = (a < b) ? b : a, on the (flushed) inputs. So min(x, NaN) = x, min(NaN, x) = NaN,
// min(+0, -0) = +0.
std::uint32_t op_min(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m);
std::uint32_t op_max(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m);

// Conversions. From binary64/binary32 rounds once; to binary64 is exact; to binary32 rounds in
// IEEE round-to-nearest-even (exact for every format with E <= 8, M <= 23).
std::uint32_t from_double(double v, const Format& f, const Mode& m);
std::uint32_t from_int(std::int64_t v, const Format& f, const Mode& m);
// Rounds toward zero to an integer, saturating at the int32 range; NaN gives 0.
std::int32_t to_int(std::uint32_t bits, const Format& f, const Mode& m);

// "0.0a3f1c" style grouping for failure messages: sign.exponent.mantissa in binary.
std::string bit_groups(std::uint32_t bits, const Format& f);

}  // namespace saarcor::ff
