// `saarcor sample-check` (testbench/sample_check.h, docs/sampling.md).
#include "testbench/sample_check.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>

#include "host/builtin_scenes.h"
#include "host/image_builder.h"
#include "host/scene.h"
#include "testbench/covering_design.h"
#include "testbench/render_cmd.h"

namespace saarcor {
namespace {

const covering::Config& config_named(const std::string& name) {
  for (const covering::Config& c : covering::configs())
    if (name == c.name) return c;
  std::string known;
  for (const covering::Config& c : covering::configs())
    known += std::string(known.empty() ? "" : ", ") + c.name;
  throw std::runtime_error("bad --config '" + name + "': one of " + known);
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The frame's value of each checked figure.
std::vector<double> figure_values(const CycleFrame& c) {
  std::vector<double> v = {static_cast<double>(c.cycles), c.fps};
  for (int k = 0; k < units::kFigureCount; ++k)
    if (units::kFigures[k].in_report) v.push_back(c.figures.at(k));
  return v;
}

std::vector<SampleInterval> figure_intervals(const SampleSummary& s) {
  std::vector<SampleInterval> v = {s.cycles, s.fps};
  for (int k = 0; k < units::kFigureCount; ++k)
    if (units::kFigures[k].in_report) v.push_back(s.figures[static_cast<std::size_t>(k)]);
  return v;
}

}  // namespace

const std::vector<std::string>& sample_check_figures() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = {"cycles", "fps"};
    for (int k = 0; k < units::kFigureCount; ++k)
      if (units::kFigures[k].in_report) n.emplace_back(units::kFigures[k].name);
    return n;
  }();
  return names;
}

bool sample_check_relative(const std::string& figure) {
  return !figure.starts_with("usage.") && !figure.starts_with("cache_hit.");
}

memif::MemoryImage sample_check_image(const std::string& scene, const std::string& res) {
  const Resolution r = parse_resolution(res);
  const std::string file = std::filesystem::path(scene).filename().string();
  const std::uint32_t bank_mb = scene == "builtin:terrain"                              ? 32
                                : file.starts_with("Recip") || file.starts_with("2Cyl") ? 8
                                                                                        : 4;
  host::ImageParams ip;
  ip.width = r.width;
  ip.height = r.height;
  ip.bank_words = bank_mb * 262144u;
  return host::build_image(host::load_scene(scene), ip).image;
}

std::vector<std::string> sample_check_scenes(const std::string& references, int models) {
  std::vector<std::string> s;
  for (const std::string& n : host::builtin_scene_names())
    s.push_back("builtin:" + n);
  static const char* const kModels[] = {"ReciprocatingSaw/ReciprocatingSaw.gltf",
                                        "2CylinderEngine/2CylinderEngine.gltf",
                                        "VC/VC.gltf",
                                        "DamagedHelmet/DamagedHelmet.gltf",
                                        "CesiumMilkTruck/CesiumMilkTruck.gltf",
                                        "CesiumMan/CesiumMan.gltf",
                                        "Duck/Duck.gltf",
                                        "SpheresScaledInstances/spheres_scaled_instances.gltf",
                                        "BoxTextured/BoxTextured.gltf",
                                        "SimpleMeshes/SimpleMeshes.gltf",
                                        "RiggedSimple/RiggedSimple.gltf",
                                        "Box/Box.gltf"};
  int found = 0;
  for (const char* m : kModels) {
    const std::filesystem::path p = std::filesystem::path(references) / m;
    if (found < models && std::filesystem::exists(p)) {
      s.push_back(p.string());
      ++found;
    }
  }
  if (found < models)
    throw std::runtime_error("sample-check: " + std::to_string(found) + " of the " +
                             std::to_string(models) + " reference models under '" + references +
                             "'");
  return s;
}

