// `saarcor render` (docs/compare.md): load, set the time, build the memory image,
// run one model, write PNG / EXR / hit EXR / JSON report. docs/compare.md lists the outputs.
#include "testbench/render_cmd.h"

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "host/float_reference.h"
#include "host/primary_rays.h"
#include "host/tree_settings.h"
#include "testbench/frame_sequence.h"
#include "testbench/heartbeat.h"
#include "testbench/hit_exr.h"
#include "testbench/image_io.h"
#include "testbench/report.h"
#include "units/functional_model.h"
#include "units/request_trace.h"

namespace saarcor {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

bool parse_int(const std::string& s, int& out) {
  if (s.empty() || s.size() > 9) return false;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
  }
  out = std::stoi(s);
  return true;
}

std::uint32_t float_bits(float f) {
  std::uint32_t b;
  std::memcpy(&b, &f, 4);
  return b;
}

// ---- float reference ---------------------------------------------------------------------------

host::FloatParams float_params(const RenderSettings& s) {
  host::FloatParams p;
  p.shadows = s.shadows;
  p.secondary = s.depth > 0;
  p.instance_step = s.float_instance_step;
  return p;
}

PixelHit to_pixel_hit(const host::FloatHit& h, std::uint32_t instance_id, const host::FloatRay& r) {
  PixelHit p;
  p.t = h.t;
  p.u = h.u;
  p.v = h.v;
  p.cos = h.cos;
  p.instance = h.hit() ? instance_id : 0xFFFFFFFFu;
  p.triangle = h.hit() ? h.triangle : 0xFFFFFFFFu;
  if (!h.hit()) {
    p.t = std::numeric_limits<float>::infinity();
    p.u = p.v = p.cos = 0.0f;
  }
  p.ox = r.origin.x;
  p.oy = r.origin.y;
  p.oz = r.origin.z;
  p.dx = r.direction.x;
  p.dy = r.direction.y;
  p.dz = r.direction.z;
  return p;
}

FrameResult render_float_frame(const PreparedScene& prep, const RenderSettings& settings) {
  FrameResult r;
  r.model = "float";
  const auto t0 = Clock::now();
  const host::FloatFrame frame = host::render_float(prep.built, prep.scene, float_params(settings));
  r.seconds = seconds_since(t0);
  r.hits.width = frame.width;
  r.hits.height = frame.height;
  r.hits.pixels.resize(frame.pixels.size());
  for (std::size_t i = 0; i < frame.pixels.size(); ++i) {
    const host::FloatPixel& p = frame.pixels[i];
    r.hits.pixels[i] = to_pixel_hit(p.hit, p.instance_id, p.ray);
  }
  r.image.width = frame.width;
  r.image.height = frame.height;
  r.image.rgb = frame.rgb;
  const host::FloatTraceStats& s = frame.stats;
  r.rays = s.rays;
  r.counter_stats = float_counter_stats(s);
  r.counters = nest(r.counter_stats);
  r.counters["note"] = "float reference: counters of primary rays; binary32 ops are not counted";
  return r;
}

PixelHit trace_float_pixel(const PreparedScene& prep, const RenderSettings& settings,
                           PixelCoord px) {
  const host::FloatScene fs(prep.built, settings.float_instance_step);
  const host::FloatRay ray = host::primary_ray(host::to_float(prep.built.basis), px.x, px.y);
  // Primary rays: t_min = 0 (strict), t_max = +inf (docs/shading.md section 2).
  const host::FloatHit h = fs.trace(ray, 0.0f, std::numeric_limits<float>::infinity());
  const std::uint32_t id = h.hit() ? prep.built.instances.at(h.instance).id : 0xFFFFFFFFu;
  return to_pixel_hit(h, id, ray);
}

// ---- functional model --------------------------------------------------------------------------

