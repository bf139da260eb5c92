// `saarcor sweep`: the cycle model over a grid of configurations (testbench/sweep_cmd.h).
#include "testbench/sweep_cmd.h"

#include <cinttypes>
#include <cstdio>
#include <optional>
#include <set>
#include <stdexcept>

#include "host/tree_settings.h"
#include "testbench/compare.h"
#include "testbench/cycle_render.h"
#include "testbench/image_io.h"
#include "units/cycle_params.h"

namespace saarcor {

SweepAxis parse_sweep_axis(const std::string& text) {
  auto bad = [&](const std::string& why) {
    return std::runtime_error("bad --vary '" + text + "': " + why);
  };
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw bad("expected KEY=V1,V2,...");
  }
  SweepAxis axis;
  axis.key = text.substr(0, eq);
  std::set<std::string> seen;
  std::size_t from = eq + 1;
  while (true) {
    const auto comma = text.find(',', from);
    std::string v = text.substr(from, comma == std::string::npos ? comma : comma - from);
    if (v.empty()) {
      throw bad("an empty value");
    }
    if (!seen.insert(v).second) {
      throw bad("the value " + v + " twice");
    }
    axis.values.push_back(std::move(v));
    if (comma == std::string::npos) {
      break;
    }
    from = comma + 1;
  }
  return axis;
}

std::vector<std::vector<std::string>> sweep_points(const std::vector<SweepAxis>& axes,
                                                   const CycleRenderOptions& base) {
  if (axes.empty()) {
    throw std::runtime_error("sweep needs at least one --vary KEY=V1,V2,...");
  }
  resolve_cycle_params(base);  // --preset and --set errors name those options
  std::set<std::string> keys;
  std::size_t count = 1;
  for (const SweepAxis& a : axes) {
    if (!keys.insert(a.key).second) {
      throw std::runtime_error("bad --vary " + a.key + ": the key is varied twice");
    }
    count *= a.values.size();
    if (count > kMaxSweepPoints) {
      throw std::runtime_error("sweep of more than " + std::to_string(kMaxSweepPoints) +
                               " points: vary fewer keys or values");
    }
  }
  std::vector<std::vector<std::string>> points(count);
  for (std::size_t i = 0; i < count; ++i) {
    std::size_t rest = i;
    for (std::size_t a = axes.size(); a-- > 0;) {
      const std::vector<std::string>& vs = axes[a].values;
      points[i].insert(points[i].begin(), axes[a].key + "=" + vs[rest % vs.size()]);
      rest /= vs.size();
    }
  }
  for (const std::vector<std::string>& p : points) {
    CycleRenderOptions o = base;
    o.set.insert(o.set.end(), p.begin(), p.end());
    try {
      resolve_cycle_params(o);
    } catch (const std::runtime_error& e) {
      // The key table speaks of --set; the value came from --vary (or the combination is bad).
      std::string msg = e.what();
      if (msg.starts_with("bad --set ")) {
        msg = "bad --vary " + msg.substr(10);
      } else if (msg.starts_with("unknown --set ")) {
        msg = "unknown --vary " + msg.substr(14);
      }
      throw std::runtime_error(msg + " (sweep point " + join_words(p) + ")");
    }
  }
  return points;
}

void check_sweep_point(const FrameResult& frame, const FrameResult& reference,
                       const std::string& where) {
  const CompareResult hits = compare_hits(frame.hits, reference.hits);
  const bool same_image = frame.image.rgb == reference.image.rgb;
  if (!hits.bit_identical || !same_image) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "same triangle %.4f %%, image %s", hits.same_triangle_pct,
                  same_image ? "identical" : "differs");
    throw std::runtime_error("sweep point " + where +
                             ": the cycle model's hit records or image differ from the "
                             "functional model's (" +
                             buf + ")");
  }
  if (frame.rays != reference.rays) {
    throw std::runtime_error("sweep point " + where + ": " + std::to_string(frame.rays) +
                             " rays returned, the functional model traced " +
                             std::to_string(reference.rays));
  }
}

