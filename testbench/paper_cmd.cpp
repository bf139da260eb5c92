// `saarcor paper`: Tables 3 and 4 of the paper beside the model's (testbench/paper_cmd.h).
#include "testbench/paper_cmd.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <utility>

#include "testbench/cost_cmd.h"
#include "testbench/cycle_render.h"
#include "testbench/heartbeat.h"
#include "testbench/image_io.h"
#include "testbench/render_cmd.h"
#include "testbench/report.h"
#include "testbench/task_pool.h"

namespace saarcor {

namespace {

// Table 3 of the paper (512x384, primary rays, textured shading; SaarCOR at 90 MHz with one
// DynRTP, OpenRT on a 2.66 GHz Pentium 4).
const std::vector<Table3Row>& paper_table3() {
  static const std::vector<Table3Row> rows = {
      {"Scene6", 806, 1, 60.8, 12.9},         {"Castle", 20891, 8, 23.8, 9.2},
      {"Office", 34312, 1, 48.9, 10.4},       {"Quake3", 39424, 1, 33.6, 11.1},
      {"Quake3-p", 52790, 17, 26.7, 7.9},     {"UT2003", 52479, 1, 25.4, 8.0},
      {"Conference", 282805, 54, 22.1, 8.1},  {"Terrain", 10469866, 264, 15.9, 3.5},
      {"SunCOR", 187145136, 5622, 32.1, 7.5},
  };
  return rows;
}

void check_options(const PaperOptions& opts) {
  if (opts.table != 0 && opts.table != 3 && opts.table != 4)
    throw std::runtime_error("bad --table " + std::to_string(opts.table) + ": 3 or 4");
  if (opts.scale < 1 || opts.scale > 64)
    throw std::runtime_error("bad --scale " + std::to_string(opts.scale) + ": 1..64");
  if (!opts.csv.empty() && !opts.csv.ends_with(".csv"))
    throw std::runtime_error("bad --csv '" + opts.csv + "': expected a .csv file name");
  if (!opts.json.empty() && !opts.json.ends_with(".json"))
    throw std::runtime_error("bad --json '" + opts.json + "': expected a .json file name");
  (void)resolve_jobs(opts.jobs);
  CycleRenderOptions c;
  c.set = opts.set;
  c.sample = opts.sample;
  c.sample_spec = opts.sample_spec;
  resolve_cycle_params(c);  // bad --set keys fail before any scene loads
}

std::vector<PaperScene> chosen_scenes(const PaperOptions& opts) {
  std::vector<PaperScene> all = paper_scenes(opts.references);
  if (opts.scenes.empty()) return all;
  std::vector<PaperScene> v;
  for (const std::string& name : opts.scenes) {
    const auto it =
        std::find_if(all.begin(), all.end(), [&](const PaperScene& s) { return s.paper == name; });
    if (it == all.end()) {
      std::string known;
      for (const PaperScene& s : all) {
        if (!known.empty()) known += ", ";
        known += s.paper;
      }
      throw std::runtime_error("bad --scene " + name + ": the paper scenes shown are " + known);
    }
    v.push_back(*it);
  }
  return v;
}

// The frames of several tasks (scenes, thread counts) on `jobs` host threads. With more than one,
// each frame runs beside the others (run_beside_others) and one heartbeat counts the frames in
// place of the frames' own and the progress lines.
class FramePool {
 public:
  FramePool(int jobs, std::size_t frames)
      : jobs_(jobs), frames_(frames), beat_("paper", jobs > 1 && heartbeat_enabled()) {}
  int jobs() const { return jobs_; }
  void prepare(RenderSettings& s) const {
    if (jobs_ > 1) {
      run_beside_others(s);
    }
  }
  void progress(const std::string& line) const {
    if (jobs_ <= 1) {
      saarcor::progress(line);
    }
  }
  void frame_done() {
    if (jobs_ > 1) {
      beat_.beat(std::to_string(++done_) + " / " + std::to_string(frames_) + " frames, " +
                 std::to_string(jobs_) + " at once");
    }
  }
  void finish() { beat_.finish(); }

