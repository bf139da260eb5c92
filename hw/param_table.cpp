// The parameter tables' checks and messages, shared by every table (hw/param_table.h).
#include "hw/param_table.h"

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

namespace saarcor::hw {
namespace {

// "1 or 3", "0, 1 or 2".
std::string choice_list(const std::vector<int>& values) {
  std::string s;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) s += i + 1 == values.size() ? " or " : ", ";
    s += std::to_string(values[i]);
  }
  return s;
}

}  // namespace

const char* param_type_name(ParamType t) {
  switch (t) {
    case ParamType::kInteger:
      return "integer";
    case ParamType::kReal:
      return "real";
    case ParamType::kBoolean:
      return "boolean";
    case ParamType::kChoice:
      return "choice";
  }
  return "?";
}

std::string format_param_value(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.15g", v);
  return buf;
}

std::string param_violation(const ParamInfo& p, double v) {
  if (p.type != ParamType::kReal && std::isfinite(v) && v != std::floor(v))
    return "expected an integer";
  if (p.type == ParamType::kBoolean && v != 0.0 && v != 1.0) return "expected 0 or 1";
  if (p.type == ParamType::kChoice) {
    for (int c : p.choices)
      if (v == c) return "";
    return "expected " + choice_list(p.choices) + " " + p.unit;
  }
  if (!(v >= p.min && v <= p.max))  // NaN included
    return "expected " + format_param_value(p.min) + ".." + format_param_value(p.max) + " " +
           p.unit;
  if (p.pow2) {
    const auto n = static_cast<std::uint64_t>(v);
    if (n == 0 || (n & (n - 1)) != 0) return "expected a power of two";
  }
  return "";
}

std::pair<std::string, std::string> split_key_value(const std::string& option,
                                                    const std::string& key_value) {
  const auto eq = key_value.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::runtime_error("bad " + option + " '" + key_value + "': expected KEY=VALUE");
  return {key_value.substr(0, eq), key_value.substr(eq + 1)};
}

double parse_param(const std::string& option, const ParamInfo& p, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  const std::string what = "bad " + option + " " + p.name + "=" + text + ": ";
  if (text.empty() || end != text.c_str() + text.size() || errno != 0 || !std::isfinite(v))
    throw std::runtime_error(what + "not a number");
  const std::string why = param_violation(p, v);
  if (!why.empty()) throw std::runtime_error(what + why);
  return v;
}

}  // namespace saarcor::hw