SweepResult run_sweep_points(const std::vector<SweepAxis>& axes, const PreparedScene& prepared,
                             const RenderSettings& settings) {
  SweepResult r;
  r.axes = axes;
  const std::vector<std::vector<std::string>> points = sweep_points(axes, settings.cycle);
  // The image's format picks the pair: fp24 and the prototype's cycle model, or both in e7m23.
  const bool wide = prepared.built.params.format == ff::Format{7, 23};
  r.functional_model = wide ? "e7m23" : "fp24";
  const ModelSpec cycle = parse_model(wide ? "cycle-e7m23" : "cycle");
  progress("functional " + r.functional_model + " model: the reference frame");
  FrameResult reference = render_model(parse_model(r.functional_model), prepared, settings);
  r.functional_rays = reference.rays;
  // A point that varies kd.* keys has its own trees: its image is rebuilt, and its functional
  // reference frame rendered on it (points in a row with the same trees share both).
  std::optional<PreparedScene> rebuilt;
  std::string trees_of_rebuilt;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::string where = join_words(points[i]);
    progress("point " + std::to_string(i + 1) + " / " + std::to_string(points.size()) + ": " +
             where);
    RenderSettings s = settings;
    s.cycle.set.insert(s.cycle.set.end(), points[i].begin(), points[i].end());
    std::string trees;
    for (const std::string& kv : points[i])
      if (host::is_tree_setting(kv)) trees += kv + " ";
    if (!trees.empty() && (!rebuilt || trees != trees_of_rebuilt)) {
      if (!rebuilt) rebuilt = prepared;
      build_prepared_image(*rebuilt, s, prepared.built.params.format);
      trees_of_rebuilt = trees;
      reference = render_model(parse_model(r.functional_model), *rebuilt, s);
    } else if (trees.empty() && rebuilt) {
      rebuilt.reset();
      reference = render_model(parse_model(r.functional_model), prepared, settings);
    }
    const FrameResult f = render_model(cycle, rebuilt ? *rebuilt : prepared, s);
    check_sweep_point(f, reference, where);
    SweepPoint p;
    p.settings = points[i];
    p.cycle = f.cycle;
    const double first = r.points.empty() ? f.cycle["cycles"].get<double>()
                                          : r.points.front().cycle["cycles"].get<double>();
    p.speedup = first / f.cycle["cycles"].get<double>();
    r.points.push_back(std::move(p));
  }
  return r;
}

namespace {

// The point's value of each axis, in axis order ("threads=4" -> "4").
std::vector<std::string> point_values(const SweepPoint& p) {
  std::vector<std::string> v;
  for (const std::string& kv : p.settings) {
    v.push_back(kv.substr(kv.find('=') + 1));
  }
  return v;
}

struct Column {
  const char* name;    // CSV header
  const char* head;    // table header
  const char* format;  // printf format of the table cell
  double (*get)(const SweepPoint&);
};

double fig(const SweepPoint& p, const char* group, const char* key) {
  return p.cycle[group][key].get<double>();
}

const std::vector<Column>& columns() {
  static const std::vector<Column> c = {
      {"cycles", "cycles", "%10.0f",
       [](const SweepPoint& p) { return p.cycle["cycles"].get<double>(); }},
      {"fps", "fps", "%8.1f", [](const SweepPoint& p) { return p.cycle["fps"].get<double>(); }},
      {"mrays_per_s", "Mrays/s", "%8.2f",
       [](const SweepPoint& p) { return p.cycle["rays_per_s"].get<double>() / 1e6; }},
      {"speedup", "speed-up", "%8.2f", [](const SweepPoint& p) { return p.speedup; }},
      {"usage_traversal", "trav%", "%6.0f",
       [](const SweepPoint& p) { return fig(p, "usage", "traversal"); }},
      {"usage_list", "list%", "%6.0f", [](const SweepPoint& p) { return fig(p, "usage", "list"); }},
      {"usage_transformation", "xfrm%", "%6.0f",
       [](const SweepPoint& p) { return fig(p, "usage", "transformation"); }},
      {"usage_intersection", "int%", "%6.0f",
       [](const SweepPoint& p) { return fig(p, "usage", "intersection"); }},
      {"cache_hit_traversal", "hit-trav%", "%10.1f",
       [](const SweepPoint& p) { return fig(p, "cache_hit", "traversal"); }},
      {"cache_hit_list", "hit-list%", "%10.1f",
       [](const SweepPoint& p) { return fig(p, "cache_hit", "list"); }},
      {"cache_hit_transformation", "hit-xfrm%", "%10.1f",
       [](const SweepPoint& p) { return fig(p, "cache_hit", "transformation"); }},
      {"bandwidth_mb_s_total", "MB/s", "%7.0f",
       [](const SweepPoint& p) { return fig(p, "bandwidth_mb_s", "total"); }},
      {"cycles_per_packet", "cyc/pkt", "%8.1f",
       [](const SweepPoint& p) { return p.cycle["cycles_per_packet"].get<double>(); }},
      {"simd_efficiency", "SIMD", "%6.2f",
       [](const SweepPoint& p) { return p.cycle["simd_efficiency"].get<double>(); }},
  };
  return c;
}

}  // namespace

