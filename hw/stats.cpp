// Statistics registry (docs/hw.md): storage, JSON dump and time series.
#include "hw/stats.h"

#include <charconv>
#include <cmath>
#include <stdexcept>

namespace saarcor::hw {

void Histogram::sample(double v) {
  ++count;
  sum += v;
  if (v < lo) {
    ++underflow;
    return;
  }
  const double pos = (v - lo) / width;
  if (pos >= static_cast<double>(buckets.size())) {
    ++overflow;
    return;
  }
  ++buckets[static_cast<std::size_t>(pos)];
}

std::string json_escape(const std::string& s) {
  std::string out;
  out.reserve(s.size() + 2);
  for (char ch : s) {
    switch (ch) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(ch) < 0x20) {
          static const char* hex = "0123456789abcdef";
          out += "\\u00";
          out += hex[(ch >> 4) & 15];
          out += hex[ch & 15];
        } else {
          out += ch;
        }
    }
  }
  return out;
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";  // JSON has no inf/nan
  if (v == std::floor(v) && std::fabs(v) < 9.0e15) {
    return std::to_string(static_cast<long long>(v));
  }
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip form
  return std::string(buf, r.ptr);
}

Stats::Entry& Stats::declare(const std::string& name, const std::string& unit,
                             const std::string& desc, Kind kind) {
  if (name.empty() || name.front() == '.' || name.back() == '.' ||
      name.find("..") != std::string::npos) {
    throw std::logic_error("stats: malformed statistic name '" + name + "'");
  }
  if (index_.count(name) != 0) {
    throw std::logic_error("stats: statistic '" + name + "' declared twice");
  }
  if (!series_.empty()) {
    throw std::logic_error("stats: statistic '" + name +
                           "' declared after the time series started");
  }
  auto e = std::make_unique<Entry>();
  e->name = name;
  e->unit = unit;
  e->desc = desc;
  e->kind = kind;
  index_[name] = entries_.size();
  entries_.push_back(std::move(e));
  return *entries_.back();
}

Counter& Stats::counter(const std::string& name, const std::string& unit, const std::string& desc) {
  Entry& e = declare(name, unit, desc, Kind::kCounter);
  e.c = std::make_unique<Counter>();
  return *e.c;
}

Average& Stats::average(const std::string& name, const std::string& unit, const std::string& desc) {
  Entry& e = declare(name, unit, desc, Kind::kAverage);
  e.a = std::make_unique<Average>();
  return *e.a;
}

Histogram& Stats::histogram(const std::string& name, const std::string& unit,
                            const std::string& desc, double lo, double width, int buckets) {
  if (!(width > 0.0) || buckets <= 0) {
    throw std::logic_error("stats: histogram '" + name + "' needs width > 0 and buckets > 0");
  }
  Entry& e = declare(name, unit, desc, Kind::kHistogram);
  e.h = std::make_unique<Histogram>();
  e.h->lo = lo;
  e.h->width = width;
  e.h->buckets.assign(static_cast<std::size_t>(buckets), 0);
  return *e.h;
}

void Stats::formula(const std::string& name, const std::string& unit, const std::string& desc,
                    std::function<double()> fn) {
  Entry& e = declare(name, unit, desc, Kind::kFormula);
  e.f = std::move(fn);
}

double Stats::entry_value(const Entry& e) const {
  switch (e.kind) {
    case Kind::kCounter:
      return static_cast<double>(e.c->value);
    case Kind::kAverage:
      return e.a->mean();
    case Kind::kHistogram:
      return static_cast<double>(e.h->count);
    case Kind::kFormula:
      return e.f();
  }
  return 0.0;
}

double Stats::value(const std::string& name) const {
  auto it = index_.find(name);
  if (it == index_.end()) throw std::logic_error("stats: unknown statistic '" + name + "'");
  return entry_value(*entries_[it->second]);
}

const Counter& Stats::get_counter(const std::string& name) const {
  auto it = index_.find(name);
  if (it == index_.end() || entries_[it->second]->kind != Kind::kCounter) {
    throw std::logic_error("stats: no counter named '" + name + "'");
  }
  return *entries_[it->second]->c;
}

std::vector<std::string> Stats::names() const {
  std::vector<std::string> out;
  out.reserve(index_.size());
  for (const auto& [name, idx] : index_)
    out.push_back(name);
  return out;
}

std::string Stats::json() const {
  static const char* kinds[] = {"counter", "average", "histogram", "formula"};
  std::string out = "{\n";
  bool first = true;
  for (const auto& [name, idx] : index_) {
    const Entry& e = *entries_[idx];
    if (!first) out += ",\n";
    first = false;
    out += "  \"" + json_escape(name) + "\": {\"kind\": \"" + kinds[static_cast<int>(e.kind)] +
           "\", \"unit\": \"" + json_escape(e.unit) + "\", \"desc\": \"" + json_escape(e.desc) +
           "\", \"value\": " + json_number(entry_value(e));
    if (e.kind == Kind::kAverage) {
      out += ", \"count\": " + std::to_string(e.a->count);
    }
    if (e.kind == Kind::kHistogram) {
      out += ", \"lo\": " + json_number(e.h->lo) + ", \"width\": " + json_number(e.h->width) +
             ", \"mean\": " +
             json_number(e.h->count ? e.h->sum / static_cast<double>(e.h->count) : 0.0) +
             ", \"underflow\": " + std::to_string(e.h->underflow) +
             ", \"overflow\": " + std::to_string(e.h->overflow) + ", \"buckets\": [";
      for (std::size_t i = 0; i < e.h->buckets.size(); ++i) {
        if (i) out += ", ";
        out += std::to_string(e.h->buckets[i]);
      }
      out += "]";
    }
    out += "}";
  }
  out += "\n}\n";
  return out;
}

void Stats::sample(std::uint64_t cycle) {
  if (series_.empty()) {
    series_entries_.clear();
    series_names_.clear();
    series_columns_.clear();
    for (const auto& [name, idx] : index_) {
      if (entries_[idx]->kind == Kind::kHistogram) continue;
      series_entries_.push_back(idx);
      series_names_.push_back(name);
      if (entries_[idx]->c) series_columns_[entries_[idx]->c.get()] = series_names_.size();
    }
  }
  std::vector<double> row;
  row.reserve(series_entries_.size() + 1);
  row.push_back(static_cast<double>(cycle));
  for (std::size_t idx : series_entries_)
    row.push_back(entry_value(*entries_[idx]));
  series_.push_back(std::move(row));
}

std::size_t Stats::time_series_column(const Counter& c) const {
  const auto it = series_columns_.find(&c);
  if (it == series_columns_.end())
    throw std::logic_error("stats: the counter is not in the time series");
  return it->second;
}

std::string Stats::time_series_json() const {
  std::string out = "{\"period\": " + std::to_string(period_) + ", \"names\": [";
  for (std::size_t i = 0; i < series_names_.size(); ++i) {
    if (i) out += ", ";
    out += "\"" + json_escape(series_names_[i]) + "\"";
  }
  out += "], \"samples\": [";
  for (std::size_t r = 0; r < series_.size(); ++r) {
    out += r ? ",\n  [" : "\n  [";
    for (std::size_t i = 0; i < series_[r].size(); ++i) {
      if (i) out += ", ";
      out += json_number(series_[r][i]);
    }
    out += "]";
  }
  out += "]}\n";
  return out;
}

}  // namespace saarcor::hw