 private:
  int jobs_;
  std::size_t frames_;
  std::atomic<std::size_t> done_{0};
  Heartbeat beat_;
};

// One table's entry for one scene: the frame at the table's resolution and its figures.
nlohmann::json table_entry(int table, const PaperScene& ps, PreparedScene& prep, RenderSettings& s,
                           bool rebuild, int scale, const FramePool& pool) {
  s.res = table == 3 ? Resolution{512 / scale, 384 / scale} : Resolution{1024 / scale, 768 / scale};
  if (rebuild) build_prepared_image(prep, s, ff::kFp24);
  pool.progress("Table " + std::to_string(table) + ": " + ps.paper + " (" + ps.spec + ")");
  const FrameResult f = render_model(parse_model("cycle"), prep, s);
  return paper_entry_json(table, ps.paper, ps.spec, ps.reference, s.res.width, s.res.height,
                          s.cycle.set, f.cycle);
}

}  // namespace

std::vector<PaperScene> paper_scenes(const std::string& references_dir) {
  std::vector<PaperScene> v = {
      {"Scene6", "builtin:room", 4.0, false},
      {"Terrain", "builtin:terrain", 32.0, false},  // 10.5M triangles: over the 4 MB banks
      {"SunCOR", "builtin:suncor", 4.0, false},
  };
  // Glb/glTF models nearest in triangle count to the paper's scenes we have no stand-in for.
  const std::vector<PaperScene> refs = {
      {"Office", "DamagedHelmet/DamagedHelmet.gltf", 4.0, true},            // 15,452 vs 34,312
      {"Quake3", "2CylinderEngine/2CylinderEngine.gltf", 4.0, true},        // 121,496 vs 39,424
      {"Conference", "ReciprocatingSaw/ReciprocatingSaw.gltf", 8.0, true},  // 198,470 vs 282,805
  };
  if (!references_dir.empty() && std::filesystem::is_directory(references_dir))
    for (PaperScene r : refs) {
      r.spec = (std::filesystem::path(references_dir) / r.spec).string();
      if (std::filesystem::exists(r.spec)) v.push_back(r);
    }
  return v;
}

const Table3Row* paper_table3_row(const std::string& paper_scene) {
  for (const Table3Row& r : paper_table3())
    if (paper_scene == r.scene) return &r;
  return nullptr;
}

// The paper's texture filter for `paper` (a Table 3/4 scene name): "all scenes use bilinear
// filtered textures, Scene6 and Office were rendered with unfiltered textures since otherwise the
// shading bandwidth would slightly limit the performance (10 % at most)". A --set
// image.bilinear=... given by the user applies to every scene instead.
std::vector<std::string> paper_settings(const PaperOptions& opts, const std::string& paper) {
  std::vector<std::string> set = opts.set;
  const bool given = std::any_of(set.begin(), set.end(), [](const std::string& kv) {
    return kv.rfind("image.bilinear=", 0) == 0;
  });
  const bool unfiltered = paper == "Scene6" || paper == "Office";
  if (!given) set.insert(set.begin(), unfiltered ? "image.bilinear=0" : "image.bilinear=1");
  return set;
}

nlohmann::json run_paper_tables(const PaperOptions& opts) {
  check_options(opts);
  const std::vector<PaperScene> scenes = chosen_scenes(opts);
  std::vector<int> tables;
  if (opts.table != 4) tables.push_back(3);
  if (opts.table != 3) tables.push_back(4);
  // One task per scene (its tables share the scene's load); the entries in scene order.
  FramePool pool(std::min(resolve_jobs(opts.jobs), static_cast<int>(scenes.size())),
                 scenes.size() * tables.size());
  std::vector<nlohmann::json> per_scene(scenes.size(), nlohmann::json::array());
  run_tasks(scenes.size(), pool.jobs(), [&](std::size_t i) {
    const PaperScene& ps = scenes[i];
    RenderSettings s = frame_settings("512x384", 0.0, false, 0, ps.bank_mb);
    s.cycle.set = paper_settings(opts, ps.paper);
    s.cycle.sample = opts.sample;
    s.cycle.sample_spec = opts.sample_spec;
    s.res = tables.front() == 3 ? Resolution{512 / opts.scale, 384 / opts.scale}
                                : Resolution{1024 / opts.scale, 768 / opts.scale};
    pool.prepare(s);
    pool.progress("loading " + ps.spec);
    PreparedScene prep = prepare_scene(ps.spec, s);
    for (std::size_t t = 0; t < tables.size(); ++t) {
      per_scene[i].push_back(table_entry(tables[t], ps, prep, s, t > 0, opts.scale, pool));
      pool.frame_done();
    }
  });
  pool.finish();
  return paper_tables_json(opts.scale, opts.set, per_scene);
}

namespace {

struct TextColumn {
  const char* key;
  const char* head;
  int width;
  int decimals;
};

const std::vector<TextColumn>& text_columns(int table) {
  static const std::vector<TextColumn> t3 = {{"fps", "fps", 7, 1},
                                             {"cycles_per_packet", "cyc/pkt", 8, 1},
                                             {"mrays_per_s", "Mrays/s", 8, 2}};
  static const std::vector<TextColumn> t4 = {
      {"fps", "fps", 7, 1},
      {"usage_traversal", "trav%", 6, 0},
      {"usage_list", "list%", 6, 0},
      {"usage_transformation", "xfrm%", 6, 0},
      {"usage_intersection", "int%", 6, 0},
      {"hit_traversal", "hit-t", 6, 0},
      {"hit_list", "hit-l", 6, 0},
      {"hit_transformation", "hit-x", 6, 0},
      {"mb_s_dynrtc", "dynrtc", 7, 0},
      {"mb_s_shading", "shade", 6, 0},
      {"mb_s_total", "total", 6, 0},
      {"cycles_per_packet", "cyc/pkt", 8, 1},
      {"mrays_per_s", "Mrays/s", 8, 2},
      {"shading_bytes_per_pixel", "B/px", 6, 1},
  };
  return table == 3 ? t3 : t4;
}

std::string table_heading(int table, const nlohmann::json& result) {
  const int scale = result["scale"].get<int>();
  std::string s = table == 3 ? "Table 3 (paper: 512x384" : "Table 4 (paper: 1024x768";
  s += ", primary rays, textured shading; 90 MHz, 1 DynRTP, 64 threads, 4-ray packets)";
  if (scale != 1)
    s += "; model at 1/" + std::to_string(scale) + " of the resolution, fps scaled to the paper's";
  return s + "\n";
}

std::string text_line(const char* label, const nlohmann::json& figs,
                      const std::vector<TextColumn>& cols, const char* which) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%-34s", label);
  std::string s = buf;
  for (const TextColumn& c : cols) {
    const double v = figs[c.key][which].get<double>();
    std::snprintf(buf, sizeof buf, " %*.*f", c.width,
                  std::string(which) == "ratio" ? 2 : c.decimals, v);
    s += buf;
  }
  return s + "\n";
}

}  // namespace

