// `saarcor sweep`: the cycle model over a grid of configurations (testbench/sweep_cmd.h).
#include "testbench/sweep_cmd.h"

#include <algorithm>
#include <atomic>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <future>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "host/tree_settings.h"
#include "testbench/compare.h"
#include "testbench/cycle_render.h"
#include "testbench/heartbeat.h"
#include "testbench/image_io.h"
#include "testbench/mpi_ranks.h"
#include "testbench/report.h"
#include "testbench/run_journal.h"
#include "testbench/sampling.h"
#include "testbench/task_pool.h"
#include "units/cost.h"
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

std::pair<std::size_t, std::size_t> parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  auto number = [](const std::string& t, std::size_t& out) {
    if (t.empty() || t.size() > 4) return false;
    for (char c : t)
      if (c < '0' || c > '9') return false;
    out = std::stoul(t);
    return true;
  };
  std::size_t k = 0, n = 0;
  if (slash == std::string::npos || !number(text.substr(0, slash), k) ||
      !number(text.substr(slash + 1), n))
    throw std::runtime_error("bad --shard '" + text + "': expected K/N, e.g. 2/8");
  if (k < 1 || k > n || n > kMaxSweepPoints)
    throw std::runtime_error("bad --shard '" + text +
                             "': expected 1 <= K <= N <= " + std::to_string(kMaxSweepPoints));
  return {k - 1, n};
}

namespace {

// Points are grouped by the trees they build: a point that varies kd.* keys has its own image
// and its own functional reference frame (points with the same trees share both). The group
// without kd.* keys reads `prepared`, and its reference gives functional_rays even when no
// point of this shard belongs to it. One group's image is alive at a time.
struct Group {
  std::string trees;
  std::vector<std::size_t> points;
};

std::vector<Group> group_by_trees(const std::vector<std::vector<std::string>>& points,
                                  const SweepRun& run) {
  std::vector<Group> groups = {{"", {}}};
  for (std::size_t i = run.shard; i < points.size(); i += run.shards) {
    if (run.finished.contains(i)) continue;  // kept from a run that was stopped
    std::string trees;
    for (const std::string& kv : points[i])
      if (host::is_tree_setting(kv)) trees += kv + " ";
    auto g = std::ranges::find_if(groups, [&](const Group& x) { return x.trees == trees; });
    if (g == groups.end()) {
      groups.push_back({trees, {}});
      g = groups.end() - 1;
    }
    g->points.push_back(i);
  }
  return groups;
}

// What every group of one sweep shares.
struct SweepContext {
  const std::vector<std::vector<std::string>>& points;
  const PreparedScene& prepared;
  const RenderSettings& settings;
  const ModelSpec& cycle;
  const ModelSpec& functional;
  int jobs;
  const std::function<void(const SweepPoint&)>& on_point;
  Heartbeat& beat;
  std::atomic<std::size_t>& done;
  std::size_t selected;
};

// One group: its image (rebuilt when it varies kd.* keys), its functional reference frame and
// its points on the cycle model, each checked against the reference.
std::vector<SweepPoint> run_group(const Group& g, const SweepContext& cx, SweepResult& r) {
  const std::vector<std::vector<std::string>>& points = cx.points;
  std::optional<PreparedScene> rebuilt;
  RenderSettings group_settings = cx.settings;
  group_settings.heartbeat = false;  // the sweep's heartbeat counts points instead of packets
  if (!g.trees.empty()) {
    const std::vector<std::string>& first = points[g.points.front()];
    group_settings.cycle.set.insert(group_settings.cycle.set.end(), first.begin(), first.end());
    rebuilt = cx.prepared;
    build_prepared_image(*rebuilt, group_settings, cx.prepared.built.params.format);
  }
  const PreparedScene& prep = rebuilt ? *rebuilt : cx.prepared;
  progress("functional " + r.functional_model + " model: the reference frame" +
           (g.trees.empty() ? "" : " (" + g.trees.substr(0, g.trees.size() - 1) + ")"));
  // Task 0 renders the reference; tasks 1.. the points, which wait for it only to compare.
  std::promise<FrameResult> reference_promise;
  std::shared_future<FrameResult> reference = reference_promise.get_future().share();
  std::vector<SweepPoint> group_points(g.points.size());
  run_tasks(g.points.size() + 1, cx.jobs, [&](std::size_t task) {
    if (task == 0) {
      try {
        reference_promise.set_value(render_model(cx.functional, prep, group_settings));
      } catch (...) {
        reference_promise.set_exception(std::current_exception());
        throw;
      }
      return;
    }
    if (stop_signal() != 0) return;  // stopped: the point stays missing
    const std::size_t i = g.points[task - 1];
    RenderSettings s = cx.settings;
    s.heartbeat = group_settings.heartbeat;
    s.cycle.set.insert(s.cycle.set.end(), points[i].begin(), points[i].end());
    if (cx.jobs > 1) {
      run_beside_others(s);
    }
    const FrameResult f = render_model(cx.cycle, prep, s);
    // A sampled point checked its simulated packets itself (testbench/sampling.h).
    if (!f.cycle.contains("sampling")) check_sweep_point(f, reference.get(), join_words(points[i]));
    SweepPoint& p = group_points[task - 1];
    p.index = i;
    p.settings = points[i];
    p.cycle = f.cycle;
    // The configuration's cost, the light table at the preset's capacity (units/cost.h).
    p.cost =
        sweep_cost_json({resolve_cycle_params(s.cycle), units::cost_preset(s.cycle.preset).lights});
    if (cx.on_point) cx.on_point(p);
    cx.beat.beat("points " + std::to_string(++cx.done) + " / " + std::to_string(cx.selected) +
                 (cx.jobs > 1 ? ", " + std::to_string(cx.jobs) + " at once" : ""));
  });
  if (g.trees.empty()) r.functional_rays = reference.get().rays;
  std::erase_if(group_points, [](const SweepPoint& p) { return p.cycle.is_null(); });
  return group_points;
}

}  // namespace

