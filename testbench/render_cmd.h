// `saarcor render`: one frame of a scene through one of the models of docs/compare.md (float
// reference, functional model in Float<7,m>; the cycle model comes later), written as image, hit
// EXR and JSON report (docs/compare.md). The pieces are public so `saarcor precision` and the
// tests reuse them.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "fixedfloat/format.h"
#include "host/float_reference.h"
#include "host/image_builder.h"
#include "host/scene.h"
#include "testbench/cycle_render.h"
#include "testbench/hit_buffer.h"
#include "testbench/report.h"

namespace saarcor {

struct Resolution {
  int width = 512;
  int height = 384;
};
// "WxH" with 1 <= W, H <= 16384; throws "bad --res 'TEXT': ..." otherwise.
Resolution parse_resolution(const std::string& text);

// --out is a prefix the commands add extensions to; a prefix given with one of the extensions
// they write ("frame.png") loses it, so it names the file written instead of "frame.png.png".
// Throws "bad --out '': ..." on an empty prefix.
std::string output_prefix(const std::string& out, std::initializer_list<std::string_view> exts);

struct PixelCoord {
  int x = 0;
  int y = 0;
};
// "x,y" inside the frame; throws "bad --pixel 'TEXT': ..." otherwise.
PixelCoord parse_pixel(const std::string& text, const Resolution& res);

enum class ModelKind { kFloat, kFunctional, kCycle };
struct ModelSpec {
  ModelKind kind = ModelKind::kFunctional;
  int mantissa = 16;  // functional model: Float<7, mantissa>
  std::string name = "fp24";
};
// "float", "fp24" (= "e7m16"), "e7m<M>" (Float<7,M>, M = 10..23), "cycle" (the cycle model, fp24).
ModelSpec parse_model(const std::string& name);
inline constexpr int kMinMantissa = 10;
inline constexpr int kMaxMantissa = 23;

struct RenderSettings {
  Resolution res;
  double time = 0.0;     // seconds into the scene's animation
  bool shadows = false;  // shadow rays (docs/shading.md section 6)
  int depth = 0;         // secondary rays (reflection, transparency) up to this depth; 0 = none
  double bank_mb = 4.0;  // SRAM bank size of the memory image (the prototype: 4 MB)
  // --model float: how rays enter an instance (host/float_reference.h); binary32 makes Float<7,23>
  // bit-identical to the reference on every scene (tests), binary64 is the golden image.
  host::InstanceStep float_instance_step = host::InstanceStep::kBinary64;
  CycleRenderOptions cycle;  // --model cycle: preset, --set overrides, --interval, --vcd
  bool heartbeat = true;     // a frame's terminal heartbeat (off for the sweep's parallel frames)
  // The request trace (the functional and the cycle models) and the Kanata log (the cycle model)
  // to write; the streams belong to the caller (docs/traces.md).
  units::RunTraceOptions trace;
  // Copies of the top level in the image (host::ImageParams::top_level_buffers): 2 for frame
  // sequences (testbench/frame_sequence.h).
  int top_level_buffers = 1;
};

// A frame rendered beside others, one per worker thread (`saarcor sweep`'s points, `saarcor
// paper`'s scenes): its thread programs stay on the worker's thread unless --host-threads says
// otherwise (two frames per core would run slower than one; the results are the same,
// docs/cycle-model.md), and it writes no heartbeat of its own (the command's counts frames).
void run_beside_others(RenderSettings& s);

// The scene loaded, set to the time, with its memory image built in `format`.
struct PreparedScene {
  std::string spec;
  host::Scene scene;
  host::BuiltImage built;
  double load_seconds = 0.0;
  double build_seconds = 0.0;
};
PreparedScene prepare_scene(const std::string& spec, const RenderSettings& settings,
                            ff::Format format = ff::kFp24);
// (Re)builds prepared.built from prepared.scene in `format` (the precision study builds one image
// per format from one loaded scene).
void build_prepared_image(PreparedScene& prepared, const RenderSettings& settings,
                          ff::Format format);

// One frame of one model: hit records (hit.instance = glTF node index, values converted exactly
// to binary32), the shaded RGB8 image, and what it cost.
struct FrameResult {
  std::string model;
  HitBuffer hits;
  Rgb8Image image;
  double seconds = 0.0;     // the model's run time (wall clock)
  std::uint64_t rays = 0;   // rays traced (primary, plus shadow and secondary when on)
  nlohmann::json counters;  // per-ray counters and op counts, totals and per ray
  std::vector<ReportStat> counter_stats;  // the same with their declarations (stats.txt)
  nlohmann::json cycle;                   // --model cycle: the per-frame report (cycle_report_json)
  std::string table4;                     // --model cycle: the Table 4 printout
};

// Runs the model on a prepared scene. The functional model needs the image built in
// Format{7, mantissa}; it throws when the prepared image has another format.
FrameResult render_model(const ModelSpec& model, const PreparedScene& prepared,
                         const RenderSettings& settings);

// The hit record of one pixel traced alone (the replay recipe of a failing check).
PixelHit trace_pixel(const ModelSpec& model, const PreparedScene& prepared,
                     const RenderSettings& settings, PixelCoord pixel);
std::string format_pixel_hit(PixelCoord pixel, const PixelHit& hit);

// The functional model's shading options of a frame (--shadows, --depth).
units::FunctionalParams functional_params(const RenderSettings& settings);

// The words separated by single spaces ("threads=4 packet=16").
std::string join_words(const std::vector<std::string>& words);

// The frame settings the commands share (--res, --time, --shadows, --depth, --bank-mb); throws
// for a bad --res.
RenderSettings frame_settings(const std::string& res, double time, bool shadows, int depth,
                              double bank_mb);

// --trace FILE [--trace-from N --trace-to M], --konata FILE [--konata-threads LIST] and
// --perfetto FILE.json (docs/traces.md).
struct TraceOptions {
  std::string file;      // the request trace (models fp24, e7mM, cycle, cycle-e7m23)
  std::string konata;    // the Kanata log (cycle models)
  std::string perfetto;  // the Chrome trace-event timeline (cycle models; units/perfetto_trace.h)
  std::uint64_t from = 0;
  std::uint64_t to = std::numeric_limits<std::uint64_t>::max();
  bool window_given = false;   // --trace-from or --trace-to on the command line
  std::string konata_threads;  // "0,3,8-11": the Kanata log's threads (default: every thread)
  bool any() const { return !file.empty() || !konata.empty() || !perfetto.empty(); }
};
// Checks the trace options against the model (one line naming the option on misuse).
void check_trace_options(const TraceOptions& t, const ModelSpec& model, bool pixel);
// "0,3,8-11" as thread ids, each below `threads` (all DynRTPs' threads); throws "bad
// --konata-threads ..." otherwise.
std::vector<std::uint32_t> parse_thread_list(const std::string& text, int threads);
// The RGC's packet index holding pixel (x, y) at packet width P (units/functional_model.h).
int pixel_packet(PixelCoord pixel, const Resolution& res, int packet);

struct RenderOptions {
  std::string scene;
  std::string model = "fp24";
  std::string res = "512x384";
  double time = 0.0;
  std::string out = "out/render";
  bool exr = false;
  std::string hits;    // hit EXR path, optional
  std::string report;  // JSON path, optional
  std::string pixel;   // "x,y": trace one pixel and print its record instead of a frame
  bool shadows = false;
  int depth = 0;
  double bank_mb = 4.0;
  CycleRenderOptions cycle;
  TraceOptions trace;
  // --out-dir DIR (testbench/report.h write_run_folder): image.png, image.exr (--exr), hits.exr
  // (--hits without a file name), report.json, stats.txt, config.json, command.txt, host.json;
  // --out, --report and a --hits file name are refused with it (the folder names every file).
  std::string out_dir;
  bool out_given = false;         // --out was on the command line (not its default)
  bool hits_asked = false;        // --hits was on the command line, with or without a file name
  std::vector<std::string> argv;  // the command line, for command.txt
  // --frames N [--fps F | --dt S] [--frame-gap] [--bus-sweep MB/S,...]: a frame sequence
  // (testbench/frame_sequence.h, docs/frames.md).
  int frames = 0;
  double fps = 0.0;
  double dt = 0.0;
  bool frame_gap = false;
  std::string bus_sweep;
  // --resume DIR: the run folder of a sequence that was stopped (testbench/run_journal.h): only
  // the frames its journal lacks are rendered. Implies --out-dir DIR.
  std::string resume;
  bool frames_given = false, fps_given = false, dt_given = false;
};

// Returns 0; throws std::runtime_error with one line on bad input. With --frames: the sequence
// (run_frame_sequence).
int run_render(const RenderOptions& opts);

// Writes one line of progress to stderr when the heartbeat would show (a terminal, CI unset:
// testbench/heartbeat.h), and nothing otherwise.
void progress(const std::string& line);

}  // namespace saarcor
