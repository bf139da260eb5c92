// Parameter tables (STYLE.md: gem5's parameters, each declared once with name, type, default,
// unit and one line of help; an unknown key is an error that names it).
//
// A ParamTable<S> binds dotted keys ("cache.list.items") to the fields of a plain struct S. Each
// parameter is declared once, by one of the typed declarations below, with its key, the field it
// binds, its unit, its range and its help. Its default is the default member initialiser of that
// field: S{} is the default configuration, and no table holds a second copy of a default.
//
//   integer(key, field, unit, min, max, help)       an integral field (not bool), min..max
//   power_of_two(key, field, unit, min, max, help)  the same, and a power of two
//   real(key, field, unit, min, max, help)          a float or double field, finite, min..max
//   boolean(key, field, help)                       a bool field, 0 or 1 (unit "bool")
//   choice(key, field, unit, {v1, v2, ...}, help)   an integral field, one of the values listed
//
// `field` is a data member pointer (&S::threads) or an accessor for a nested field
// ([](auto& s) -> auto& { return s.kd.leaf_size; }); the declared type must fit the field's C++
// type, which the declaration checks at compile time.
//
// apply(s, "KEY=VALUE") parses, validates and stores one value, or throws std::runtime_error with
// one line naming the key (an unknown key, a value that is not a number, not an integer, out of
// range, not a power of two, not one of the choices); a refused value changes nothing. check(s)
// validates every field of a configuration built in code the same way. describe(s) lists every
// parameter with s's value, in declaration order (the resolved configuration: config.json,
// --help, the README's key table); defaults() is describe(S{}).
#pragma once

#include <algorithm>
#include <functional>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace saarcor::hw {

enum class ParamType { kInteger, kReal, kBoolean, kChoice };
const char* param_type_name(ParamType t);  // "integer", "real", "boolean", "choice"

// One parameter as declared, with a value: a configuration's (describe) or the default (defaults).
struct ParamInfo {
  std::string name;  // the key, "cache.list.items"
  double value = 0.0;
  std::string unit;
  std::string help;
  double min = 0.0, max = 0.0;  // a choice's smallest and largest value, a boolean's 0 and 1
  bool pow2 = false;            // an integer that must be a power of two
  ParamType type = ParamType::kInteger;
  std::vector<int> choices;  // kChoice: the values allowed, ascending
};

// What is wrong with value `v` for parameter `p` ("expected 1..64 cycles"), "" when nothing.
std::string param_violation(const ParamInfo& p, double v);
// Splits "KEY=VALUE"; throws "bad <option> '<kv>': expected KEY=VALUE".
std::pair<std::string, std::string> split_key_value(const std::string& option,
                                                    const std::string& key_value);
// Parses `text` as a value of `p`; throws "bad <option> KEY=TEXT: <why>" (one line).
double parse_param(const std::string& option, const ParamInfo& p, const std::string& text);
// %.15g: every default and range bound as written in the declarations.
std::string format_param_value(double v);

template <class S>
class ParamTable {
 public:
  // `option` is the command-line option the values come from ("--set"); `known` opens the list of
  // keys an unknown key's error gives ("known" -> "(known: a, b)").
  explicit ParamTable(std::string option = "--set", std::string known = "known")
      : option_(std::move(option)), known_(std::move(known)) {}