// Float<7, m> chosen by an explicit switch: each case is its own template instantiation.
units::FunctionalFrame run_functional_m(int m, const memif::MemoryImage& image,
                                        const units::FunctionalParams& params,
                                        const units::ProgressFn& progress, std::ostream* trace) {
  switch (m) {
    case 10:
      return units::run_functional<ff::Float<7, 10>>(image, params, progress, nullptr, trace);
    case 11:
      return units::run_functional<ff::Float<7, 11>>(image, params, progress, nullptr, trace);
    case 12:
      return units::run_functional<ff::Float<7, 12>>(image, params, progress, nullptr, trace);
    case 13:
      return units::run_functional<ff::Float<7, 13>>(image, params, progress, nullptr, trace);
    case 14:
      return units::run_functional<ff::Float<7, 14>>(image, params, progress, nullptr, trace);
    case 15:
      return units::run_functional<ff::Float<7, 15>>(image, params, progress, nullptr, trace);
    case 16:
      return units::run_functional<ff::Float<7, 16>>(image, params, progress, nullptr, trace);
    case 17:
      return units::run_functional<ff::Float<7, 17>>(image, params, progress, nullptr, trace);
    case 18:
      return units::run_functional<ff::Float<7, 18>>(image, params, progress, nullptr, trace);
    case 19:
      return units::run_functional<ff::Float<7, 19>>(image, params, progress, nullptr, trace);
    case 20:
      return units::run_functional<ff::Float<7, 20>>(image, params, progress, nullptr, trace);
    case 21:
      return units::run_functional<ff::Float<7, 21>>(image, params, progress, nullptr, trace);
    case 22:
      return units::run_functional<ff::Float<7, 22>>(image, params, progress, nullptr, trace);
    case 23:
      return units::run_functional<ff::Float<7, 23>>(image, params, progress, nullptr, trace);
    default:
      break;
  }
  throw std::runtime_error("bad mantissa " + std::to_string(m) + ": expected " +
                           std::to_string(kMinMantissa) + ".." + std::to_string(kMaxMantissa));
}

// An encoding of the model's format as binary32: exact for Float<7, m <= 23> (the exponent range
// of binary32 holds it), subnormal encodings read as zero as the model reads them.
float to_binary32(std::uint32_t bits, ff::Format f) {
  return static_cast<float>(ff::decode(bits, f, ff::Subnormals::kFlush));
}

PixelHit functional_pixel_hit(const units::FrameSink::Pixel& p, ff::Format f,
                              const host::BuiltImage& built) {
  PixelHit h;
  h.ox = to_binary32(p.o[0], f);
  h.oy = to_binary32(p.o[1], f);
  h.oz = to_binary32(p.o[2], f);
  h.dx = to_binary32(p.d[0], f);
  h.dy = to_binary32(p.d[1], f);
  h.dz = to_binary32(p.d[2], f);
  if (p.instance == memif::kNone) return h;  // miss: t = inf, ids ~0
  if (p.instance >= built.instances.size()) {
    throw std::runtime_error("functional model reported instance " + std::to_string(p.instance) +
                             " beyond the image's " + std::to_string(built.instances.size()));
  }
  h.t = to_binary32(p.t, f);
  h.u = to_binary32(p.u, f);
  h.v = to_binary32(p.v, f);
  h.cos = to_binary32(p.cos, f);
  h.instance = built.instances[p.instance].id;
  h.triangle = p.triangle;
  return h;
}

FrameResult render_functional_frame(const ModelSpec& model, const PreparedScene& prep,
                                    const RenderSettings& settings) {
  FrameResult r;
  r.model = model.name;
  Heartbeat beat("  " + model.name + " model", settings.heartbeat && heartbeat_enabled());
  units::ProgressFn report;
  if (beat.enabled()) {
    report = [&beat](int done, int total) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "packets %d / %d", done, total);
      beat.beat(buf);
      if (done == total) beat.finish(buf);
    };
  }
  const auto t0 = Clock::now();
  const units::FunctionalFrame frame = run_functional_m(
      model.mantissa, prep.built.image, functional_params(settings), report, settings.trace.trace);
  r.seconds = seconds_since(t0);
  r.hits.width = frame.width;
  r.hits.height = frame.height;
  r.hits.pixels.resize(frame.pixels.size());
  for (std::size_t i = 0; i < frame.pixels.size(); ++i) {
    r.hits.pixels[i] = functional_pixel_hit(frame.pixels[i], frame.format, prep.built);
  }
  r.image.width = frame.width;
  r.image.height = frame.height;
  r.image.rgb = frame.rgb;
  r.counter_stats = functional_counter_stats(frame, r.rays);
  r.counters = nest(r.counter_stats);
  return r;
}

