// saarcor float-info / float-calc / float-gen (docs/fixedfloat.md). The ops come from
// the runtime-format functions of fixedfloat/format.h, the same code the MPFR tests check.
#include "testbench/float_tools.h"

#include <algorithm>
#include <cerrno>
#include <cfenv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fixedfloat/format.h"

namespace saarcor {
namespace {

using ff::Format;
using ff::Mode;

enum class Op { kAdd, kSub, kMul, kDiv, kSqrt, kLt, kLe, kEq, kMin, kMax };

struct OpName {
  std::string_view name;
  Op op;
};
constexpr OpName kOps[] = {
    {"add", Op::kAdd}, {"sub", Op::kSub}, {"mul", Op::kMul}, {"div", Op::kDiv}, {"sqrt", Op::kSqrt},
    {"lt", Op::kLt},   {"le", Op::kLe},   {"eq", Op::kEq},   {"min", Op::kMin}, {"max", Op::kMax}};

bool find_op(std::string_view name, Op* op) {
  for (const OpName& o : kOps) {
    if (o.name == name) {
      *op = o.op;
      return true;
    }
  }
  return false;
}

bool is_unary(Op op) {
  return op == Op::kSqrt;
}
bool is_compare(Op op) {
  return op == Op::kLt || op == Op::kLe || op == Op::kEq;
}

Format parse_format_or_throw(const std::string& text) {
  Format f;
  if (!ff::parse_format(text, &f)) {
    throw std::runtime_error("unknown float format '" + text +
                             "' (expected eEmM with 2 <= E <= 8, 1 <= M <= 23, or fp24/fp32/fp16)");
  }
  return f;
}

std::uint32_t eval(Op op, std::uint32_t a, std::uint32_t b, const Format& f, const Mode& m) {
  switch (op) {
    case Op::kAdd:
      return ff::op_add(a, b, f, m);
    case Op::kSub:
      return ff::op_sub(a, b, f, m);
    case Op::kMul:
      return ff::op_mul(a, b, f, m);
    case Op::kDiv:
      return ff::op_div(a, b, f, m);
    case Op::kSqrt:
      return ff::op_sqrt(a, f, m);
    case Op::kLt:
      return ff::op_lt(a, b, f, m) ? 1u : 0u;
    case Op::kLe:
      return ff::op_le(a, b, f, m) ? 1u : 0u;
    case Op::kEq:
      return ff::op_eq(a, b, f, m) ? 1u : 0u;
    case Op::kMin:
      return ff::op_min(a, b, f, m);
    case Op::kMax:
      return ff::op_max(a, b, f, m);
  }
  return 0;
}

int hex_digits(const Format& f) {
  return (f.bits() + 3) / 4;
}

void append_hex(std::string* s, std::uint32_t v, int digits) {
  static constexpr char kHex[] = "0123456789abcdef";
  for (int i = digits - 1; i >= 0; --i)
    s->push_back(kHex[(v >> (4 * i)) & 0xFu]);
}

std::string hex(std::uint32_t v, const Format& f) {
  std::string s;
  append_hex(&s, v, hex_digits(f));
  return s;
}

// Parses a hexadecimal encoding ("3f0000" or "0x3f0000") that must fit the format.
bool parse_hex(std::string_view t, const Format& f, std::uint32_t* out) {
  if (t.size() > 2 && t[0] == '0' && (t[1] == 'x' || t[1] == 'X')) t.remove_prefix(2);
  if (t.empty() || t.size() > 8) return false;
  std::uint32_t v = 0;
  for (char c : t) {
    int d;
    if (c >= '0' && c <= '9') {
      d = c - '0';
    } else if (c >= 'a' && c <= 'f') {
      d = c - 'a' + 10;
    } else if (c >= 'A' && c <= 'F') {
      d = c - 'A' + 10;
    } else {
      return false;
    }
    v = (v << 4) | static_cast<std::uint32_t>(d);
  }
  if ((v & ~f.bits_mask()) != 0) return false;
  *out = v;
  return true;
}

// Splits a line into whitespace-separated fields.
void split_fields(std::string_view line, std::vector<std::string_view>* fields) {
  fields->clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r'))
      ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r')
      ++i;
    if (i > start) fields->push_back(line.substr(start, i - start));
  }
}

// Exact decimal expansion of a finite binary64 value (glibc's printf prints exact digits).
std::string exact_decimal(double v) {
  if (v == 0.0) return std::signbit(v) ? "-0" : "0";
  int e2 = 0;
  std::frexp(v, &e2);
  // v = m * 2^(e2-53) with an integer m: at most 53 - e2 digits after the decimal point.
  const int frac_digits = std::max(0, 53 - e2);
  std::vector<char> buf(static_cast<std::size_t>(frac_digits) + 400);
  std::snprintf(buf.data(), buf.size(), "%.*f", frac_digits, v);
  std::string s(buf.data());
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0')
      s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  return s;
}

// Rounds a decimal (or hex-float, inf, nan) string into the format exactly: strtod in the three
// directed modes tells whether the text is a binary64 number and, if not, on which side of the
// nearest binary64 value it lies; round_pack then rounds once with that error sign.
std::uint32_t round_text(const std::string& text, const Format& f, const Mode& m, double* nearest) {
  auto parse = [&](int dir) {
    const int old = std::fegetround();
    std::fesetround(dir);
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    std::fesetround(old);
    if (end == text.c_str() || *end != '\0') {
      throw std::runtime_error("--value '" + text + "' is not a number");
    }
    return v;
  };
  const double v = parse(FE_TONEAREST);
  const double up = parse(FE_UPWARD);
  const double down = parse(FE_DOWNWARD);
  double r = v;
  int dir = 0;
  if (up != down && !std::isnan(v)) dir = (v == up) ? -1 : +1;
  // Beyond binary64's range strtod says inf; the largest binary64 plus the error sign keeps
  // truncation at the largest finite value of the format.
  if (std::isinf(v) && v > 0 && std::isfinite(down)) {
    r = down;
    dir = +1;
  } else if (std::isinf(v) && v < 0 && std::isfinite(up)) {
    r = up;
    dir = -1;
  }
  *nearest = v;
  return ff::round_pack(r, dir, f, m);
}

std::string value_line(std::uint32_t bits, const Format& f) {
  const double v = ff::decode(bits, f, ff::Subnormals::kKeep);
  std::string s = "0x" + hex(bits, f) + "  " + ff::bit_groups(bits, f) + "  ";
  if (std::isnan(v)) return s + "NaN";
  if (std::isinf(v)) return s + (v < 0 ? "-inf" : "inf");
  char g[64];
  std::snprintf(g, sizeof g, "%.9g", v);
  return s + g + "  (exact " + exact_decimal(v) + ")";
}

// Edge patterns: zeros, infinities, NaN, smallest/largest normals and subnormals, values near
// overflow and underflow, one and its neighbours, halves (for ties); each also negated.
std::vector<std::uint32_t> edge_operands(const Format& f) {
  const std::uint32_t top = f.exp_field_max();
  const std::uint32_t sign = f.sign_mask();
  const std::uint32_t man = f.man_mask();
  auto enc = [&](std::uint32_t e, std::uint32_t mm) { return (e << f.man_bits) | (mm & man); };
  std::vector<std::uint32_t> edges = {
      0u,
      f.inf_bits(),
      f.nan_bits(),
      f.max_finite_bits(),
      f.max_finite_bits() - 1u,
      enc(top - 1u, 0u),
      enc(1u, 0u),
      enc(1u, 1u),
      enc(2u, 0u),
      man,  // largest subnormal
      1u,   // smallest subnormal
      f.one_bits(),
      f.one_bits() + 1u,
      f.one_bits() - 1u,
      f.one_bits() | (1u << (f.man_bits - 1)),  // 1.5
      enc(static_cast<std::uint32_t>(f.bias()) - static_cast<std::uint32_t>(f.man_bits) - 1u, 0u),
      enc(static_cast<std::uint32_t>(f.bias()) + static_cast<std::uint32_t>(f.man_bits) + 1u, 0u),
      enc(static_cast<std::uint32_t>(f.bias() / 2), 0u),  // squares near the smallest normal
      enc(static_cast<std::uint32_t>(f.bias() + f.bias() / 2 + 1), man),  // squares overflow
  };
  for (auto& e : edges)
    e &= f.bits_mask();
  const std::size_t n_edges = edges.size();
  for (std::size_t i = 0; i < n_edges; ++i)
    edges.push_back(edges[i] | sign);
  return edges;
}

std::uint32_t random_mantissa(std::mt19937_64& rng, const Format& f) {
  const std::uint32_t man = f.man_mask();
  switch (rng() % 4) {
    case 0:
      return 0u;
    case 1:
      return man;
    case 2:
      return static_cast<std::uint32_t>(rng() % 4);
    default:
      return static_cast<std::uint32_t>(rng()) & man;
  }
}

std::uint32_t random_operand(std::mt19937_64& rng, const Format& f) {
  return static_cast<std::uint32_t>(rng()) & f.bits_mask();
}

// One operand pair, a quarter each: edge against edge, edge against random, nearby exponents
// (cancellation, carries, ties), random against random.
void random_pair(std::mt19937_64& rng, const Format& f, const std::vector<std::uint32_t>& edges,
                 std::uint32_t* a_out, std::uint32_t* b_out) {
  const std::uint32_t top = f.exp_field_max();
  const std::uint32_t sign = f.sign_mask();
  const std::uint32_t man = f.man_mask();
  auto enc = [&](std::uint32_t e, std::uint32_t mm) { return (e << f.man_bits) | (mm & man); };
  std::uint32_t a;
  std::uint32_t b;
  switch (rng() % 4) {
    case 0:  // edge against edge
      a = edges[rng() % edges.size()];
      b = edges[rng() % edges.size()];
      break;
    case 1:  // edge against random
      a = edges[rng() % edges.size()];
      b = random_operand(rng, f);
      if (rng() % 2) std::swap(a, b);
      break;
    case 2: {  // nearby exponents: cancellation, carries, ties
      a = random_operand(rng, f);
      const int ea = static_cast<int>((a >> f.man_bits) & top);
      const int span = f.man_bits + 2;
      const int eb = std::clamp(ea + static_cast<int>(rng() % (2 * span + 1)) - span, 0,
                                static_cast<int>(top));
      b = (static_cast<std::uint32_t>(rng()) & sign) |
          enc(static_cast<std::uint32_t>(eb), random_mantissa(rng, f));
      break;
    }
    default:
      a = random_operand(rng, f);
      b = random_operand(rng, f);
      break;
  }
  *a_out = a;
  *b_out = b;
}

}  // namespace

