// The round-and-pack routine and the ops on encodings. See format.h for the method: binary64
// result + sign of the exact error, rounded once.
#include "fixedfloat/format.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace saarcor::ff {
namespace {

int sign_of(double x) {
  return (x > 0.0) - (x < 0.0);
}

}  // namespace

Mode parse_mode(const std::string& round, const std::string& subnormals) {
  Mode m;
  if (round == "rne") {
    m.rounding = Rounding::kNearestEven;
  } else if (round == "rtz") {
    m.rounding = Rounding::kTowardZero;
  } else {
    throw std::runtime_error("unknown rounding mode '" + round + "' (expected rne or rtz)");
  }
  if (subnormals == "flush") {
    m.subnormals = Subnormals::kFlush;
  } else if (subnormals == "keep") {
    m.subnormals = Subnormals::kKeep;
  } else {
    throw std::runtime_error("unknown subnormal mode '" + subnormals +
                             "' (expected flush or keep)");
  }
  return m;
}

bool parse_format(const std::string& text, Format* out) {
  Format f;
  if (text == "fp24") {
    f = kFp24;
  } else if (text == "fp32") {
    f = kFp32;
  } else if (text == "fp16") {
    f = Format{5, 10};
  } else {
    int e = 0;
    int m = 0;
    char tail = 0;
    if (std::sscanf(text.c_str(), "e%dm%d%c", &e, &m, &tail) != 2) return false;
    f = Format{e, m};
  }
  if (!f.valid()) return false;
  *out = f;
  return true;
}

std::string format_name(const Format& f) {
  return "e" + std::to_string(f.exp_bits) + "m" + std::to_string(f.man_bits);
}

std::uint32_t round_pack(double v, int dir, const Format& f, const Mode& mode) {
  if (std::isnan(v)) return f.nan_bits();
  const std::uint32_t sign = std::signbit(v) ? f.sign_mask() : 0u;
  const double a = std::fabs(v);
  if (std::isinf(a)) return sign | f.inf_bits();
  if (a == 0.0) return sign;
  // Direction of the exact magnitude relative to |v|.
  const int dm = std::signbit(v) ? -dir : dir;
  const int m = f.man_bits;
  const std::uint64_t hidden = std::uint64_t{1} << m;

  int e2 = 0;
  std::frexp(a, &e2);
  int ex = e2 - 1;  // a = 1.f * 2^ex
  bool sub = ex < f.emin();
  const double s = std::ldexp(a, sub ? (m - f.emin()) : (m - ex));  // exact: power-of-two scale
  const double fl = std::floor(s);
  const double frac = s - fl;
  auto q = static_cast<std::uint64_t>(fl);

  if (mode.rounding == Rounding::kNearestEven) {
    if (frac > 0.5 || (frac == 0.5 && (dm > 0 || (dm == 0 && (q & 1u))))) ++q;
    if (!sub && q == (hidden << 1)) {
      q = hidden;
      ++ex;
    }
  } else if (frac == 0.0 && dm < 0) {
    // |v| sits on the grid but the exact magnitude is just below it: truncation takes the
    // grid point below, which may lie in the binade below (twice as fine) or among subnormals.
    --q;
    if (!sub && q < hidden) {
      if (ex - 1 >= f.emin()) {
        --ex;
        q = (hidden << 1) - 1;
      } else {
        sub = true;
        q = hidden - 1;
      }
    }
  }

  if (sub) {
    // q counts units of the smallest subnormal; q == hidden is the smallest normal.
    if (q < hidden && mode.subnormals == Subnormals::kFlush) return sign;
    return sign | static_cast<std::uint32_t>(q);
  }
  if (ex > f.emax()) {
    return sign | (mode.rounding == Rounding::kNearestEven ? f.inf_bits() : f.max_finite_bits());
  }
  return sign | (static_cast<std::uint32_t>(ex + f.bias()) << m) |
         static_cast<std::uint32_t>(q - hidden);
}

double decode(std::uint32_t bits, const Format& f, Subnormals subnormals) {
  const bool neg = (bits & f.sign_mask()) != 0;
  const std::uint32_t expf = (bits >> f.man_bits) & f.exp_field_max();
  const std::uint32_t man = bits & f.man_mask();
  double mag = 0.0;
  if (expf == f.exp_field_max()) {
    if (man != 0) return std::numeric_limits<double>::quiet_NaN();
    mag = std::numeric_limits<double>::infinity();
  } else if (expf == 0) {
    mag = (man == 0 || subnormals == Subnormals::kFlush)
              ? 0.0
              : std::ldexp(static_cast<double>(man), f.emin() - f.man_bits);
  } else {
    mag = std::ldexp(static_cast<double>(man | (1u << f.man_bits)),
                     static_cast<int>(expf) - f.bias() - f.man_bits);
  }
  return neg ? -mag : mag;
}