SweepResult run_sweep_points(const std::vector<SweepAxis>& axes, const PreparedScene& prepared,
                             const RenderSettings& settings, const SweepRun& run) {
  SweepResult r;
  r.axes = axes;
  r.shard = run.shard;
  r.shards = run.shards;
  const std::vector<std::vector<std::string>> points = sweep_points(axes, settings.cycle);
  r.total_points = points.size();
  // The image's format picks the pair: fp24 and the prototype's cycle model, or both in e7m23.
  const bool wide = prepared.built.params.format == ff::Format{7, 23};
  r.functional_model = wide ? "e7m23" : "fp24";
  const ModelSpec cycle = parse_model(wide ? "cycle-e7m23" : "cycle");
  const ModelSpec functional = parse_model(r.functional_model);
  const int jobs = std::max(1, run.jobs);
  const std::vector<Group> groups = group_by_trees(points, run);

  Heartbeat beat("sweep", run.heartbeat && heartbeat_enabled());
  std::atomic<std::size_t> done{run.finished.size()};
  std::size_t selected = run.finished.size();
  for (const Group& g : groups)
    selected += g.points.size();
  const SweepContext cx{points, prepared,     settings, cycle, functional,
                        jobs,   run.on_point, beat,     done,  selected};
  std::vector<SweepPoint> results;
  for (const auto& [index, point] : run.finished)
    results.push_back(point);
  for (const Group& g : groups) {
    if (stop_signal() != 0) break;
    for (SweepPoint& p : run_group(g, cx, r))
      results.push_back(std::move(p));
  }
  if (stop_signal() != 0)
    beat.finish("stopped by " + signal_name(stop_signal()) + ": points " +
                std::to_string(results.size()) + " / " + std::to_string(selected) + " kept");
  else
    beat.finish();
  std::ranges::sort(results, {}, &SweepPoint::index);
  r.points = std::move(results);
  set_speedups(r);
  return r;
}

