// `saarcor paper`: the paper's Tables 3 and 4 reproduced side by side. Each stand-in scene runs
// through the cycle model at the table's setting (Table 3: 512x384, Table 4: 1024x768; primary
// rays, textured shading, the prototype configuration) and its row is printed beside the paper's
// with a ratio (model / paper) for every column (docs/fidelity.md).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace saarcor {

// One scene of the paper and what the model runs for it.
struct PaperScene {
  std::string paper;       // the paper's name ("Scene6")
  std::string spec;        // the scene the model renders ("builtin:room", a glTF path)
  double bank_mb = 4.0;    // SRAM bank size the stand-in needs
  bool reference = false;  // a model nearest in size, shown for reference, not a stand-in
};

// The stand-ins (room, terrain, suncor) and, when `references_dir` names a folder holding them,
// the reference models nearest in size to Office, Quake3 and Conference.
std::vector<PaperScene> paper_scenes(const std::string& references_dir);

// The paper's Table 3 row for a scene name: SaarCOR and OpenRT fps at 512x384; nullptr if absent.
struct Table3Row {
  const char* scene;
  double triangles;
  int objects;
  double saarcor_fps;
  double openrt_fps;
};
const Table3Row* paper_table3_row(const std::string& paper_scene);

// The figures compared, in column order, with their names (JSON/CSV keys).
struct PaperFigure {
  const char* key;
  double model = 0.0;
  double paper = 0.0;
};
// A table's figures are made by the report module from the frame's cycle report
// (testbench/report.h paper_figures): the paper's cycles per packet and Mrays/s follow from its
// fps at the table's resolution and 4-ray packets.

struct PaperOptions {
  int table = 0;         // 3 or 4; 0 = both (and the thread curve with `threads`)
  bool threads = false;  // the room's thread curve 1..64 beside the paper's (section 5)
  int scale = 1;         // divide the tables' resolutions by this (quick looks; the output says so)
  std::string references = "../shared/scenes";  // folder of the reference models ("" = none)
  std::vector<std::string> scenes;              // only these paper names (empty = all)
  std::vector<std::string> set;                 // cycle model --set keys for every run
  bool sample = false;                          // --sample [SPEC]: frames sampled (sampling.h)
  std::string sample_spec;
  std::string csv;
  std::string json;
  // Scenes (tables) or thread counts (--threads) rendered at once on this host: 0 = its cores.
  // Every figure is the same for any count; each frame then runs on its worker's thread.
  int jobs = 0;
};

// The --set keys a paper scene's frames run with: the user's, and the paper's texture filter for
// that scene (unfiltered for Scene6 and Office, bilinear for the others) unless the user set one.
std::vector<std::string> paper_settings(const PaperOptions& opts, const std::string& paper);

// The result: one entry per table and scene, with the model's whole cycle report and the
// settings it ran with.
nlohmann::json run_paper_tables(const PaperOptions& opts);
// The room at the Table 3 setting with 1, 2, 4, ..., 64 threads: fps, speed-up over one thread,
// and the speed-up of each doubling beside the paper's (x2 up to 32 threads, about x1.10 from 32
// to 64). `scale` divides the resolution as for the tables.
nlohmann::json run_thread_curve(const PaperOptions& opts);
std::string thread_curve_text(const nlohmann::json& curve);

// The side-by-side text (model, paper and ratio lines per scene) and the CSV of a result.
std::string paper_text(const nlohmann::json& result);
std::string paper_csv(const nlohmann::json& result);

// Prints the tables; returns 0. Bad input throws std::runtime_error with one line.
int run_paper(const PaperOptions& opts);

}  // namespace saarcor