  template <class Field>
  ParamTable& integer(std::string key, Field field, std::string unit, double min, double max,
                      std::string help) {
    static_assert(kIntegral<Field>, "an integer parameter binds an integral field");
    return add(declared(key, ParamType::kInteger, unit, min, max, help), field);
  }
  template <class Field>
  ParamTable& power_of_two(std::string key, Field field, std::string unit, double min, double max,
                           std::string help) {
    static_assert(kIntegral<Field>, "a power-of-two parameter binds an integral field");
    ParamInfo info = declared(key, ParamType::kInteger, unit, min, max, help);
    info.pow2 = true;
    return add(std::move(info), field);
  }
  template <class Field>
  ParamTable& real(std::string key, Field field, std::string unit, double min, double max,
                   std::string help) {
    static_assert(std::is_floating_point_v<FieldType<Field>>, "a real parameter binds a float");
    return add(declared(key, ParamType::kReal, unit, min, max, help), field);
  }
  template <class Field>
  ParamTable& boolean(std::string key, Field field, std::string help) {
    static_assert(std::is_same_v<FieldType<Field>, bool>, "a boolean parameter binds a bool");
    return add(declared(key, ParamType::kBoolean, "bool", 0.0, 1.0, help), field);
  }
  template <class Field>
  ParamTable& choice(std::string key, Field field, std::string unit, std::vector<int> values,
                     std::string help) {
    static_assert(kIntegral<Field>, "a choice parameter binds an integral field");
    if (values.empty() || !std::is_sorted(values.begin(), values.end()))
      throw std::logic_error("parameter " + key + ": choices must be listed, ascending");
    ParamInfo info = declared(key, ParamType::kChoice, unit, values.front(), values.back(), help);
    info.choices = std::move(values);
    return add(std::move(info), field);
  }

  // Applies "KEY=VALUE" (see the file comment); throws std::runtime_error naming the key.
  void apply(S& s, const std::string& key_value) const {
    const auto [key, text] = split_key_value(option_, key_value);
    const Param& p = find(key);
    p.set(s, parse_param(option_, p.info, text));
  }
  // Every field valid; throws std::runtime_error "bad KEY=VALUE: <why>" for the first that is not.
  void check(const S& s) const {
    for (const Param& p : params_) {
      const double v = p.get(s);
      const std::string why = param_violation(p.info, v);
      if (!why.empty())
        throw std::runtime_error("bad " + p.info.name + "=" + format_param_value(v) + ": " + why);
    }
  }
  bool has(const std::string& key) const {
    for (const Param& p : params_)
      if (p.info.name == key) return true;
    return false;
  }
  std::vector<ParamInfo> describe(const S& s) const {
    std::vector<ParamInfo> v;
    v.reserve(params_.size());
    for (const Param& p : params_) {
      v.push_back(p.info);
      v.back().value = p.get(s);
    }
    return v;
  }
  std::vector<ParamInfo> defaults() const { return describe(S{}); }
  std::size_t size() const { return params_.size(); }

 private:
  template <class Field>
  using FieldType = std::remove_cvref_t<std::invoke_result_t<Field&, S&>>;
  template <class Field>
  static constexpr bool kIntegral =
      std::is_integral_v<FieldType<Field>> && !std::is_same_v<FieldType<Field>, bool>;

  struct Param {
    ParamInfo info;
    std::function<double(const S&)> get;
    std::function<void(S&, double)> set;
  };

  static ParamInfo declared(std::string& key, ParamType type, std::string unit, double min,
                            double max, std::string& help) {
    ParamInfo info;
    info.name = std::move(key);
    info.unit = std::move(unit);
    info.help = std::move(help);
    info.min = min;
    info.max = max;
    info.type = type;
    return info;
  }

  template <class Field>
  ParamTable& add(ParamInfo info, Field field) {
    using T = FieldType<Field>;
    if (has(info.name)) throw std::logic_error("parameter " + info.name + " declared twice");
    params_.push_back({std::move(info),
                       [field](const S& s) { return static_cast<double>(std::invoke(field, s)); },
                       [field](S& s, double v) { std::invoke(field, s) = static_cast<T>(v); }});
    return *this;
  }

  const Param& find(const std::string& key) const {
    std::string known;
    for (const Param& p : params_) {
      if (p.info.name == key) return p;
      known += (known.empty() ? "" : ", ") + p.info.name;
    }
    throw std::runtime_error("unknown " + option_ + " key '" + key + "' (" + known_ + ": " + known +
                             ")");
  }

  std::string option_, known_;
  std::vector<Param> params_;
};

}  // namespace saarcor::hw