// ---- cycle model (testbench/cycle_render.h) -----------------------------------------------------

FrameResult render_cycle_frame(const ModelSpec& model, const PreparedScene& prep,
                               const RenderSettings& settings) {
  FrameResult r;
  r.model = model.name;
  const auto t0 = Clock::now();
  const CycleFrame c = run_cycle_render(prep.built.image, functional_params(settings),
                                        settings.cycle, settings.heartbeat, settings.trace);
  r.seconds = seconds_since(t0);
  r.hits.width = c.frame.width;
  r.hits.height = c.frame.height;
  r.hits.pixels.resize(c.frame.pixels.size());
  for (std::size_t i = 0; i < c.frame.pixels.size(); ++i)
    r.hits.pixels[i] = functional_pixel_hit(c.frame.pixels[i], c.frame.format, prep.built);
  r.image.width = c.frame.width;
  r.image.height = c.frame.height;
  r.image.rgb = c.frame.rgb;
  r.rays = c.rays;
  // The trees are part of the configuration an architect sweeps (kd.* keys).
  r.cycle = cycle_report_json(c, &prep.built.params);
  r.table4 = table4_text(c, prep.spec);
  // The per-ray counters of the frame report and the float units' op counts.
  for (ReportStat& st : cycle_stats(c))
    if (st.name.starts_with("per_ray.")) r.counter_stats.push_back(std::move(st));
  for (ReportStat& st : op_stats(c.frame.units))
    r.counter_stats.push_back(std::move(st));
  r.counters = nest(r.counter_stats);
  return r;
}

void check_functional_format(const ModelSpec& model, const PreparedScene& prep) {
  const ff::Format want{7, model.mantissa};
  if (!(prep.built.params.format == want)) {
    throw std::runtime_error("model " + model.name + " needs a memory image in " +
                             describe_format(want) + ", the image was built in " +
                             describe_format(prep.built.params.format));
  }
}

}  // namespace

void run_beside_others(RenderSettings& s) {
  s.heartbeat = false;
  if (s.cycle.host_threads == 0) {
    s.cycle.host_threads = 1;
  }
}

void progress(const std::string& line) {
  if (heartbeat_enabled()) std::fprintf(stderr, "%s\n", line.c_str());
}

std::string output_prefix(const std::string& out, std::initializer_list<std::string_view> exts) {
  for (const std::string_view ext : exts) {
    if (out.size() > ext.size() && out.ends_with(ext))
      return out.substr(0, out.size() - ext.size());
  }
  if (out.empty() || std::ranges::find(exts, std::string_view(out)) != exts.end()) {
    throw std::runtime_error("bad --out '" + out + "': expected a file prefix");
  }
  return out;
}

Resolution parse_resolution(const std::string& text) {
  const auto x = text.find('x');
  Resolution r;
  if (x == std::string::npos || !parse_int(text.substr(0, x), r.width) ||
      !parse_int(text.substr(x + 1), r.height)) {
    throw std::runtime_error("bad --res '" + text + "': expected WxH, e.g. 512x384");
  }
  if (r.width < 1 || r.height < 1 || r.width > 16384 || r.height > 16384) {
    throw std::runtime_error("bad --res '" + text + "': width and height must be 1..16384");
  }
  return r;
}

PixelCoord parse_pixel(const std::string& text, const Resolution& res) {
  const auto c = text.find(',');
  PixelCoord p;
  if (c == std::string::npos || !parse_int(text.substr(0, c), p.x) ||
      !parse_int(text.substr(c + 1), p.y)) {
    throw std::runtime_error("bad --pixel '" + text + "': expected x,y, e.g. 10,20");
  }
  if (p.x >= res.width || p.y >= res.height) {
    throw std::runtime_error("bad --pixel '" + text + "': outside the " +
                             std::to_string(res.width) + "x" + std::to_string(res.height) +
                             " frame");
  }
  return p;
}