void set_speedups(SweepResult& sweep) {
  if (sweep.points.empty()) return;
  const double first = sweep.points.front().cycle["cycles"].get<double>();
  for (SweepPoint& p : sweep.points)
    p.speedup = first / p.cycle["cycles"].get<double>();
}

std::vector<bool> pareto_front(const std::vector<std::pair<double, double>>& performance_cost) {
  std::vector<bool> front(performance_cost.size(), true);
  for (std::size_t i = 0; i < performance_cost.size(); ++i) {
    const auto [perf, cost] = performance_cost[i];
    for (const auto& [p, c] : performance_cost) {
      if (p >= perf && c <= cost && (p > perf || c < cost)) {
        front[i] = false;
        break;
      }
    }
  }
  return front;
}

std::string pareto_cost_name(const std::string& name) {
  if (name.empty()) return "luts";
  const std::vector<std::string> names = sweep_cost_names();
  if (std::ranges::find(names, name) != names.end()) return name;
  std::string known;
  for (const std::string& n : names)
    known += (known.empty() ? "" : ", ") + n;
  throw std::runtime_error("bad --pareto-cost '" + name + "': expected a cost column (" + known +
                           ")");
}

void mark_pareto(SweepResult& sweep, const std::string& cost) {
  std::vector<std::pair<double, double>> pc;
  for (const SweepPoint& p : sweep.points)
    pc.emplace_back(p.cycle.at("fps").get<double>(), p.cost.at(cost).get<double>());
  const std::vector<bool> front = pareto_front(pc);
  for (std::size_t i = 0; i < sweep.points.size(); ++i)
    sweep.points[i].pareto = front[i];
  sweep.pareto_cost = cost;
}

namespace {

// A CSV's lines and cells (the sweep's own CSVs: no quoting, one row a line).
std::vector<std::vector<std::string>> csv_cells(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::size_t from = 0;
  while (from < text.size()) {
    std::size_t eol = text.find('\n', from);
    if (eol == std::string::npos) eol = text.size();
    std::vector<std::string> cells;
    std::size_t c = from;
    while (true) {
      const std::size_t comma = text.find(',', c);
      if (comma == std::string::npos || comma >= eol) {
        cells.push_back(text.substr(c, eol - c));
        break;
      }
      cells.push_back(text.substr(c, comma - c));
      c = comma + 1;
    }
    rows.push_back(std::move(cells));
    from = eol + 1;
  }
  return rows;
}

// The columns that depend on the whole sweep, recomputed over the merged rows: the speed-up over
// point 0 from the exact cycles and, when the shards marked a front (a column pareto_<cost>), the
// Pareto front of all points (each shard marked its own).
void recompute_whole_sweep(const std::vector<std::string>& header,
                           std::vector<std::optional<std::vector<std::string>>>& rows,
                           const std::string& first_file) {
  const auto col = [&](const std::string& name) {
    return static_cast<std::size_t>(std::ranges::find(header, name) - header.begin());
  };
  const auto number = [](const std::string& cell) { return std::strtod(cell.c_str(), nullptr); };
  const std::size_t cycles = col("cycles"), speedup = col("speedup"), fps = col("fps");
  if (cycles == header.size() || speedup == header.size() || fps == header.size())
    throw std::runtime_error(first_file + ": no cycles, fps or speedup column");
  const double first = number((*rows[0])[cycles]);
  char buf[64];
  for (auto& row : rows) {
    std::snprintf(buf, sizeof buf, "%.17g", first / number((*row)[cycles]));
    (*row)[speedup] = buf;
  }
  const auto pareto =
      std::ranges::find_if(header, [](const std::string& h) { return h.starts_with("pareto_"); });
  if (pareto == header.end()) return;
  const std::size_t flag = static_cast<std::size_t>(pareto - header.begin());
  const std::size_t cost = col(pareto->substr(7));
  if (cost == header.size())
    throw std::runtime_error(first_file + ": a column " + *pareto + " without its cost column");
  std::vector<std::pair<double, double>> pc;
  for (const auto& row : rows)
    pc.emplace_back(number((*row)[fps]), number((*row)[cost]));
  const std::vector<bool> front = pareto_front(pc);
  for (std::size_t i = 0; i < rows.size(); ++i)
    (*rows[i])[flag] = front[i] ? "1" : "0";
}

std::string csv_line(const std::vector<std::string>& cells, std::size_t from) {
  std::string s;
  for (std::size_t i = from; i < cells.size(); ++i)
    s += cells[i] + (i + 1 == cells.size() ? "\n" : ",");
  return s;
}

}  // namespace