void float_info(const FloatInfoOptions& opts, std::ostream& out) {
  const Format f = parse_format_or_throw(opts.format);
  const Mode keep{ff::Rounding::kNearestEven, ff::Subnormals::kKeep};
  const std::uint32_t epsilon = ff::from_double(std::ldexp(1.0, -f.man_bits), f, keep);
  out << "format           " << ff::format_name(f) << ": 1 sign, " << f.exp_bits << " exponent, "
      << f.man_bits << " mantissa bits (" << f.bits() << " bits, " << f.man_bits + 1
      << "-bit significand)\n";
  out << "bias             " << f.bias() << "\n";
  out << "exponent range   2^" << f.emin() << " .. 2^" << f.emax() << " (normal numbers)\n";
  out << "largest          " << value_line(f.max_finite_bits(), f) << "\n";
  out << "smallest normal  " << value_line(1u << f.man_bits, f) << "\n";
  out << "smallest subnorm " << value_line(1u, f) << " (read as 0 in flush mode)\n";
  out << "epsilon          " << value_line(epsilon, f) << " (2^-" << f.man_bits
      << ", ulp of 1.0)\n";
  out << "one              " << value_line(f.one_bits(), f) << "\n";
  out << "infinity         0x" << hex(f.inf_bits(), f) << "  " << ff::bit_groups(f.inf_bits(), f)
      << "\n";
  out << "NaN (canonical)  0x" << hex(f.nan_bits(), f) << "  " << ff::bit_groups(f.nan_bits(), f)
      << "\n";
  if (!opts.value.empty()) {
    out << "value            " << opts.value << " rounded into " << ff::format_name(f) << ":\n";
    for (const char* rnd : {"rne", "rtz"}) {
      const Mode m = ff::parse_mode(rnd, "keep");
      double nearest = 0.0;
      const std::uint32_t bits = round_text(opts.value, f, m, &nearest);
      out << "value (" << rnd << ")      " << value_line(bits, f);
      if (ff::is_subnormal(bits, f)) out << "  [subnormal: 0 in flush mode]";
      out << "\n";
    }
  }
}