ModelSpec parse_model(const std::string& name) {
  ModelSpec m;
  m.name = name;
  if (name == "float") {
    m.kind = ModelKind::kFloat;
    m.mantissa = 23;
    return m;
  }
  if (name == "fp24") {
    m.kind = ModelKind::kFunctional;
    m.mantissa = 16;
    return m;
  }
  int mant = 0;
  if (name.rfind("e7m", 0) == 0 && parse_int(name.substr(3), mant) && mant >= kMinMantissa &&
      mant <= kMaxMantissa) {
    m.kind = ModelKind::kFunctional;
    m.mantissa = mant;
    return m;
  }
  if (name == "cycle" || name == "cycle-e7m23") {
    m.kind = ModelKind::kCycle;
    m.mantissa = name == "cycle" ? 16 : 23;
    return m;
  }
  throw std::runtime_error("unknown model '" + name +
                           "': expected float, fp24, e7m10..e7m23, cycle or cycle-e7m23");
}

PreparedScene prepare_scene(const std::string& spec, const RenderSettings& settings,
                            ff::Format format) {
  if (settings.depth < 0 || settings.depth > 16) {
    throw std::runtime_error("bad --depth " + std::to_string(settings.depth) + ": expected 0..16");
  }
  if (!(settings.bank_mb > 0.0) || settings.bank_mb > 16384.0) {
    throw std::runtime_error("bad --bank-mb " + std::to_string(settings.bank_mb) +
                             ": expected a size in (0, 16384] MB");
  }
  if (!std::isfinite(settings.time) || settings.time < 0.0) {
    throw std::runtime_error("bad --time " + std::to_string(settings.time) +
                             ": expected a time >= 0 in seconds");
  }
  PreparedScene p;
  p.spec = spec;
  auto t0 = Clock::now();
  progress("loading " + spec);
  p.scene = host::load_scene(spec);
  if (settings.time != 0.0) p.scene.set_time(settings.time);
  p.load_seconds = seconds_since(t0);
  build_prepared_image(p, settings, format);
  return p;
}

void build_prepared_image(PreparedScene& p, const RenderSettings& settings, ff::Format format) {
  host::ImageParams ip;
  ip.format = format;
  ip.width = settings.res.width;
  ip.height = settings.res.height;
  ip.max_depth = static_cast<std::uint32_t>(settings.depth);
  ip.bank_words = static_cast<std::uint32_t>(std::llround(settings.bank_mb * 262144.0));
  ip.top_level_buffers = settings.top_level_buffers;
  for (const std::string& kv : settings.cycle.set)
    if (host::is_tree_setting(kv)) host::apply_tree_setting(ip, kv);
  const auto t0 = Clock::now();
  progress("building the memory image (" + describe_format(format) + ")");
  p.built = host::build_image(p.scene, ip);
  p.build_seconds = seconds_since(t0);
}

FrameResult render_model(const ModelSpec& model, const PreparedScene& prep,
                         const RenderSettings& settings) {
  switch (model.kind) {
    case ModelKind::kFloat:
      return render_float_frame(prep, settings);
    case ModelKind::kFunctional:
      check_functional_format(model, prep);
      return render_functional_frame(model, prep, settings);
    case ModelKind::kCycle:
      check_functional_format(model, prep);
      return render_cycle_frame(model, prep, settings);
  }
  throw std::runtime_error("model '" + model.name + "' is not available yet");
}