std::string paper_text(const nlohmann::json& result) {
  std::string s;
  for (int table : {3, 4}) {
    const std::vector<TextColumn>& cols = text_columns(table);
    bool headed = false;
    for (const nlohmann::json& e : result["entries"]) {
      if (e["table"].get<int>() != table) continue;
      if (!headed) {
        s += (s.empty() ? "" : "\n") + table_heading(table, result);
        char buf[64];
        std::snprintf(buf, sizeof buf, "%-34s", "scene");
        s += buf;
        for (const TextColumn& c : cols) {
          std::snprintf(buf, sizeof buf, " %*s", c.width, c.head);
          s += buf;
        }
        s += "\n";
        headed = true;
      }
      const std::string paper = e["paper_scene"].get<std::string>();
      const bool ref = e["kind"] == "reference";
      const std::string name = std::filesystem::path(e["scene"].get<std::string>()).filename();
      const bool bilinear = std::find(e["configuration"].begin(), e["configuration"].end(),
                                      "image.bilinear=1") != e["configuration"].end();
      const std::string model = (ref ? "  reference " : "  model ") + name;
      // The paper's row names its texture filter, which the model's frame used too.
      const std::string label =
          paper + (ref ? " (no stand-in)" : "") + (bilinear ? ", bilinear" : ", unfiltered");
      s += text_line(label.c_str(), e["figures"], cols, "paper");
      s += text_line(model.substr(0, 34).c_str(), e["figures"], cols, "model");
      s += text_line("  ratio model/paper", e["figures"], cols, "ratio");
    }
  }
  if (s.find("Table 4") != std::string::npos)
    s += "shade: the RGS's shading-bank reads and frame-buffer writes (the paper's shading "
         "bandwidth includes the frame buffer); B/px: both in bytes per pixel\n";
  return s;
}

