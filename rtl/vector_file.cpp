// Reading and writing unit vector files (rtl/vector_file.h).
#include "rtl/vector_file.h"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace saarcor::rtl {
namespace {

std::uint32_t parse_field(const std::string& word, bool flag, const std::string& where) {
  if (flag) {
    if (word == "0") return 0;
    if (word == "1") return 1;
    throw std::runtime_error(where + "flag '" + word + "' is not 0 or 1");
  }
  if (word.empty() || word.size() > 6) {
    throw std::runtime_error(where + "'" + word + "' is not an fp24 encoding (1 to 6 hex digits)");
  }
  std::uint32_t v = 0;
  for (const char ch : word) {
    int d = -1;
    if (ch >= '0' && ch <= '9') d = ch - '0';
    if (ch >= 'a' && ch <= 'f') d = ch - 'a' + 10;
    if (ch >= 'A' && ch <= 'F') d = ch - 'A' + 10;
    if (d < 0) throw std::runtime_error(where + "'" + word + "' is not hex");
    v = v * 16u + static_cast<std::uint32_t>(d);
  }
  return v;
}

}  // namespace

VectorFile parse_vector_text(const std::string& text, const std::string& name) {
  VectorFile f;
  bool have_unit = false;
  std::istringstream in(text);
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string where = name + ": line " + std::to_string(line_no) + ": ";
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    if (line[0] == '#') {
      f.header.push_back(line);
      if (line.rfind("# unit: ", 0) == 0) {
        try {
          f.unit = units::parse_vector_unit(line.substr(8));
        } catch (const std::exception& e) {
          throw std::runtime_error(where + e.what());
        }
        have_unit = true;
      }
      continue;
    }
    if (!have_unit) throw std::runtime_error(where + "a vector before the '# unit: ' line");
    const auto& ins = units::vector_inputs(f.unit);
    const auto& outs = units::vector_outputs(f.unit);
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string x; words >> x;)
      w.push_back(x);
    if (w.size() != ins.size() + outs.size()) {
      throw std::runtime_error(where + std::to_string(w.size()) + " fields, the " +
                               units::vector_unit_name(f.unit) + " unit's vectors have " +
                               std::to_string(ins.size() + outs.size()));
    }
    VectorLine v;
    v.line = line_no;
    for (std::size_t i = 0; i < ins.size(); ++i)
      v.in.push_back(parse_field(w[i], units::vector_field_is_flag(ins[i]), where));
    for (std::size_t i = 0; i < outs.size(); ++i)
      v.out.push_back(parse_field(w[ins.size() + i], units::vector_field_is_flag(outs[i]), where));
    f.vectors.push_back(std::move(v));
  }
  if (!have_unit) throw std::runtime_error(name + ": no '# unit: ' line");
  return f;
}

VectorFile read_vector_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream s;
  s << in.rdbuf();
  return parse_vector_text(s.str(), path);
}

std::string format_vector_file(const VectorFile& file,
                               const std::vector<std::vector<std::uint32_t>>& outputs) {
  if (outputs.size() != file.vectors.size())
    throw std::runtime_error("format_vector_file: one output set per vector expected");
  const auto& ins = units::vector_inputs(file.unit);
  const auto& outs = units::vector_outputs(file.unit);
  std::string s;
  for (const std::string& h : file.header)
    s += h + "\n";
  char buf[16];
  auto field = [&](std::uint32_t v, bool flag) {
    std::snprintf(buf, sizeof buf, flag ? "%u" : "%06x", static_cast<unsigned>(v));
    return std::string(buf);
  };
  for (std::size_t k = 0; k < file.vectors.size(); ++k) {
    const VectorLine& v = file.vectors[k];
    std::string line;
    for (std::size_t i = 0; i < ins.size(); ++i)
      line += (i ? " " : "") + field(v.in[i], units::vector_field_is_flag(ins[i]));
    for (std::size_t i = 0; i < outs.size(); ++i)
      line += " " + field(outputs[k].at(i), units::vector_field_is_flag(outs[i]));
    s += line + "\n";
  }
  return s;
}

}  // namespace saarcor::rtl