PixelHit trace_pixel(const ModelSpec& model, const PreparedScene& prep,
                     const RenderSettings& settings, PixelCoord pixel) {
  switch (model.kind) {
    case ModelKind::kFloat:
      return trace_float_pixel(prep, settings, pixel);
    case ModelKind::kFunctional: {
      check_functional_format(model, prep);
      const units::PixelTrace t =
          units::trace_pixel(prep.built.image, functional_params(settings), pixel.x, pixel.y);
      return functional_pixel_hit(t.pixel, prep.built.params.format, prep.built);
    }
    case ModelKind::kCycle: {
      // The cycle model runs whole frames: the pixel's record from the frame (bit-identical to
      // the fp24 model's replay by construction).
      const FrameResult f = render_model(model, prep, settings);
      return f.hits
          .pixels[static_cast<std::size_t>(pixel.y) * static_cast<std::size_t>(f.hits.width) +
                  static_cast<std::size_t>(pixel.x)];
    }
  }
  throw std::runtime_error("model '" + model.name + "' is not available yet");
}

std::string format_pixel_hit(PixelCoord px, const PixelHit& h) {
  char buf[1024];
  std::string s;
  std::snprintf(buf, sizeof buf, "pixel %d,%d: ", px.x, px.y);
  s += buf;
  if (h.hit()) {
    std::snprintf(buf, sizeof buf,
                  "hit instance %" PRIu32 " triangle %" PRIu32
                  "\n"
                  "  t   = %.9g (0x%08x)\n  u   = %.9g (0x%08x)\n  v   = %.9g (0x%08x)\n"
                  "  cos = %.9g (0x%08x)\n",
                  h.instance, h.triangle, h.t, float_bits(h.t), h.u, float_bits(h.u), h.v,
                  float_bits(h.v), h.cos, float_bits(h.cos));
  } else {
    std::snprintf(buf, sizeof buf, "miss\n");
  }
  s += buf;
  std::snprintf(buf, sizeof buf,
                "  ray origin    (%.9g, %.9g, %.9g)\n  ray direction (%.9g, %.9g, %.9g)\n", h.ox,
                h.oy, h.oz, h.dx, h.dy, h.dz);
  s += buf;
  return s;
}

units::FunctionalParams functional_params(const RenderSettings& s) {
  units::FunctionalParams p;
  p.shadows = s.shadows;
  p.secondary = s.depth > 0;
  p.max_depth = s.depth > 0 ? s.depth : -1;
  return p;
}

std::string join_words(const std::vector<std::string>& words) {
  std::string s;
  for (const std::string& w : words) {
    if (!s.empty()) s += ' ';
    s += w;
  }
  return s;
}

RenderSettings frame_settings(const std::string& res, double time, bool shadows, int depth,
                              double bank_mb) {
  RenderSettings s;
  s.res = parse_resolution(res);
  s.time = time;
  s.shadows = shadows;
  s.depth = depth;
  s.bank_mb = bank_mb;
  return s;
}

void check_trace_options(const TraceOptions& t, const ModelSpec& model, bool pixel) {
  const bool cycle = model.kind == ModelKind::kCycle;
  if (t.any() && model.kind == ModelKind::kFloat)
    throw std::runtime_error(
        "--trace and --konata need a model with DynRTP units (fp24, e7mM, cycle, cycle-e7m23); "
        "the float reference has none");
  if (!t.konata.empty() && !cycle)
    throw std::runtime_error("--konata needs --model cycle (the functional model has no cycles)");
  if (!t.perfetto.empty() && !cycle)
    throw std::runtime_error("--perfetto needs --model cycle (the functional model has no cycles)");
  if (!t.perfetto.empty() && !t.perfetto.ends_with(".json"))
    throw std::runtime_error("bad --perfetto '" + t.perfetto +
                             "': the trace-event file name ends in .json");
  if ((t.window_given || !t.konata_threads.empty()) && !cycle)
    throw std::runtime_error(
        "--trace-from, --trace-to and --konata-threads apply to --model cycle");
  if (t.window_given && !t.any())
    throw std::runtime_error(
        "--trace-from and --trace-to limit --trace, --konata or --perfetto: give one");
  if (!t.konata_threads.empty() && t.konata.empty())
    throw std::runtime_error("--konata-threads chooses the threads of --konata: give it");
  if (t.to < t.from)
    throw std::runtime_error("bad --trace-to " + std::to_string(t.to) + ": before --trace-from " +
                             std::to_string(t.from));
  if (pixel && t.any())
    throw std::runtime_error(
        "--pixel prints its packet's requests itself: drop --trace, --konata, --perfetto");
}