std::string merge_sweep_csv(const std::vector<std::pair<std::string, std::string>>& parts) {
  if (parts.empty()) throw std::runtime_error("sweep-merge needs at least one shard CSV");
  std::vector<std::string> header;
  std::size_t total = 0;
  std::vector<std::optional<std::vector<std::string>>> rows;
  for (const auto& [name, text] : parts) {
    const auto cells = csv_cells(text);
    if (cells.empty() || cells[0].size() < 3 || cells[0][0] != "point" || cells[0][1] != "points")
      throw std::runtime_error(name +
                               ": not a shard CSV (saarcor sweep --shard K/N): its header "
                               "does not start with point,points");
    if (header.empty()) {
      header = cells[0];
    } else if (cells[0] != header) {
      throw std::runtime_error(name + ": its columns differ from " + parts.front().first + "'s");
    }
    for (std::size_t r = 1; r < cells.size(); ++r) {
      const std::vector<std::string>& row = cells[r];
      if (row.size() != header.size())
        throw std::runtime_error(name + ": line " + std::to_string(r + 1) + " has " +
                                 std::to_string(row.size()) + " cells, the header " +
                                 std::to_string(header.size()));
      const std::size_t index = std::stoul(row[0]), points = std::stoul(row[1]);
      if (total == 0) {
        total = points;
        rows.resize(total);
      }
      if (points != total || index >= total)
        throw std::runtime_error(name + ": line " + std::to_string(r + 1) + ": point " + row[0] +
                                 " of " + row[1] + " in a sweep of " + std::to_string(total) +
                                 " points");
      if (rows[index])
        throw std::runtime_error(name + ": point " + row[0] + " is in two shard files");
      rows[index] = row;
    }
  }
  for (std::size_t i = 0; i < rows.size(); ++i)
    if (!rows[i])
      throw std::runtime_error("sweep-merge: point " + std::to_string(i) + " of " +
                               std::to_string(total) +
                               " is in none of the files (a shard missing)");
  if (rows.empty()) throw std::runtime_error("sweep-merge: the shard files hold no rows");
  recompute_whole_sweep(header, rows, parts.front().first);
  std::string out = csv_line(header, 2);
  for (const auto& row : rows)
    out += csv_line(*row, 2);
  return out;
}