std::uint64_t float_calc(const FloatCalcOptions& opts, std::istream& in, std::ostream& out) {
  const Format f = parse_format_or_throw(opts.format);
  const Mode m = ff::parse_mode(opts.round, opts.subnormals);
  const int digits = hex_digits(f);
  std::string line;
  std::string buffer;
  std::vector<std::string_view> fields;
  std::uint64_t line_no = 0;
  std::uint64_t answered = 0;
  auto fail = [&](const std::string& what) {
    out << buffer;  // everything answered so far, then stop
    out.flush();
    throw std::runtime_error("float-calc: line " + std::to_string(line_no) + ": " + what);
  };
  while (std::getline(in, line)) {
    ++line_no;
    split_fields(line, &fields);
    if (fields.empty() || fields[0][0] == '#') continue;  // blank lines and comments
    Op op;
    if (!find_op(fields[0], &op)) {
      fail("unknown op '" + std::string(fields[0]) +
           "' (expected add sub mul div sqrt lt le eq min max)");
    }
    const std::size_t want = is_unary(op) ? 2 : 3;
    if (fields.size() != want) {
      fail(std::string(fields[0]) + " takes " + std::to_string(want - 1) + " operand(s), got " +
           std::to_string(fields.size() - 1));
    }
    std::uint32_t a = 0;
    std::uint32_t b = 0;
    for (std::size_t i = 1; i < want; ++i) {
      if (!parse_hex(fields[i], f, i == 1 ? &a : &b)) {
        fail("operand '" + std::string(fields[i]) + "' is not a hex encoding of " +
             ff::format_name(f) + " (" + std::to_string(f.bits()) + " bits)");
      }
    }
    const std::uint32_t r = eval(op, a, b, f, m);
    if (is_compare(op)) {
      buffer.push_back(r ? '1' : '0');
    } else {
      append_hex(&buffer, r, digits);
    }
    buffer.push_back('\n');
    ++answered;
    if (buffer.size() >= (1u << 16)) {
      out << buffer;
      buffer.clear();
    }
  }
  out << buffer;
  out.flush();
  return answered;
}