std::string paper_csv(const nlohmann::json& result) {
  std::string s = "table,paper_scene,scene,kind,resolution,figure,model,paper,ratio\n";
  char buf[128];
  for (const nlohmann::json& e : result["entries"])
    for (const auto& [key, f] : e["figures"].items()) {
      s += std::to_string(e["table"].get<int>()) + "," + e["paper_scene"].get<std::string>() + "," +
           e["scene"].get<std::string>() + "," + e["kind"].get<std::string>() + "," +
           e["resolution"].get<std::string>() + "," + key;
      std::snprintf(buf, sizeof buf, ",%.6g,%.6g,%.6g\n", f["model"].get<double>(),
                    f["paper"].get<double>(), f["ratio"].get<double>());
      s += buf;
    }
  return s;
}

nlohmann::json run_thread_curve(const PaperOptions& opts) {
  check_options(opts);
  RenderSettings s = frame_settings("512x384", 0.0, false, 0, 4.0);
  s.res = {512 / opts.scale, 384 / opts.scale};
  s.cycle.set = paper_settings(opts, "Scene6");
  s.cycle.sample = opts.sample;
  s.cycle.sample_spec = opts.sample_spec;
  progress("thread curve: loading builtin:room");
  const PreparedScene prep = prepare_scene("builtin:room", s);
  const std::vector<int> counts = {1, 2, 4, 8, 16, 32, 64};
  FramePool pool(std::min(resolve_jobs(opts.jobs), static_cast<int>(counts.size())), counts.size());
  std::vector<nlohmann::json> reports(counts.size());
  run_tasks(counts.size(), pool.jobs(), [&](std::size_t i) {
    RenderSettings st = s;
    st.cycle.set.push_back("threads=" + std::to_string(counts[i]));
    pool.prepare(st);
    pool.progress("thread curve: " + std::to_string(counts[i]) + " threads");
    reports[i] = render_model(parse_model("cycle"), prep, st).cycle;
    pool.frame_done();
  });
  pool.finish();
  return thread_curve_json(counts, reports,
                           std::to_string(s.res.width) + "x" + std::to_string(s.res.height));
}

std::string thread_curve_text(const nlohmann::json& curve) {
  std::string s =
      "Threads per DynRTP on the room, " + curve["resolution"].get<std::string>() +
      " (paper section 5: nearly linear speed-up up to 32 threads, about +10 % from 32 to 64)\n"
      "threads      fps  speed-up  x per doubling  paper  ratio  busiest unit %\n";
  char buf[160];
  for (const nlohmann::json& r : curve["rows"]) {
    double busiest = 0.0;
    for (const auto& [unit, u] : r["usage"].items())
      busiest = std::max(busiest, u.get<double>());
    std::snprintf(buf, sizeof buf, "%7d %8.1f %9.2f %15.2f %6.2f %6.2f %15.0f\n",
                  r["threads"].get<int>(), r["fps"].get<double>(), r["speedup"].get<double>(),
                  r["step"].get<double>(), r["paper_step"].get<double>(), r["ratio"].get<double>(),
                  busiest);
    s += buf;
  }
  return s;
}

int run_paper(const PaperOptions& opts) {
  // Tables 1 and 2 count the hardware (testbench/cost_cmd.h); no frame is rendered.
  if (opts.table == 1 || opts.table == 2)
    return run_paper_cost_table(opts.table, opts.set, opts.json, opts.csv);
  if (opts.threads) {
    const nlohmann::json curve = run_thread_curve(opts);
    if (!opts.json.empty()) write_text_file(opts.json, curve.dump(2) + "\n");
    std::printf("%s", thread_curve_text(curve).c_str());
    return 0;
  }
  const nlohmann::json result = run_paper_tables(opts);
  if (!opts.json.empty()) write_text_file(opts.json, result.dump(2) + "\n");
  if (!opts.csv.empty()) write_text_file(opts.csv, paper_csv(result));
  std::printf("%s", paper_text(result).c_str());
  if (!opts.json.empty()) std::printf("  json: %s\n", opts.json.c_str());
  if (!opts.csv.empty()) std::printf("  csv:  %s\n", opts.csv.c_str());
  return 0;
}

}  // namespace saarcor