int run_sweep_merge(const SweepMergeOptions& opts) {
  if (opts.out.empty() || !opts.out.ends_with(".csv"))
    throw std::runtime_error("bad -o '" + opts.out + "': expected a .csv file name");
  std::vector<std::pair<std::string, std::string>> parts;
  for (const std::string& p : opts.parts) {
    require_readable_file(p);
    std::ifstream f(p, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    parts.push_back({p, ss.str()});
  }
  const std::string merged = merge_sweep_csv(parts);
  write_text_file(opts.out, merged);
  std::printf("saarcor sweep-merge: %zu shard files, %zu points -> %s\n", parts.size(),
              static_cast<std::size_t>(std::count(merged.begin(), merged.end(), '\n') - 1),
              opts.out.c_str());
  return 0;
}

namespace {

// Under mpirun: every rank sends rank 0 its points (or its error); rank 0 gets the first failing
// rank's error or every rank's points, in sweep order. Returns false on the other ranks.
bool gather_ranks(MpiRanks& ranks, std::string& error, SweepResult& sweep) {
  const std::vector<std::string> all = ranks.gather(sweep_rank_message(error, sweep).dump());
  if (ranks.rank() != 0) return false;
  std::vector<SweepPoint> points;
  for (std::size_t r = 0; r < all.size() && error.empty(); ++r) {
    const nlohmann::json j = nlohmann::json::parse(all[r]);
    if (j.contains("error")) {
      error = j["error"].get<std::string>();
      break;
    }
    for (SweepPoint& p : sweep_points_from_json(j["points"]))
      points.push_back(std::move(p));
  }
  if (error.empty()) {
    std::ranges::sort(points, {}, &SweepPoint::index);
    sweep.points = std::move(points);
    sweep.shard = 0;
    sweep.shards = 1;
    set_speedups(sweep);
  }
  return true;
}

// --report, --csv and --out-dir checked (one line naming the option).
void check_sweep_outputs(const SweepOptions& opts) {
  if (!opts.report.empty() && !opts.report.ends_with(".json")) {
    throw std::runtime_error("bad --report '" + opts.report + "': expected a .json file name");
  }
  if (!opts.csv.empty() && !opts.csv.ends_with(".csv")) {
    throw std::runtime_error("bad --csv '" + opts.csv + "': expected a .csv file name");
  }
  if (!opts.out_dir.empty()) {
    check_out_dir(opts.out_dir);
    if (!opts.csv.empty() || !opts.report.empty())
      throw std::runtime_error(
          "--out-dir names every file it writes (sweep.csv, report.json): drop --csv and "
          "--report");
  }
}

// What a sweep's journal must agree on to be resumed: everything that changes a point's result or
// which points there are (not --jobs, --host-threads or the outputs).
nlohmann::json sweep_identity(const SweepOptions& o) {
  return {{"command", "sweep"},
          {"scene", o.scene},
          {"model", o.model},
          {"res", o.res},
          {"time", o.time},
          {"shadows", o.shadows},
          {"depth", o.depth},
          {"bank_mb", o.bank_mb},
          {"preset", o.preset},
          {"set", o.set},
          {"vary", o.vary},
          {"shard", o.shard},
          {"sample", o.sample ? o.sample_spec : "off"}};
}

std::string point_key(std::size_t index) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "point%04zu", index);
  return buf;
}

// A finished point as its journal record: its report without host timing (host.json's alone).
std::string point_record(const SweepPoint& p) {
  nlohmann::json cycle = p.cycle;
  take_cycle_host(cycle);
  return nlohmann::json{
      {"index", p.index}, {"settings", p.settings}, {"cycle", cycle}, {"cost", p.cost}}
      .dump();
}

// --out-dir (and --resume, which names it): the folder's journal, new or resumed, with the points
// it holds in `run.finished`; none under mpirun (the ranks' points reach rank 0 only at the end).
std::unique_ptr<RunJournal> open_sweep_journal(SweepOptions& o, int ranks, SweepRun& run) {
  if (o.out_dir.empty()) return nullptr;
  if (ranks > 1) {
    if (!o.resume.empty())
      throw std::runtime_error("--resume runs in one process: drop mpirun (or resume --shard K/N)");
    return nullptr;
  }
  if (o.resume.empty()) return std::make_unique<RunJournal>(o.out_dir, sweep_identity(o), o.argv);
  auto j = std::make_unique<RunJournal>(RunJournal::resume(o.out_dir, sweep_identity(o)));
  for (const JournalRecord& r : j->records()) {
    const nlohmann::json e = nlohmann::json::parse(r.payload);
    SweepPoint p = sweep_points_from_json(nlohmann::json::array({e})).front();
    run.finished.emplace(p.index, std::move(p));
  }
  o.argv = j->argv();  // command.txt: the command that began the run
  return j;
}

