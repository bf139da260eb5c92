// Unit vector files: writing and checking their text (testbench/vector_file.h).
#include "testbench/vector_file.h"

#include <cstdint>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace saarcor {
namespace {

constexpr const char* kMagic = "# saarcor unit vectors 1";

std::string field_text(const std::string& field, std::uint32_t v) {
  char buf[16];
  if (units::vector_field_is_flag(field)) {
    std::snprintf(buf, sizeof buf, "%u", v);
  } else {
    std::snprintf(buf, sizeof buf, "%06x", v);
  }
  return buf;
}

// Text from the file as an error message shows it: control characters (a carriage return would
// break the one-line message) as \xNN.
std::string printable(const std::string& text) {
  std::string s;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", u);
      s += buf;
    } else {
      s += c;
    }
  }
  return s;
}

std::string words(const std::vector<std::string>& w) {
  std::string s;
  for (const std::string& x : w)
    s += (s.empty() ? "" : " ") + x;
  return s;
}

std::runtime_error bad_line(std::size_t number, const std::string& why) {
  return std::runtime_error("vector file line " + std::to_string(number) + ": " + why);
}

units::VectorUnit header_unit(const std::string& line, std::size_t number) {
  try {
    return units::parse_vector_unit(line.substr(8));
  } catch (const std::runtime_error& e) {
    throw bad_line(number, printable(e.what()));
  }
}

// One field of a vector line: a 0/1 flag or a 6-digit hex fp24 encoding, by the field's name.
std::uint32_t parse_field(const std::string& name, const std::string& tok, std::size_t number) {
  std::size_t used = 0;
  unsigned long v = 0;
  try {
    v = std::stoul(tok, &used, units::vector_field_is_flag(name) ? 10 : 16);
  } catch (const std::exception&) {
    used = 0;
  }
  const unsigned long limit = units::vector_field_is_flag(name) ? 1u : 0xffffffu;
  if (used != tok.size() || v > limit) {
    std::string why = "field ";
    why += name;
    why += " '";
    why += printable(tok);
    why += "' is not ";
    why += units::vector_field_is_flag(name) ? "0 or 1" : "a hex fp24 encoding";
    throw bad_line(number, why);
  }
  return static_cast<std::uint32_t>(v);
}

std::vector<std::uint32_t> parse_fields(const std::string& line, std::size_t number,
                                        const std::vector<std::string>& ins,
                                        const std::vector<std::string>& outs) {
  std::istringstream fields(line);
  std::vector<std::uint32_t> values;
  std::string tok;
  while (fields >> tok) {
    const std::size_t k = values.size();
    const std::string& name = k < ins.size()                 ? ins[k]
                              : k - ins.size() < outs.size() ? outs[k - ins.size()]
                                                             : std::string("(extra)");
    values.push_back(parse_field(name, tok, number));
  }
  return values;
}

// One vector line: its outputs against what the bit-accurate datapath computes from its inputs.
void check_vector_line(const std::string& line, std::size_t number, VectorCheck& r) {
  const auto& ins = units::vector_inputs(r.unit);
  const auto& outs = units::vector_outputs(r.unit);
  const std::vector<std::uint32_t> values = parse_fields(line, number, ins, outs);
  if (values.size() != ins.size() + outs.size()) {
    throw bad_line(number, std::to_string(values.size()) + " fields, a " +
                               units::vector_unit_name(r.unit) + " vector has " +
                               std::to_string(ins.size() + outs.size()));
  }
  const std::vector<std::uint32_t> input(values.begin(),
                                         values.begin() + static_cast<long>(ins.size()));
  std::vector<std::uint32_t> expected;
  try {
    expected = units::expected_outputs(r.unit, input);
  } catch (const std::runtime_error& e) {
    throw bad_line(number, e.what());
  }
  ++r.vectors;
  bool differs = false;
  for (std::size_t k = 0; k < outs.size(); ++k) {
    const std::uint32_t got = values[ins.size() + k];
    if (got == expected[k]) {
      continue;
    }
    differs = true;
    if (r.first_differences.size() < 5) {
      r.first_differences.push_back("line " + std::to_string(number) + ": " + outs[k] + " is " +
                                    field_text(outs[k], got) + ", the datapath gives " +
                                    field_text(outs[k], expected[k]));
    }
  }
  r.differing += differs ? 1 : 0;
}

}  // namespace

std::string format_vector_file(units::VectorUnit unit, const units::VectorCapture& capture,
                               const std::string& source) {
  const auto& ins = units::vector_inputs(unit);
  const auto& outs = units::vector_outputs(unit);
  std::string s = std::string(kMagic) + "\n";
  s += std::string("# unit: ") + units::vector_unit_name(unit) + "\n";
  s += "# format: fp24 (e7m16, bias 63), round to nearest even, subnormals flushed; encodings as "
       "6 hex digits, flags 0/1\n";
  s += "# inputs: " + words(ins) + "\n";
  s += "# outputs: " + words(outs) + "\n";
  s += "# source: " + source + ", " + std::to_string(capture.vectors.size()) + " of " +
       std::to_string(capture.transactions) + " transactions\n";
  for (const units::UnitVector& v : capture.vectors) {
    std::string line;
    for (std::size_t k = 0; k < v.in.size(); ++k) {
      line += (k == 0 ? "" : " ") + field_text(ins[k], v.in[k]);
    }
    for (std::size_t k = 0; k < v.out.size(); ++k) {
      line += " " + field_text(outs[k], v.out[k]);
    }
    s += line + "\n";
  }
  return s;
}

VectorCheck check_vector_text(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  std::size_t number = 0;
  bool have_unit = false;
  VectorCheck r;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();  // CRLF files read alike
    if (number == 1 && line != kMagic) {
      throw bad_line(number, "expected '" + std::string(kMagic) + "'");
    }
    if (line.empty()) {
      continue;
    }
    if (line[0] == '#') {
      if (line.rfind("# unit: ", 0) == 0) {
        r.unit = header_unit(line, number);
        have_unit = true;
      }
      continue;
    }
    if (!have_unit) {
      throw bad_line(number, "a vector before the '# unit: ' line");
    }
    check_vector_line(line, number, r);
  }
  if (number == 0) {
    throw bad_line(number, "empty file");
  }
  if (!have_unit) {
    throw bad_line(number, "no '# unit: ' line");
  }
  return r;
}

}  // namespace saarcor