std::string sweep_table(const SweepResult& sweep) {
  std::string s;
  char buf[64];
  for (const SweepAxis& a : sweep.axes) {
    std::snprintf(buf, sizeof buf, "%*s ", static_cast<int>(std::max<std::size_t>(a.key.size(), 6)),
                  a.key.c_str());
    s += buf;
  }
  for (const Column& c : columns()) {
    char probe[64];
    const int width = std::snprintf(probe, sizeof probe, c.format, 0.0);
    std::snprintf(buf, sizeof buf, " %*s", width, c.head);
    s += buf;
  }
  s += "\n";
  for (const SweepPoint& p : sweep.points) {
    const std::vector<std::string> v = point_values(p);
    for (std::size_t a = 0; a < v.size(); ++a) {
      const int width = static_cast<int>(std::max<std::size_t>(sweep.axes[a].key.size(), 6));
      std::snprintf(buf, sizeof buf, "%*s ", width, v[a].c_str());
      s += buf;
    }
    for (const Column& c : columns()) {
      s += ' ';
      std::snprintf(buf, sizeof buf, c.format, c.get(p));
      s += buf;
    }
    s += "\n";
  }
  return s;
}

std::string sweep_csv(const SweepResult& sweep) {
  std::string s;
  for (const SweepAxis& a : sweep.axes) {
    s += a.key + ",";
  }
  for (const Column& c : columns()) {
    s += std::string(c.name) + (&c == &columns().back() ? "\n" : ",");
  }
  char buf[64];
  for (const SweepPoint& p : sweep.points) {
    for (const std::string& v : point_values(p)) {
      s += v + ",";
    }
    for (const Column& c : columns()) {
      std::snprintf(buf, sizeof buf, "%.17g", c.get(p));
      s += std::string(buf) + (&c == &columns().back() ? "\n" : ",");
    }
  }
  return s;
}

nlohmann::json sweep_json(const SweepResult& sweep, const SweepOptions& opts) {
  nlohmann::json j;
  j["scene"] = opts.scene;
  j["resolution"] = opts.res;
  j["preset"] = opts.preset;
  j["set"] = opts.set;
  nlohmann::json vary = nlohmann::json::object();
  for (const SweepAxis& a : sweep.axes) {
    vary[a.key] = a.values;
  }
  j["vary"] = vary;
  j["model"] = opts.model;
  j["functional_model"] = sweep.functional_model;
  j["bit_identical_to_functional_model"] = true;  // run_sweep_points throws otherwise
  j["functional_rays"] = sweep.functional_rays;
  nlohmann::json points = nlohmann::json::array();
  for (const SweepPoint& p : sweep.points) {
    nlohmann::json e;
    const std::vector<std::string> v = point_values(p);
    for (std::size_t a = 0; a < v.size(); ++a) {
      e["values"][sweep.axes[a].key] = v[a];
    }
    e["speedup"] = p.speedup;
    e["report"] = p.cycle;
    points.push_back(std::move(e));
  }
  j["points"] = points;
  return j;
}

int run_sweep(const SweepOptions& opts) {
  RenderSettings settings =
      frame_settings(opts.res, opts.time, opts.shadows, opts.depth, opts.bank_mb);
  settings.cycle.preset = opts.preset;
  settings.cycle.set = opts.set;
  settings.cycle.host_threads = opts.host_threads;
  const ModelSpec model = parse_model(opts.model);
  if (model.kind != ModelKind::kCycle) {
    throw std::runtime_error("bad --model " + opts.model + ": a sweep runs cycle or cycle-e7m23");
  }
  std::vector<SweepAxis> axes;
  for (const std::string& v : opts.vary) {
    axes.push_back(parse_sweep_axis(v));
  }
  // Every bad input fails here, before the scene loads and before any frame runs.
  const std::size_t count = sweep_points(axes, settings.cycle).size();
  if (!opts.report.empty() && !opts.report.ends_with(".json")) {
    throw std::runtime_error("bad --report '" + opts.report + "': expected a .json file name");
  }
  if (!opts.csv.empty() && !opts.csv.ends_with(".csv")) {
    throw std::runtime_error("bad --csv '" + opts.csv + "': expected a .csv file name");
  }

  const PreparedScene prep = prepare_scene(opts.scene, settings, ff::Format{7, model.mantissa});
  const SweepResult sweep = run_sweep_points(axes, prep, settings);

  if (!opts.report.empty()) {
    write_text_file(opts.report, sweep_json(sweep, opts).dump(2) + "\n");
  }
  if (!opts.csv.empty()) {
    write_text_file(opts.csv, sweep_csv(sweep));
  }
  std::printf(
      "saarcor sweep: %s, model %s, %dx%d, %zu points, every one bit-identical to the functional "
      "%s model (hit records and image, %" PRIu64 " rays)\n",
      opts.scene.c_str(), opts.model.c_str(), settings.res.width, settings.res.height, count,
      sweep.functional_model.c_str(), sweep.functional_rays);
  if (!opts.report.empty()) {
    std::printf("  report:    %s\n", opts.report.c_str());
  }
  if (!opts.csv.empty()) {
    std::printf("  csv:       %s\n", opts.csv.c_str());
  }
  std::printf("%s", sweep_table(sweep).c_str());
  return 0;
}

}  // namespace saarcor