// --resume DIR names the folder; --out-dir beside it must name the same one.
SweepOptions resolve_resume(const SweepOptions& opts) {
  SweepOptions o = opts;
  if (o.resume.empty()) return o;
  if (!o.out_dir.empty() && o.out_dir != o.resume)
    throw std::runtime_error("--resume '" + o.resume + "' and --out-dir '" + o.out_dir +
                             "' name two folders: give one");
  o.out_dir = o.resume;
  return o;
}

// --out-dir, --report and --csv, from the whole sweep (rank 0's) with its front marked.
void write_sweep_outputs(const SweepOptions& opts, const SweepResult& sweep,
                         const RenderSettings& settings, int jobs, int ranks) {
  if (!opts.out_dir.empty()) write_sweep_folder(opts, sweep, settings, jobs, ranks);
  if (!opts.report.empty()) {
    write_text_file(opts.report, sweep_json(sweep, opts).dump(2) + "\n");
  }
  if (!opts.csv.empty()) {
    write_text_file(opts.csv, sweep_csv(sweep));
  }
}

// The sweep's summary line, where its files went, its table and its Pareto front.
void print_sweep(const SweepOptions& opts, const SweepResult& sweep, const RenderSettings& settings,
                 std::size_t count) {
  const std::string shard =
      sweep.shards > 1 ? ", shard " + opts.shard + ": " + std::to_string(sweep.points.size()) : "";
  std::printf(
      "saarcor sweep: %s, model %s, %dx%d, %zu points%s, every one bit-identical to the "
      "functional %s model (hit records and image, %" PRIu64 " rays)\n",
      opts.scene.c_str(), opts.model.c_str(), settings.res.width, settings.res.height, count,
      shard.c_str(), sweep.functional_model.c_str(), sweep.functional_rays);
  // A sampled point's figures are estimates; its simulated packets were checked (docs/sampling.md).
  if (opts.sample)
    std::printf(
        "  sampled (--sample %s): each point's simulated packets checked, its figures "
        "estimated with 95 %% intervals in the report\n",
        sample_spec_text(parse_sample_spec(opts.sample_spec)).c_str());
  if (!opts.out_dir.empty()) {
    std::printf(
        "  run folder: %s (sweep.csv, report.json, stats.txt, config.json, command.txt, "
        "host.json)\n",
        opts.out_dir.c_str());
  }
  if (!opts.report.empty()) {
    std::printf("  report:    %s\n", opts.report.c_str());
  }
  if (!opts.csv.empty()) {
    std::printf("  csv:       %s\n", opts.csv.c_str());
  }
  std::printf("%s%s", sweep_table(sweep).c_str(), sweep_pareto_text(sweep).c_str());
}

}  // namespace