void float_gen(const FloatGenOptions& opts, std::ostream& out) {
  Op op;
  if (!find_op(opts.op, &op)) {
    throw std::runtime_error("unknown op '" + opts.op +
                             "' (expected add sub mul div sqrt lt le eq min max)");
  }
  const Format f = parse_format_or_throw(opts.format);
  const Mode m = ff::parse_mode(opts.round, opts.subnormals);
  std::mt19937_64 rng(opts.seed);
  const std::vector<std::uint32_t> edges = edge_operands(f);
  const bool unary = is_unary(op);
  const bool compare = is_compare(op);
  const int digits = hex_digits(f);
  std::string buffer;
  for (std::uint64_t i = 0; i < opts.count; ++i) {
    std::uint32_t a;
    std::uint32_t b;
    random_pair(rng, f, edges, &a, &b);
    const std::uint32_t r = eval(op, a, b, f, m);
    append_hex(&buffer, a, digits);
    buffer.push_back(' ');
    if (!unary) {
      append_hex(&buffer, b, digits);
      buffer.push_back(' ');
    }
    if (compare) {
      buffer.push_back(r ? '1' : '0');
    } else {
      append_hex(&buffer, r, digits);
    }
    buffer.push_back('\n');
    if (buffer.size() >= (1u << 16)) {
      out << buffer;
      buffer.clear();
    }
  }
  out << buffer;
  out.flush();
}

int run_float_info(const FloatInfoOptions& opts) {
  float_info(opts, std::cout);
  return 0;
}

int run_float_calc(const FloatCalcOptions& opts) {
  std::ios::sync_with_stdio(false);
  float_calc(opts, std::cin, std::cout);
  return 0;
}

int run_float_gen(const FloatGenOptions& opts) {
  std::ios::sync_with_stdio(false);
  float_gen(opts, std::cout);
  return 0;
}

}  // namespace saarcor
