// The request trace's line format (units/request_trace.h, docs/traces.md).
#include "units/request_trace.h"

#include <charconv>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace saarcor::units {

void append_hex(std::string& s, std::uint64_t bits, int digits) {
  static constexpr char kHex[] = "0123456789abcdef";
  for (int i = digits - 1; i >= 0; --i)
    s += kHex[(bits >> (4 * i)) & 0xfu];
}

std::string format_trace_line(const TraceLine& l) {
  std::string s;
  s.reserve(96 + l.txn.size());
  const auto num = [&s](std::uint64_t v, bool present) {
    s += present ? std::to_string(v) : "-";
    s += ' ';
  };
  num(l.cycle, l.cycle != kNoCycle);
  num(static_cast<std::uint64_t>(l.dynrtp), l.dynrtp >= 0);
  num(static_cast<std::uint64_t>(l.thread), l.thread >= 0);
  num(static_cast<std::uint64_t>(l.packet), true);
  num(l.seq, true);
  s += unit_name(l.unit);
  s += ' ';
  s += phase_name(l.phase);
  s += ' ';
  num(l.item, l.item != memif::kNone);
  num(static_cast<std::uint64_t>(l.steps), true);
  std::ostringstream mask;
  mask << "0x" << std::hex << l.mask;
  s += mask.str();
  s += ' ';
  s += ray_kind_name(l.kind);
  s += ' ';
  s += l.txn.empty() ? "-" : l.txn;
  return s;
}

namespace {

[[noreturn]] void bad(const std::string& text, const std::string& why) {
  throw std::runtime_error("trace line: " + why + ": '" + text.substr(0, 120) + "'");
}

std::uint64_t number(const std::string& text, const std::string& field, int base = 10) {
  std::uint64_t v = 0;
  const char* b = field.data();
  const char* e = b + field.size();
  if (base == 16) {
    if (field.size() < 3 || field[0] != '0' || field[1] != 'x') bad(text, "bad mask " + field);
    b += 2;
  }
  const auto r = std::from_chars(b, e, v, base);
  if (r.ec != std::errc{} || r.ptr != e || b == e) bad(text, "bad number '" + field + "'");
  return v;
}

template <class E>
E name_of(const std::string& text, const std::string& field, int count, const char* (*name)(E)) {
  for (int i = 0; i < count; ++i)  // ("?": an id no added unit took)
    if (field != "?" && field == name(static_cast<E>(i))) return static_cast<E>(i);
  bad(text, "unknown name '" + field + "'");
}

}  // namespace

TraceLine parse_trace_line(const std::string& text) {
  std::vector<std::string> f;
  std::istringstream in(text);
  for (std::string w; in >> w;)
    f.push_back(w);
  if (f.size() < 12) bad(text, "expected at least 12 columns, got " + std::to_string(f.size()));
  TraceLine l;
  const auto opt = [&](const std::string& w) { return w == "-" ? kNoCycle : number(text, w); };
  l.cycle = opt(f[0]);
  l.dynrtp = f[1] == "-" ? -1 : static_cast<int>(number(text, f[1]));
  l.thread = f[2] == "-" ? -1 : static_cast<int>(number(text, f[2]));
  l.packet = static_cast<int>(number(text, f[3]));
  l.seq = static_cast<std::uint32_t>(number(text, f[4]));
  l.unit = name_of<UnitId>(text, f[5], kMaxUnits, unit_name);
  l.phase = name_of<Phase>(text, f[6], kMaxPhases, phase_name);
  l.item = f[7] == "-" ? memif::kNone : static_cast<std::uint32_t>(number(text, f[7]));
  l.steps = static_cast<int>(number(text, f[8]));
  l.mask = number(text, f[9], 16);
  l.kind = name_of<RayKind>(text, f[10], kRayKinds, ray_kind_name);
  if (f.size() == 12 && f[11] == "-") return l;
  for (std::size_t i = 11; i < f.size(); ++i) {
    if (f[i] == "-") bad(text, "'-' among transaction tokens");
    if (!l.txn.empty()) l.txn += ' ';
    l.txn += f[i];
  }
  return l;
}

bool same_request(const TraceLine& a, const TraceLine& b) {
  return a.packet == b.packet && a.seq == b.seq && a.unit == b.unit && a.phase == b.phase &&
         a.item == b.item && a.steps == b.steps && a.mask == b.mask && a.kind == b.kind &&
         a.txn == b.txn;
}

}  // namespace saarcor::units