namespace {

// The sweep's frame settings, axes and run (jobs, shard or rank), every option checked before the
// scene loads; returns the points' count.
std::size_t plan_sweep(const SweepOptions& opts, const MpiRanks& ranks, RenderSettings& settings,
                       std::vector<SweepAxis>& axes, SweepRun& run, int& jobs) {
  settings = frame_settings(opts.res, opts.time, opts.shadows, opts.depth, opts.bank_mb);
  settings.cycle.preset = opts.preset;
  settings.cycle.set = opts.set;
  settings.cycle.host_threads = opts.host_threads;
  settings.cycle.sample = opts.sample;
  settings.cycle.sample_spec = opts.sample_spec;
  settings.cycle.sample_check = true;
  const ModelSpec model = parse_model(opts.model);
  if (model.kind != ModelKind::kCycle) {
    throw std::runtime_error("bad --model " + opts.model + ": a sweep runs cycle or cycle-e7m23");
  }
  for (const std::string& v : opts.vary) {
    axes.push_back(parse_sweep_axis(v));
  }
  // Every bad input fails here, before the scene loads and before any frame runs.
  const std::size_t count = sweep_points(axes, settings.cycle).size();
  check_sweep_outputs(opts);
  pareto_cost_name(opts.pareto_cost);
  const bool per_core = jobs == 0;
  jobs = resolve_jobs(jobs);
  if (!opts.shard.empty()) std::tie(run.shard, run.shards) = parse_shard(opts.shard);
  if (ranks.size() > 1) {
    if (!opts.shard.empty())
      throw std::runtime_error("--shard and mpirun both split the sweep: give one of them");
    run.shard = static_cast<std::size_t>(ranks.rank());
    run.shards = static_cast<std::size_t>(ranks.size());
  }
  if (per_core) {
    jobs = std::max(1, jobs / ranks.local_size());  // the host's cores, shared by its ranks
  }
  run.jobs = jobs;
  run.heartbeat = ranks.rank() == 0;
  return count;
}

// A sweep a signal stopped: what it kept and how to go on (one line).
Interrupted sweep_stopped(const SweepOptions& o, const SweepResult& sweep, std::size_t count,
                          const SweepRun& run) {
  const std::size_t mine = (count - run.shard + run.shards - 1) / run.shards;
  return Interrupted(stop_signal(), "sweep stopped by " + signal_name(stop_signal()) + ": " +
                                        std::to_string(sweep.points.size()) + " of " +
                                        std::to_string(mine) + " points kept in " + o.out_dir +
                                        "/journal.txt; go on with: saarcor sweep ... --resume " +
                                        o.out_dir);
}

}  // namespace

int run_sweep(const SweepOptions& options) {
  // Under mpirun every rank runs this; rank 0 gathers and alone prints and writes. Every failure
  // of any rank, bad input included, reaches rank 0 as text, so no rank waits for a dead one and
  // the error is printed once.
  MpiRanks ranks;
  std::string error;
  SweepResult sweep;
  RenderSettings settings;
  std::size_t count = 0, resumed = 0;
  int jobs = options.jobs;
  SweepOptions opts;
  std::unique_ptr<RunJournal> journal;
  std::optional<StopOnSignal> stop;
  SweepRun run;
  try {
    opts = resolve_resume(options);
    std::vector<SweepAxis> axes;
    count = plan_sweep(opts, ranks, settings, axes, run, jobs);
    journal = open_sweep_journal(opts, ranks.size(), run);
    resumed = run.finished.size();
    if (journal) {
      stop.emplace();  // SIGINT, SIGTERM: stop starting points, keep the finished ones
      run.on_point = [&journal](const SweepPoint& p) {
        journal->append(point_key(p.index), point_record(p));
      };
    }
    const ModelSpec model = parse_model(opts.model);
    const PreparedScene prep = prepare_scene(opts.scene, settings, ff::Format{7, model.mantissa});
    sweep = run_sweep_points(axes, prep, settings, run);
    if (stop_signal() != 0) throw sweep_stopped(opts, sweep, count, run);
  } catch (const Interrupted&) {
    throw;
  } catch (const std::exception& e) {
    error = e.what();
  }
  if (ranks.size() > 1 && !gather_ranks(ranks, error, sweep)) return error.empty() ? 0 : 1;
  if (!error.empty()) throw std::runtime_error(error);
  if (opts.pareto || !opts.pareto_cost.empty())
    mark_pareto(sweep, pareto_cost_name(opts.pareto_cost));
  write_sweep_outputs(opts, sweep, settings, jobs, ranks.size());
  if (journal) journal->seal();
  print_sweep(opts, sweep, settings, count);
  if (resumed != 0)
    std::printf("  resumed:   %zu points from %s/journal.txt, %zu run now\n", resumed,
                opts.out_dir.c_str(), sweep.points.size() - resumed);
  return 0;
}

}  // namespace saarcor