SampleCase run_sample_case(const memif::MemoryImage& image, const std::string& config,
                           const SampleSpec& spec) {
  const covering::Config& cf = config_named(config);
  const units::CycleParams p = covering::params_of(cf);
  CycleRunOptions o;
  o.shading = covering::shading_of(cf);
  SampleCase c;
  c.config = config;
  auto t0 = std::chrono::steady_clock::now();
  const CycleFrame full = run_cycle(image, p, o);
  c.full_seconds = seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  const CycleFrame sampled = run_sampled(image, p, o, spec);
  c.sampled_seconds = seconds_since(t0);
  c.full = figure_values(full);
  c.estimate = figure_values(sampled);
  c.packets = full.packets;
  c.packets_simulated = sampled.sampling ? sampled.sampling->packets_simulated : full.packets;
  if (!sampled.sampling) {  // the plan held every packet: the run was whole, exact
    c.ci.assign(c.full.size(), SampleInterval{});
    for (std::size_t i = 0; i < c.full.size(); ++i)
      c.ci[i] = {c.estimate[i], c.estimate[i]};
    return c;
  }
  check_sampled_packets(image, p, o.shading, sampled);
  c.covariate_seconds = sampled.sampling->covariate_seconds;
  c.windows = sampled.sampling->windows;
  c.defeated = sampled.sampling->defeated;
  c.trusted = c.defeated.empty();
  c.ci = figure_intervals(*sampled.sampling);
  return c;
}

namespace {

double case_error(const SampleCase& c, std::size_t f) {
  const double d = std::abs(c.estimate[f] - c.full[f]);
  if (!sample_check_relative(sample_check_figures()[f])) return d;
  return c.full[f] == 0 ? (d == 0 ? 0 : 100) : 100.0 * d / std::abs(c.full[f]);
}

nlohmann::json figure_summary(const std::vector<SampleCase>& cases, std::size_t f) {
  double sum = 0, max = 0;
  int n = 0, trusted = 0, covered = 0;
  std::string worst;
  for (const SampleCase& c : cases) {
    const double e = case_error(c, f);
    sum += e;
    ++n;
    if (e >= max) {
      max = e;
      worst = c.scene + " " + c.res + " [" + c.config + "]";
    }
    if (!c.trusted) continue;
    ++trusted;
    // A tolerance of one part in 1e9 for the rounding of an interval that is a single value.
    const double tol = 1e-9 * std::max(1.0, std::abs(c.full[f]));
    covered += c.ci[f].low - tol <= c.full[f] && c.full[f] <= c.ci[f].high + tol ? 1 : 0;
  }
  return {{"figure", sample_check_figures()[f]},
          {"error", sample_check_relative(sample_check_figures()[f]) ? "%" : "points"},
          {"mean_abs_error", n ? sum / n : 0.0},
          {"max_abs_error", max},
          {"worst", worst},
          {"coverage_pct", trusted ? 100.0 * covered / trusted : 0.0},
          {"cases_with_interval", trusted}};
}

}  // namespace

nlohmann::json sample_check_summary(const std::vector<SampleCase>& cases) {
  nlohmann::json j;
  j["cases"] = cases.size();
  int defeated = 0;
  for (const SampleCase& c : cases)
    defeated += c.trusted ? 0 : 1;
  j["cases_defeated"] = defeated;
  j["figures"] = nlohmann::json::array();
  for (std::size_t f = 0; f < sample_check_figures().size(); ++f)
    j["figures"].push_back(figure_summary(cases, f));
  // Full s, sampled s (covariate included), smallest ratio, covariate s.
  std::map<std::string, std::array<double, 4>> host;
  for (const SampleCase& c : cases) {
    auto [it, fresh] = host.try_emplace(c.res, std::array<double, 4>{0, 0, 1e300, 0});
    it->second[0] += c.full_seconds;
    it->second[1] += c.sampled_seconds;
    it->second[2] = std::min(it->second[2], c.full_seconds / std::max(c.sampled_seconds, 1e-9));
    it->second[3] += c.covariate_seconds;
  }
  for (const auto& [res, h] : host)
    j["host"][res] = {{"full_seconds", h[0]},
                      {"sampled_seconds", h[1]},
                      {"covariate_seconds", h[3]},
                      {"ratio", h[1] > 0 ? h[0] / h[1] : 0.0},
                      {"smallest_case_ratio", h[2]}};
  return j;
}