std::vector<std::uint32_t> parse_thread_list(const std::string& text, int threads) {
  const auto bad = [&](const std::string& why) {
    return std::runtime_error("bad --konata-threads '" + text + "': " + why);
  };
  const auto number = [&](const std::string& w) {
    if (w.empty() || w.size() > 9 || w.find_first_not_of("0123456789") != std::string::npos)
      throw bad("expected thread ids like 0,3,8-11");
    const int v = std::stoi(w);
    if (v >= threads)
      throw bad("thread " + w + " does not exist (" + std::to_string(threads) + " threads)");
    return static_cast<std::uint32_t>(v);
  };
  std::vector<std::uint32_t> out;
  std::istringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    const std::size_t dash = item.find('-');
    const std::uint32_t a = number(item.substr(0, dash));
    const std::uint32_t b = dash == std::string::npos ? a : number(item.substr(dash + 1));
    if (b < a) throw bad("range " + item + " runs backwards");
    for (std::uint32_t t = a; t <= b; ++t)
      out.push_back(t);
  }
  if (out.empty() || text.back() == ',') throw bad("expected thread ids like 0,3,8-11");
  return out;
}

int pixel_packet(PixelCoord pixel, const Resolution& res, int packet) {
  const units::PacketTiling t = units::packet_tiling(res.width, res.height, packet);
  return (pixel.y / t.tile_height) * t.tiles_x + pixel.x / t.tile_width;
}

namespace {

// The trace files of a render, open while it runs: a file that cannot be written is an error
// before the render, and one left half-written by an error is removed.
class TraceFiles {
 public:
  TraceFiles(const TraceOptions& t, int threads) : t_(t) {
    run.from = t.from;
    run.to = t.to;
    if (!t.konata_threads.empty())
      run.konata_threads = parse_thread_list(t.konata_threads, threads);
    open(t.file, "--trace", trace_, run.trace);
    open(t.konata, "--konata", konata_, run.konata);
    open(t.perfetto, "--perfetto", perfetto_, run.perfetto);
  }
  TraceFiles(const TraceFiles&) = delete;
  TraceFiles& operator=(const TraceFiles&) = delete;
  ~TraceFiles() {
    if (done_) return;
    for (const std::string* f : {&t_.file, &t_.konata, &t_.perfetto})
      if (!f->empty()) {
        std::error_code ec;
        std::filesystem::remove(*f, ec);
      }
  }
  // Closes the files; throws when one could not be written completely.
  void finish(std::vector<std::pair<std::string, std::string>>& outputs) {
    close(t_.file, "--trace", trace_, "trace", outputs);
    close(t_.konata, "--konata", konata_, "konata", outputs);
    close(t_.perfetto, "--perfetto", perfetto_, "perfetto", outputs);
    done_ = true;
  }
  units::RunTraceOptions run;

 private:
  static void open(const std::string& file, const char* flag, std::ofstream& f, std::ostream*& to) {
    if (file.empty()) return;
    f.open(file, std::ios::binary);
    if (!f) throw std::runtime_error(std::string("cannot write ") + flag + " '" + file + "'");
    to = &f;
  }
  static void close(const std::string& file, const char* flag, std::ofstream& f, const char* key,
                    std::vector<std::pair<std::string, std::string>>& outputs) {
    if (file.empty()) return;
    f.close();
    if (!f) throw std::runtime_error(std::string("cannot write ") + flag + " '" + file + "'");
    outputs.push_back({key, file});
  }
  const TraceOptions& t_;
  std::ofstream trace_, konata_, perfetto_;
  bool done_ = false;
};

// --pixel with the cycle model: the frame with the request trace of the pixel's packet, whose
// lines are printed with their cycles (the hit record comes from the same frame).
PixelHit cycle_pixel(const ModelSpec& model, const PreparedScene& prep, RenderSettings settings,
                     PixelCoord pixel, std::vector<std::string>& lines) {
  std::ostringstream trace;
  settings.trace.trace = &trace;
  settings.trace.packet =
      pixel_packet(pixel, settings.res, resolve_cycle_params(settings.cycle).packet);
  const PixelHit h = trace_pixel(model, prep, settings, pixel);
  std::istringstream in(trace.str());
  for (std::string text; std::getline(in, text);) {
    if (text.starts_with("#")) continue;
    const units::TraceLine l = units::parse_trace_line(text);
    char line[200];
    std::snprintf(line, sizeof line,
                  "cycle=%-9llu dynrtp=%d thread=%-3d %-14s %-18s item=%-10u steps=%-3d "
                  "mask=%llx %s",
                  static_cast<unsigned long long>(l.cycle), l.dynrtp, l.thread,
                  units::unit_name(l.unit), units::phase_name(l.phase), l.item, l.steps,
                  static_cast<unsigned long long>(l.mask), units::ray_kind_name(l.kind));
    lines.emplace_back(line);
  }
  return h;
}

}  // namespace