bool is_nan(std::uint32_t bits, const Format& f) {
  return ((bits >> f.man_bits) & f.exp_field_max()) == f.exp_field_max() &&
         (bits & f.man_mask()) != 0;
}
bool is_inf(std::uint32_t bits, const Format& f) {
  return (bits & ~f.sign_mask() & f.bits_mask()) == f.inf_bits();
}
bool is_zero(std::uint32_t bits, const Format& f) {
  return (bits & ~f.sign_mask() & f.bits_mask()) == 0;
}
bool is_subnormal(std::uint32_t bits, const Format& f) {
  return ((bits >> f.man_bits) & f.exp_field_max()) == 0 && (bits & f.man_mask()) != 0;
}

std::uint32_t op_add(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m) {
  const double x = decode(a, f, m.subnormals);
  const double y = decode(b, f, m.subnormals);
  const double s = x + y;
  int dir = 0;
  if (std::isfinite(s)) {
    // TwoSum (Knuth): the exact error of the binary64 addition.
    const double bb = s - x;
    const double err = (x - (s - bb)) + (y - bb);
    dir = sign_of(err);
  }
  return round_pack(s, dir, f, m);
}

std::uint32_t op_sub(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m) {
  return op_add(a, b ^ f.sign_mask(), f, m);
}

std::uint32_t op_mul(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m) {
  const double x = decode(a, f, m.subnormals);
  const double y = decode(b, f, m.subnormals);
  const double p = x * y;
  int dir = 0;
  if (std::isfinite(p)) dir = sign_of(std::fma(x, y, -p));
  return round_pack(p, dir, f, m);
}

std::uint32_t op_div(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m) {
  const double x = decode(a, f, m.subnormals);
  const double y = decode(b, f, m.subnormals);
  const double q = x / y;
  int dir = 0;
  if (std::isfinite(q) && q != 0.0 && std::isfinite(y)) {
    // x - q*y is exact; x/y - q has its sign times sign(y).
    dir = sign_of(std::fma(-q, y, x)) * sign_of(y);
  }
  return round_pack(q, dir, f, m);
}

std::uint32_t op_sqrt(std::uint32_t a, const Format& f, const Mode& m) {
  const double x = decode(a, f, m.subnormals);
  if (x == 0.0) return std::signbit(x) ? f.sign_mask() : 0u;  // sqrt(-0) = -0
  const double r = std::sqrt(x);                              // NaN for x < 0
  int dir = 0;
  if (std::isfinite(r)) dir = sign_of(std::fma(-r, r, x));
  return round_pack(r, dir, f, m);
}

bool op_lt(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m) {
  return decode(a, f, m.subnormals) < decode(b, f, m.subnormals);
}
bool op_le(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m) {
  return decode(a, f, m.subnormals) <= decode(b, f, m.subnormals);
}
bool op_eq(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m) {
  return decode(a, f, m.subnormals) == decode(b, f, m.subnormals);
}

namespace {
// The value a comparator/mux passes on: in flush mode a subnormal operand leaves as signed zero.
std::uint32_t flushed(std::uint32_t bits, const Format& f, const Mode& m) {
  if (m.subnormals == Subnormals::kFlush && is_subnormal(bits, f)) return bits & f.sign_mask();
  return bits & f.bits_mask();
}
}  // namespace

std::uint32_t op_min(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m) {
  return op_lt(b, a, f, m) ? flushed(b, f, m) : flushed(a, f, m);
}
std::uint32_t op_max(std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m) {
  return op_lt(a, b, f, m) ? flushed(b, f, m) : flushed(a, f, m);
}

std::uint32_t from_double(double v, const Format& f, const Mode& m) {
  return round_pack(v, 0, f, m);
}

std::uint32_t from_int(std::int64_t v, const Format& f, const Mode& m) {
  // Split so that each half is exact in binary64; their sum carries the exact error's sign.
  const std::int64_t hi_bits = v & ~std::int64_t{0x1FFFFF};  // two's complement: floor to 2^21
  const auto hi = static_cast<double>(hi_bits);
  const auto lo = static_cast<double>(v - hi_bits);
  const double s = hi + lo;
  const double bb = s - hi;
  const double err = (hi - (s - bb)) + (lo - bb);
  return round_pack(s, sign_of(err), f, m);
}

std::int32_t to_int(std::uint32_t bits, const Format& f, const Mode& m) {
  const double x = decode(bits, f, m.subnormals);
  if (std::isnan(x)) return 0;
  const double t = std::trunc(x);
  if (t >= 2147483647.0) return std::numeric_limits<std::int32_t>::max();
  if (t <= -2147483648.0) return std::numeric_limits<std::int32_t>::min();
  return static_cast<std::int32_t>(t);
}

std::string bit_groups(std::uint32_t bits, const Format& f) {
  std::string s;
  s += (bits & f.sign_mask()) ? '1' : '0';
  s += '.';
  for (int i = f.exp_bits - 1; i >= 0; --i)
    s += ((bits >> (f.man_bits + i)) & 1u) ? '1' : '0';
  s += '.';
  for (int i = f.man_bits - 1; i >= 0; --i)
    s += ((bits >> i) & 1u) ? '1' : '0';
  return s;
}

}  // namespace saarcor::ff