std::string sample_check_text(const nlohmann::json& s) {
  std::string t;
  char buf[256];
  std::snprintf(buf, sizeof buf, "%d cases, %d defeat the sampling (no interval)\n",
                s["cases"].get<int>(), s["cases_defeated"].get<int>());
  t += buf;
  t += "figure                        error    mean     max  coverage (cases)  worst case\n";
  for (const nlohmann::json& f : s["figures"]) {
    std::snprintf(buf, sizeof buf, "%-28s %6s %7.3f %7.3f  %6.1f %% (%d)  %s\n",
                  f["figure"].get<std::string>().c_str(), f["error"].get<std::string>().c_str(),
                  f["mean_abs_error"].get<double>(), f["max_abs_error"].get<double>(),
                  f["coverage_pct"].get<double>(), f["cases_with_interval"].get<int>(),
                  f["worst"].get<std::string>().c_str());
    t += buf;
  }
  for (const auto& [res, h] : s["host"].items()) {
    std::snprintf(
        buf, sizeof buf,
        "host time at %s: full %.1f s, sampled %.1f s (covariate %.2f s), ratio %.1fx (smallest "
        "case %.1fx)\n",
        res.c_str(), h["full_seconds"].get<double>(), h["sampled_seconds"].get<double>(),
        h["covariate_seconds"].get<double>(), h["ratio"].get<double>(),
        h["smallest_case_ratio"].get<double>());
    t += buf;
  }
  return t;
}

namespace {

void print_case(const SampleCase& c) {
  std::printf("%-44s %-9s %-27s cycles %11.0f est %11.0f (%+.2f %%) [%s] %5.1fx%s\n",
              c.scene.substr(std::max<std::size_t>(c.scene.size(), 44) - 44).c_str(), c.res.c_str(),
              c.config.c_str(), c.full[0], c.estimate[0],
              c.full[0] > 0 ? 100.0 * (c.estimate[0] - c.full[0]) / c.full[0] : 0.0,
              c.trusted ? (c.ci[0].low <= c.full[0] && c.full[0] <= c.ci[0].high ? "in" : "OUT")
                        : "no interval",
              c.full_seconds / std::max(c.sampled_seconds, 1e-9),
              c.trusted ? "" : ("  (" + c.defeated + ")").c_str());
  std::fflush(stdout);
}

nlohmann::json case_json(const SampleCase& c) {
  nlohmann::json j = {{"scene", c.scene},
                      {"res", c.res},
                      {"config", c.config},
                      {"full_seconds", c.full_seconds},
                      {"sampled_seconds", c.sampled_seconds},
                      {"covariate_seconds", c.covariate_seconds},
                      {"packets", c.packets},
                      {"packets_simulated", c.packets_simulated},
                      {"windows", c.windows},
                      {"trusted", c.trusted}};
  if (!c.trusted) j["defeated"] = c.defeated;
  for (std::size_t f = 0; f < c.full.size(); ++f)
    j["figures"][sample_check_figures()[f]] = {
        {"full", c.full[f]}, {"estimate", c.estimate[f]}, {"ci95", {c.ci[f].low, c.ci[f].high}}};
  return j;
}

}  // namespace

int run_sample_check(const SampleCheckOptions& opts) {
  const SampleSpec spec = parse_sample_spec(opts.sample_spec);
  std::vector<std::string> configs = opts.configs;
  if (configs.empty())
    for (const covering::Config& c : covering::configs())
      configs.emplace_back(c.name);
  for (const std::string& c : configs)
    (void)config_named(c);  // a bad name fails before any frame runs
  for (const std::string& r : opts.res)
    (void)parse_resolution(r);
  if (!opts.json.empty() && !opts.json.ends_with(".json"))
    throw std::runtime_error("bad --json '" + opts.json + "': expected a .json file name");
  const std::vector<std::string> scenes =
      opts.scenes.empty() ? sample_check_scenes(opts.references, opts.models) : opts.scenes;
  std::vector<SampleCase> cases;
  for (const std::string& scene : scenes)
    for (const std::string& res : opts.res) {
      const memif::MemoryImage image = sample_check_image(scene, res);
      for (const std::string& config : configs) {
        SampleCase c = run_sample_case(image, config, spec);
        c.scene = scene;
        c.res = res;
        if (!opts.quiet) print_case(c);
        cases.push_back(std::move(c));
      }
    }
  const nlohmann::json summary = sample_check_summary(cases);
  std::printf("saarcor sample-check: %s\n%s", sample_spec_text(spec).c_str(),
              sample_check_text(summary).c_str());
  if (!opts.json.empty()) {
    nlohmann::json j = {{"sample", sample_spec_text(spec)}, {"summary", summary}};
    for (const SampleCase& c : cases)
      j["cases"].push_back(case_json(c));
    std::ofstream(opts.json) << j.dump(1) << '\n';
  }
  return 0;
}

}  // namespace saarcor