namespace {

// The render's options checked before the scene loads (a bad one costs no render): the model's
// own options, --pixel, the traces, the output names. Returns the cycle model's threads over all
// DynRTPs (--konata-threads; 0 for the other models).
int check_render_options(const RenderOptions& opts, const ModelSpec& model,
                         const std::optional<PixelCoord>& pixel) {
  int threads = 0;
  if (model.kind == ModelKind::kCycle) {
    const units::CycleParams cp = resolve_cycle_params(opts.cycle);
    threads = cp.pipelines * cp.threads;
  } else if (opts.cycle.any_given()) {
    throw std::runtime_error(
        "--preset, --set (but kd.* keys), --interval, --host-threads and --vcd apply to --model "
        "cycle only");
  }
  check_trace_options(opts.trace, model, pixel.has_value());
  if (!opts.out_dir.empty()) {
    check_out_dir(opts.out_dir);
    if (opts.out_given || !opts.report.empty() || !opts.hits.empty())
      throw std::runtime_error(
          "--out-dir names every file it writes: drop --out, --report and --hits' file name "
          "(--hits alone writes DIR/hits.exr)");
    if (pixel) throw std::runtime_error("--pixel prints one pixel; --out-dir is for frames");
  } else if (opts.hits_asked && opts.hits.empty()) {
    throw std::runtime_error("bad --hits: expected a file name FILE.exr (or --out-dir DIR)");
  }
  if (opts.out_dir.empty()) output_prefix(opts.out, {".png", ".exr"});  // throws on a bad --out
  if (!opts.hits.empty() && !opts.hits.ends_with(".exr")) {
    throw std::runtime_error("bad --hits '" + opts.hits + "': a hit EXR file name ends in .exr");
  }
  if (!opts.report.empty() && !opts.report.ends_with(".json")) {
    throw std::runtime_error("bad --report '" + opts.report + "': expected a .json file name");
  }
  return threads;
}

// --pixel x,y: the pixel's hit record and every unit request of its packet.
void print_pixel(const RenderOptions& opts, const ModelSpec& model, const PreparedScene& prep,
                 const RenderSettings& settings, PixelCoord pixel) {
  std::vector<std::string> cycle_lines;
  const PixelHit h = model.kind == ModelKind::kCycle
                         ? cycle_pixel(model, prep, settings, pixel, cycle_lines)
                         : trace_pixel(model, prep, settings, pixel);
  std::printf("saarcor render %s --model %s --res %dx%d --time %g\n%s", opts.scene.c_str(),
              model.name.c_str(), settings.res.width, settings.res.height, settings.time,
              format_pixel_hit(pixel, h).c_str());
  if (model.kind == ModelKind::kFunctional) {
    // Every unit request of the pixel's packet, in the order the thread program made them.
    const units::PixelTrace t =
        units::trace_pixel(prep.built.image, functional_params(settings), pixel.x, pixel.y);
    for (const std::string& line : t.log)
      std::printf("  %s\n", line.c_str());
  }
  // The cycle model: every request of the pixel's packet with the cycle a unit issued it.
  for (const std::string& line : cycle_lines)
    std::printf("  %s\n", line.c_str());
}

// The frame's image (and float EXR), hit EXR and report, each added to `outputs`.
void write_frame_outputs(const RenderOptions& opts, const ModelSpec& model,
                         const PreparedScene& prep, const RenderSettings& settings,
                         const FrameResult& frame, TraceFiles& traces,
                         std::vector<std::pair<std::string, std::string>>& outputs) {
  const bool in_dir = !opts.out_dir.empty();
  const std::string out =
      in_dir ? run_file(opts.out_dir, "image") : output_prefix(opts.out, {".png", ".exr"});
  const std::string png = out + ".png";
  write_rgb8(png, frame.image);
  outputs.push_back({"image", png});
  traces.finish(outputs);
  if (opts.exr) {
    const std::string exr = out + ".exr";
    write_float_image(exr, to_float_image(frame.image));
    outputs.push_back({"image_exr", exr});
  }
  const std::string hits =
      in_dir && opts.hits_asked ? run_file(opts.out_dir, "hits.exr") : opts.hits;
  if (!hits.empty()) {
    write_hit_exr(hits, frame.hits);
    outputs.push_back({"hits", hits});
  }
  if (in_dir) {
    write_render_folder(opts.out_dir,
                        render_report_json(opts.scene, model.name, frame, prep, settings), frame,
                        opts.argv, outputs);
  } else if (!opts.report.empty()) {
    write_render_report(opts.report,
                        render_report_json(opts.scene, model.name, frame, prep, settings), outputs);
  }
}

}  // namespace

