// The run folder of --out-dir (testbench/run_dir.h).
#include "testbench/run_dir.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <stdexcept>

#include "units/figures.h"

namespace saarcor {
namespace {

bool shell_safe(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
         std::string_view("_@%+=:,./-").find(c) != std::string_view::npos;
}

// A Table 4 figure's help by its dotted name (units/figures.h kFigures).
std::string figure_help(const std::string& name) {
  for (const units::FigureInfo& f : units::kFigures)
    if (name == f.name) return f.help;
  throw std::logic_error("no Table 4 figure named " + name);
}

std::string format_value(double v) {
  char buf[64];
  // Integers (counts, cycles) exactly; the rest at gem5's six decimals.
  if (std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 9007199254740992.0)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else
    std::snprintf(buf, sizeof buf, "%.6f", v);
  return buf;
}

void append_lines(std::string& s, const std::vector<StatLine>& lines) {
  for (const StatLine& l : lines) {
    char buf[512];
    std::snprintf(buf, sizeof buf, "%-56s %20s  # %s\n", l.name.c_str(),
                  format_value(l.value).c_str(), l.desc.c_str());
    s += buf;
  }
}

double num(const nlohmann::json& j) {
  return j.is_number() ? j.get<double>() : 0.0;
}

// What each counter of the models' reports counts (the last component of its name).
const std::map<std::string, std::string>& counter_descriptions() {
  static const std::map<std::string, std::string> d = {
      {"traversal_steps", "kd-tree traversal steps (inner, leaf and clip)"},
      {"leaves", "kd-tree leaves visited"},
      {"list_entries", "list entries read (objects and triangles)"},
      {"mailbox_skips", "list entries skipped by the mailbox"},
      {"transformations", "rays transformed (into object or unit-triangle space)"},
      {"intersections", "ray-triangle intersection tests"},
      {"rays_issued", "rays issued"},
      {"rays_returned", "rays returned"},
      {"add", "floating-point additions and subtractions"},
      {"mul", "floating-point multiplications"},
      {"div", "floating-point divisions"},
      {"sqrt", "floating-point square roots"},
      {"cmp", "floating-point comparisons"},
      {"total", "floating-point operations, all kinds"},
      {"inner_steps", "inner-node steps of the traversal unit"},
      {"clip_steps", "box-clip steps of the traversal unit"},
      {"clips", "box clips"},
      {"exit_only_clips", "box clips on the exit faces only"},
      {"list_steps", "list unit steps"},
      {"transformation_steps", "transformation unit steps"},
      {"shading_transformation_steps", "transformation unit steps for shading"},
      {"intersection_packets", "packets through the intersection unit"},
      {"sub_packets", "packets split by the traversal"},
      {"stack_drops", "traversal stack entries dropped"},
      {"empty_leaf_steps", "steps into empty leaves"},
      {"packets", "ray packets"},
      {"requests", "memory requests of the units"},
  };
  return d;
}

// Flattens numeric leaves under `prefix`; the description comes from the leaf's own name or, for
// a {total, per_ray} pair, from its parent's.
void flatten_counters(std::vector<StatLine>& lines, const nlohmann::json& j,
                      const std::string& prefix, const std::string& parent) {
  const auto& d = counter_descriptions();
  for (const auto& [key, value] : j.items()) {
    const std::string name = prefix.empty() ? key : prefix + "." + key;
    if (value.is_object()) {
      flatten_counters(lines, value, name, key);
      continue;
    }
    if (!value.is_number()) continue;
    std::string desc;
    if (key == "per_ray" || (key == "total" && d.count(parent) && parent != "ops")) {
      const auto it = d.find(parent);
      desc = (it != d.end() ? it->second : parent) + (key == "per_ray" ? ", per ray" : ", total");
    } else {
      const auto it = d.find(key);
      desc = it != d.end() ? it->second : key;
    }
    lines.push_back({name, value.get<double>(), desc});
  }
}

}  // namespace

std::string command_line_text(const std::vector<std::string>& argv) {
  std::string s;
  for (const std::string& w : argv) {
    if (!s.empty()) s += ' ';
    bool safe = !w.empty();
    for (char c : w)
      safe = safe && shell_safe(c);
    if (safe) {
      s += w;
      continue;
    }
    s += '\'';
    for (char c : w)
      s += c == '\'' ? std::string("'\\''") : std::string(1, c);
    s += '\'';
  }
  return s + "\n";
}

std::string stats_text(const std::vector<StatLine>& lines) {
  std::string s = "\n---------- Begin Simulation Statistics ----------\n";
  append_lines(s, lines);
  s += "\n---------- End Simulation Statistics   ----------\n";
  return s;
}

std::string stats_text_blocks(
    const std::vector<std::pair<std::string, std::vector<StatLine>>>& blocks) {
  std::string s;
  for (const auto& [title, lines] : blocks) {
    s += "\n---------- Begin Simulation Statistics ----------\n# " + title + "\n";
    append_lines(s, lines);
    s += "\n---------- End Simulation Statistics   ----------\n";
  }
  return s;
}

void append_cycle_stats(std::vector<StatLine>& lines, const nlohmann::json& c) {
  lines.push_back({"frame.cycles", num(c["cycles"]), "simulated cycles of the frame (cycles)"});
  lines.push_back({"frame.fps", num(c["fps"]), "frames per second at the modelled clock"});
  lines.push_back({"frame.rays", num(c["rays"]), "rays traced (count)"});
  lines.push_back({"frame.rays_per_s", num(c["rays_per_s"]), "rays per second, modelled"});
  lines.push_back({"frame.packets", num(c["packets"]), "ray packets (count)"});
  lines.push_back(
      {"frame.cycles_per_packet", num(c["cycles_per_packet"]), "cycles per packet (cycles)"});
  lines.push_back({"frame.simd_efficiency", num(c["simd_efficiency"]),
                   "active rays per packet step / packet width"});
  // The Table 4 figures as the report holds them, each with its help (units/figures.h).
  for (const char* group : {"usage", "cache_hit", "bandwidth_mb_s"})
    for (const auto& [key, v] : c[group].items()) {
      const std::string name = std::string(group) + "." + key;
      lines.push_back({"frame." + name, num(v), figure_help(name)});
    }
  for (const auto& [counter, v] : c["per_ray"].items()) {
    const auto it = counter_descriptions().find(counter);
    lines.push_back({"frame.per_ray." + counter, num(v),
                     (it != counter_descriptions().end() ? it->second : counter) + ", per ray"});
  }
  if (c.contains("stats")) {
    for (const auto& [name, s] : c["stats"].items()) {
      const std::string unit = s.value("unit", "");
      lines.push_back(
          {name, num(s["value"]), s.value("desc", "") + (unit.empty() ? "" : " (" + unit + ")")});
    }
  }
}

void append_counter_stats(std::vector<StatLine>& lines, const nlohmann::json& counters) {
  flatten_counters(lines, counters, "", "");
}

void check_out_dir(const std::string& dir) {
  if (dir.empty()) throw std::runtime_error("bad --out-dir '': expected a folder name");
  std::error_code ec;
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec))
    throw std::runtime_error("bad --out-dir '" + dir + "': a file of that name exists");
}

std::string run_file(const std::string& dir, const std::string& name) {
  return (std::filesystem::path(dir) / name).string();
}

nlohmann::json take_cycle_host(nlohmann::json& cycle) {
  nlohmann::json host = cycle.contains("host") ? cycle["host"] : nlohmann::json::object();
  cycle.erase("host");
  return host;
}

}  // namespace saarcor