int run_render(const RenderOptions& opts) {
  if (opts.cycle.sample && (opts.frames_given || !opts.pixel.empty()))
    throw std::runtime_error(
        "--sample estimates one frame's figures: not with --frames or --pixel");
  if (opts.frames_given) return run_frame_sequence(opts);
  if (opts.fps_given || opts.dt_given || opts.frame_gap || !opts.bus_sweep.empty() ||
      !opts.resume.empty())
    throw std::runtime_error("--fps, --dt, --frame-gap, --bus-sweep and --resume need --frames N");
  const ModelSpec model = parse_model(opts.model);
  RenderSettings settings =
      frame_settings(opts.res, opts.time, opts.shadows, opts.depth, opts.bank_mb);
  settings.cycle = opts.cycle;
  std::optional<PixelCoord> pixel;
  if (!opts.pixel.empty()) pixel = parse_pixel(opts.pixel, settings.res);
  const int threads = check_render_options(opts, model, pixel);
  TraceFiles traces(opts.trace, threads);  // opened now: an unwritable one costs no render
  settings.trace = traces.run;

  const ff::Format format =
      model.kind != ModelKind::kFloat ? ff::Format{7, model.mantissa} : ff::kFp24;
  const PreparedScene prep = prepare_scene(opts.scene, settings, format);
  if (pixel) {
    print_pixel(opts, model, prep, settings, *pixel);
    return 0;
  }

  progress("rendering " + std::to_string(settings.res.width) + "x" +
           std::to_string(settings.res.height) + " with the " + model.name + " model");
  const FrameResult frame = render_model(model, prep, settings);
  std::vector<std::pair<std::string, std::string>> outputs;
  write_frame_outputs(opts, model, prep, settings, frame, traces, outputs);
  const double rays_per_s = frame.seconds > 0 ? static_cast<double>(frame.rays) / frame.seconds : 0;
  std::printf("saarcor render: %s, model %s, %dx%d, %.3f s, %" PRIu64 " rays (%.3g rays/s)\n",
              opts.scene.c_str(), model.name.c_str(), settings.res.width, settings.res.height,
              frame.seconds, frame.rays, rays_per_s);
  for (const auto& [k, v] : outputs)
    std::printf("  %-10s %s\n", (k + ":").c_str(), v.c_str());
  if (!frame.table4.empty()) std::printf("%s", frame.table4.c_str());
  return 0;
}

}  // namespace saarcor
