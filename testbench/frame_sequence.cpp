// `saarcor render SCENE --frames N`: frame sequences of dynamic scenes (docs/frames.md).
#include "testbench/frame_sequence.h"

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "host/frame_upload.h"
#include "host/tree_settings.h"
#include "hw/stats.h"
#include "testbench/chip.h"
#include "testbench/heartbeat.h"
#include "testbench/report.h"
#include "testbench/run_journal.h"
#include "units/functional_model.h"

namespace saarcor {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

constexpr int kMaxFrames = 10000;
// The frame registers and the scene regions' bases travel over the bus with each upload into the
// chip's shadow registers, which the frame swap latches (memif/image_format.h).
constexpr std::uint32_t kRegisterWords =
    (sizeof(memif::FrameRegisters) + sizeof(memif::SceneRegions)) / 4;

// FNV-1a over every hit record (t, u, v, cos, ids, ray) and the image: equal digests, equal frames.
std::uint64_t digest(const units::FunctionalFrame& f) {
  std::uint64_t h = 1469598103934665603ull;
  const auto mix = [&h](std::uint32_t w) {
    for (int i = 0; i < 4; ++i) {
      h ^= (w >> (8 * i)) & 0xFFu;
      h *= 1099511628211ull;
    }
  };
  for (const units::FrameSink::Pixel& p : f.pixels) {
    for (std::uint32_t w : {p.t, p.u, p.v, p.cos, p.instance, p.triangle})
      mix(w);
    for (int k = 0; k < 3; ++k) {
      mix(p.o[static_cast<std::size_t>(k)]);
      mix(p.d[static_cast<std::size_t>(k)]);
    }
  }
  for (std::uint8_t c : f.rgb)
    mix(c);
  return h;
}

std::uint64_t rays_of(const units::FunctionalFrame& f) {
  std::uint64_t n = 0;
  for (std::uint64_t r : f.rays_issued)
    n += r;
  return n;
}

// The cycle model's frame k against the functional model's (docs/compare.md: bit for bit).
void check_frame(const units::FunctionalFrame& c, const units::FunctionalFrame& ref, int index,
                 double time) {
  std::size_t differ = 0;
  for (std::size_t i = 0; i < ref.pixels.size() && i < c.pixels.size(); ++i) {
    const units::FrameSink::Pixel &a = c.pixels[i], &b = ref.pixels[i];
    if (a.t != b.t || a.u != b.u || a.v != b.v || a.cos != b.cos || a.instance != b.instance ||
        a.triangle != b.triangle || a.o != b.o || a.d != b.d)
      ++differ;
  }
  char buf[200];
  if (c.pixels.size() != ref.pixels.size() || differ != 0 || c.rgb != ref.rgb ||
      rays_of(c) != rays_of(ref)) {
    std::snprintf(
        buf, sizeof buf,
        "frame %d (t = %g s): the cycle model's frame differs from the functional "
        "model's (%zu hit records differ, image %s, %" PRIu64 " rays against %" PRIu64 ")",
        index, time, differ, c.rgb == ref.rgb ? "identical" : "differs", rays_of(c), rays_of(ref));
    throw std::runtime_error(buf);
  }
}

// Every data word of the shading and scene banks: what the host writes before the first frame.
memif::HostUpload initial_load(const host::BuiltImage& b) {
  memif::HostUpload u;
  for (const memif::BankRange& r : host::data_words(b)) {
    const auto& src = b.image.bank(r.bank);
    u.runs.push_back(
        {r.bank, r.begin, std::vector<std::uint32_t>(src.begin() + r.begin, src.begin() + r.end)});
  }
  u.register_words = kRegisterWords;
  return u;
}

void apply_runs(memif::MemoryImage& board, const std::vector<memif::UploadRun>& runs) {
  for (const memif::UploadRun& r : runs)
    std::copy(r.words.begin(), r.words.end(),
              board.bank(r.bank).begin() + static_cast<std::ptrdiff_t>(r.offset));
}

// The model's own consistency: after an upload the board holds what the host built.
void require_same_data(const memif::MemoryImage& board, const memif::MemoryImage& host, int index) {
  for (int bank = memif::kShadingBank; bank < memif::kNumBanks; ++bank)
    if (board.bank(bank) != host.bank(bank))
      throw std::runtime_error("frame " + std::to_string(index) + ": after the upload bank " +
                               std::to_string(bank) + " differs from the host's image");
}

Rgb8Image image_of(const units::FunctionalFrame& f) {
  return {f.width, f.height, f.rgb};
}

double mb(std::uint64_t bytes) {
  return static_cast<double>(bytes) / 1048576.0;
}

// What the host prepared for the next frame while this one renders.
struct NextFrame {
  SequenceFrame row;
  memif::HostUpload upload;
};

// Frame k + 1's rebuild and upload (paper section 2: only the top level is rebuilt).
NextFrame prepare_next(host::Scene& scene, host::BuiltImage& host, const memif::MemoryImage& board,
                       const std::vector<memif::BankRange>& reads, int index, double time) {
  NextFrame n;
  n.row.index = index;
  scene.set_time(time);
  n.row.time = scene.time;
  const std::uint64_t top0 = host.stats.top_level_builds;
  const std::uint64_t bottom0 = host.stats.bottom_level_builds;
  const auto t0 = Clock::now();
  const host::UploadDelta d = host::rebuild_top_level(host, scene);
  n.row.host_rebuild_seconds = seconds_since(t0);
  n.row.top_rebuilt = d.top_rebuilt;
  n.row.moved_instances = d.moved_instances;
  n.row.top_level_builds = host.stats.top_level_builds - top0;
  n.row.bottom_level_builds = host.stats.bottom_level_builds - bottom0;
  n.upload.runs = host::changed_words(board, host.image);
  n.upload.register_words = kRegisterWords;
  n.upload.frame_reads = reads;
  n.row.gap = host::overlaps(n.upload.runs, reads);
  n.row.upload_bytes = n.upload.bytes();
  n.row.upload_words = n.upload.sram_bytes() / 4;
  n.row.upload_runs = n.upload.runs.size();
  return n;
}

void take_figures(SequenceFrame& row, const CycleFrame& c) {
  row.cycles = c.cycles;
  row.fps = c.fps;
  row.rays = c.rays;
  row.figures = c.figures;
  row.shading_bytes_per_pixel = c.shading_bytes_per_pixel;
  row.cycles_per_packet =
      c.packets == 0 ? 0.0 : static_cast<double>(c.cycles) / static_cast<double>(c.packets);
}

CycleRunOptions cycle_run_options(const RenderSettings& s, Heartbeat& beat, int index, int frames) {
  CycleRunOptions ro;
  ro.shading = functional_params(s);
  if (s.cycle.host_threads != 0)
    ro.programs =
        s.cycle.host_threads == 2 ? units::ProgramMode::kAhead : units::ProgramMode::kPacketFirst;
  if (beat.enabled())
    ro.progress = [&beat, index, frames](std::uint64_t cycles, int done, int total) {
      beat.beat("frame " + std::to_string(index + 1) + " / " + std::to_string(frames) + ", " +
                Heartbeat::cycle_status(cycles, done, total, beat.seconds()));
    };
  return ro;
}

void check_options(const ModelSpec& model, const SequenceOptions& o) {
  if (model.kind == ModelKind::kFloat)
    throw std::runtime_error(
        "--frames needs a model that reads the memory image (fp24, e7mM, cycle, cycle-e7m23); the "
        "float reference has none to upload to");
  if (o.frames < 1 || o.frames > kMaxFrames)
    throw std::runtime_error("bad --frames " + std::to_string(o.frames) + ": expected 1.." +
                             std::to_string(kMaxFrames));
  if (!std::isfinite(o.dt))
    throw std::runtime_error("bad --dt: expected seconds >= 0 between frames");
  if (!std::isfinite(o.start) || o.start < 0.0)
    throw std::runtime_error("bad --time " + std::to_string(o.start) + ": expected seconds >= 0");
}

// The timeline (docs/frames.md): frame k + 1 starts when frame k has rendered and k + 1's upload
// is stored; an upload in a gap starts only when frame k has rendered.
void place(SequenceFrame& next, const SequenceFrame& cur, std::uint64_t gap_cycles) {
  const std::uint64_t end = cur.start_cycle + cur.cycles;
  if (next.gap) {
    next.upload_cycles = cur.cycles + gap_cycles;
    next.hidden = false;
  } else {
    next.hidden = next.upload_cycles <= cur.cycles;
  }
  next.start_cycle = cur.start_cycle + std::max(cur.cycles, next.upload_cycles);
  next.stall_cycles = next.start_cycle - end;
}

}  // namespace

std::uint64_t SequenceResult::total_cycles() const {
  if (frames.empty()) return 0;
  return frames.back().start_cycle + frames.back().cycles;
}

double SequenceResult::fps() const {
  const std::uint64_t c = total_cycles();
  return c == 0 ? 0.0
                : static_cast<double>(frames.size()) * clock_mhz * 1e6 / static_cast<double>(c);
}

double SequenceResult::render_fps() const {
  std::uint64_t c = 0;
  for (const SequenceFrame& f : frames)
    c += f.cycles;
  return c == 0 ? 0.0
                : static_cast<double>(frames.size()) * clock_mhz * 1e6 / static_cast<double>(c);
}

int SequenceResult::gaps() const {
  int n = 0;
  for (std::size_t k = 1; k < frames.size(); ++k)
    n += frames[k].gap ? 1 : 0;
  return n;
}

int SequenceResult::hidden_uploads() const {
  int n = 0;
  for (std::size_t k = 1; k < frames.size(); ++k)
    n += frames[k].hidden ? 1 : 0;
  return n;
}

double SequenceResult::break_even_mb_s() const {
  double worst = 0.0;
  for (std::size_t k = 1; k < frames.size(); ++k) {
    if (frames[k].gap) continue;  // no bandwidth hides an upload that waits for the frame's end
    const double render_s = static_cast<double>(frames[k - 1].cycles) / (clock_mhz * 1e6);
    if (render_s > 0) worst = std::max(worst, mb(frames[k].upload_bytes) / render_s);
  }
  return worst;
}

namespace {

// What stays fixed over one sequence's frames.
struct SequenceRun {
  const SequenceOptions& opts;
  const RenderSettings& s;
  const units::CycleParams& cp;
  const units::FunctionalParams& fparams;
  bool cycle;
  host::Scene& scene;
  host::BuiltImage& host;
  memif::MemoryImage& board;
  Heartbeat& beat;
  const FrameSink& sink;
  const SequenceResume& resume;
};

SequenceResult sequence_header(const std::string& spec, const ModelSpec& model,
                               const RenderSettings& s, const SequenceOptions& opts,
                               const units::CycleParams& cp, bool cycle, const host::Scene& scene,
                               const host::BuiltImage& host) {
  SequenceResult r;
  r.scene = spec;
  r.model = model.name;
  r.width = s.res.width;
  r.height = s.res.height;
  r.cycle = cycle;
  r.frame_gap = opts.frame_gap;
  r.clock_mhz = cycle ? cp.clock_mhz : 0.0;
  r.bus_mb_s = cycle ? cp.hostbus_mb_s : 0.0;
  r.dt = opts.dt >= 0.0 ? opts.dt : scene.animation_seconds / opts.frames;
  r.objects = scene.objects.size();
  r.instances = scene.instances.size();
  for (const host::Instance& i : scene.instances)
    r.dynamic_instances += i.dynamic ? 1 : 0;
  r.top_copy_bytes = 8ull * host.top_node_capacity + 4ull * host.top_list_capacity +
                     4ull * static_cast<std::uint64_t>(ff::row_words(host.params.format)) *
                         memif::kInstanceRows * host.instances.size();
  return r;
}

// The initial load: the board's banks written over the bus before anything renders.
void initial_upload(memif::MemoryImage& board, const host::BuiltImage& host,
                    const units::CycleParams& cp, bool cycle, SequenceResult& r) {
  const memif::HostUpload load = initial_load(host);
  r.initial_load_bytes = load.bytes();
  if (cycle) {
    progress("uploading the scene over the host bus (" + std::to_string(load.bytes()) + " bytes)");
    r.initial_load_cycles = run_upload(board, cp, load);
  } else {
    apply_runs(board, load.runs);
  }
  require_same_data(board, host.image, 0);
}

// One frame: the swap, the render (with the next frame's upload beside it on the cycle model),
// the check, the sink; then the next frame's row becomes current.
void run_frame(SequenceRun& run, int k, SequenceFrame& cur, SequenceResult& r) {
  const auto t0 = Clock::now();
  const SequenceOptions& opts = run.opts;
  host::BuiltImage& host = run.host;
  memif::MemoryImage& board = run.board;
  // The swap: the registers the host sent latch, the frame buffers alternate.
  cur.index = k;
  cur.frame_bank = k % 2 == 0 ? memif::kFrameBank0 : memif::kFrameBank1;
  cur.top_copy = static_cast<int>(host.top_buffer);
  host.image.registers().frame_bank = static_cast<std::uint32_t>(cur.frame_bank);
  board.registers() = host.image.registers();
  board.regions() = host.image.regions();  // they move only with a relayout (in a gap)
  const std::vector<memif::BankRange> reads = host::frame_reads(host, cur.frame_bank);
  units::FunctionalFrame reference;
  if (!run.cycle || opts.check) reference = units::run_functional(board, run.fparams);
  // The host prepares the next frame while this one renders.
  const bool more = k + 1 < opts.frames;
  NextFrame next;
  if (more) next = prepare_next(run.scene, host, board, reads, k + 1, opts.start + (k + 1) * r.dt);
  std::uint64_t gap_cycles = 0;
  units::FunctionalFrame frame;
  if (run.cycle) {
    const CycleRunOptions ro = cycle_run_options(run.s, run.beat, k, opts.frames);
    CycleFrame c = more && !next.row.gap ? run_cycle(board, run.cp, ro, next.upload)
                                         : run_cycle(std::as_const(board), run.cp, ro);
    if (more && next.row.gap) gap_cycles = run_upload(board, run.cp, next.upload);
    next.row.upload_cycles = c.upload_cycles;
    take_figures(cur, c);
    if (opts.check) {
      check_frame(c.frame, reference, k, cur.time);
      cur.checked = true;
    }
    frame = std::move(c.frame);
  } else {
    if (more) apply_runs(board, next.upload.runs);
    cur.rays = rays_of(reference);
    frame = std::move(reference);
  }
  if (more) require_same_data(board, host.image, k + 1);
  cur.digest = digest(frame);
  cur.host_seconds = seconds_since(t0);
  if (run.sink) run.sink(cur, image_of(frame));
  if (run.resume.on_frame)
    run.resume.on_frame({cur, more ? next.row.upload_cycles : 0, gap_cycles});
  run.beat.beat("frame " + std::to_string(k + 1) + " / " + std::to_string(opts.frames) + " done");
  if (more && run.cycle) place(next.row, cur, gap_cycles);
  r.frames.push_back(cur);
  if (more) cur = next.row;
}

// A frame a stopped run finished (its journal record): the host's side alone (the swap, the next
// frame's rebuild and upload, stored into the board as the bus stored it then) and its row as it
// was, so the next frame starts from the state it had. The record must be this frame's.
void replay_frame(SequenceRun& run, int k, SequenceFrame& cur, SequenceResult& r,
                  const FrameRecord& rec) {
  host::BuiltImage& host = run.host;
  memif::MemoryImage& board = run.board;
  cur.frame_bank = k % 2 == 0 ? memif::kFrameBank0 : memif::kFrameBank1;
  cur.top_copy = static_cast<int>(host.top_buffer);
  if (rec.row.index != k || rec.row.time != cur.time || rec.row.top_copy != cur.top_copy ||
      rec.row.frame_bank != cur.frame_bank || rec.row.upload_bytes != cur.upload_bytes)
    throw std::runtime_error("--resume: the journal's frame " + std::to_string(k) +
                             " is not the frame this scene and these options give");
  host.image.registers().frame_bank = static_cast<std::uint32_t>(cur.frame_bank);
  board.registers() = host.image.registers();
  board.regions() = host.image.regions();
  const std::vector<memif::BankRange> reads = host::frame_reads(host, cur.frame_bank);
  r.frames.push_back(rec.row);
  if (k + 1 >= run.opts.frames) return;
  NextFrame next =
      prepare_next(run.scene, host, board, reads, k + 1, run.opts.start + (k + 1) * r.dt);
  apply_runs(board, next.upload.runs);
  require_same_data(board, host.image, k + 1);
  next.row.upload_cycles = rec.next_upload_cycles;
  if (run.cycle) place(next.row, rec.row, rec.gap_cycles);
  cur = next.row;
}

}  // namespace

SequenceResult run_sequence(const std::string& spec, const ModelSpec& model,
                            const RenderSettings& settings, const SequenceOptions& opts,
                            const FrameSink& sink, const SequenceResume& resume) {
  check_options(model, opts);
  const bool cycle = model.kind == ModelKind::kCycle;
  units::CycleParams cp;
  if (cycle) cp = resolve_cycle_params(settings.cycle);  // a bad --set fails before the load
  RenderSettings s = settings;
  s.time = opts.start;
  s.top_level_buffers = opts.frame_gap ? 1 : 2;
  PreparedScene prep = prepare_scene(spec, s, ff::Format{7, model.mantissa});
  host::BuiltImage& host = prep.built;
  host::Scene& scene = prep.scene;

  SequenceResult r = sequence_header(spec, model, s, opts, cp, cycle, scene, host);
  const units::FunctionalParams fparams =
      cycle ? units::functional_params(cp, functional_params(s)) : functional_params(s);
  memif::MemoryImage board(host.image.format(), host.image.bank_words());
  initial_upload(board, host, cp, cycle, r);

  Heartbeat beat("sequence", s.heartbeat && heartbeat_enabled());
  SequenceFrame cur;
  cur.time = scene.time;
  cur.top_rebuilt = true;  // frame 0: both levels built with the image
  cur.top_level_builds = host.stats.top_level_builds;
  cur.bottom_level_builds = host.stats.bottom_level_builds;
  cur.host_rebuild_seconds = host.stats.top_build_seconds;
  SequenceRun run{opts, s, cp, fparams, cycle, scene, host, board, beat, sink, resume};
  const auto kept = static_cast<int>(std::min<std::size_t>(resume.finished.size(), opts.frames));
  for (int k = 0; k < opts.frames; ++k) {
    if (k < kept) {
      replay_frame(run, k, cur, r, resume.finished[static_cast<std::size_t>(k)]);
      continue;
    }
    if (stop_signal() != 0) break;  // stopped: the frames so far are kept
    run_frame(run, k, cur, r);
  }
  const std::string done = std::to_string(r.frames.size()) + " / " + std::to_string(opts.frames);
  beat.finish(stop_signal() != 0
                  ? "stopped by " + signal_name(stop_signal()) + ": frames " + done + " kept"
                  : "frames " + done);
  return r;
}

// ---- the journal's frame records ---------------------------------------------------------------

std::string frame_record_text(const FrameRecord& rec) {
  const SequenceFrame& f = rec.row;
  nlohmann::json j;
  j["index"] = f.index;
  j["time"] = double_bits(f.time);
  j["frame_bank"] = f.frame_bank;
  j["top_copy"] = f.top_copy;
  j["top_rebuilt"] = f.top_rebuilt;
  j["counts"] = {f.moved_instances,
                 f.top_level_builds,
                 f.bottom_level_builds,
                 f.upload_bytes,
                 f.upload_words,
                 f.upload_runs,
                 f.upload_cycles,
                 f.stall_cycles,
                 f.start_cycle,
                 f.cycles,
                 f.rays,
                 f.digest};
  j["flags"] = {f.gap, f.hidden, f.checked};
  j["doubles"] = {double_bits(f.fps), double_bits(f.shading_bytes_per_pixel),
                  double_bits(f.cycles_per_packet)};
  j["figures_cycle"] = f.figures.cycle;
  for (const double v : f.figures.value)
    j["figures"].push_back(double_bits(v));
  j["next_upload_cycles"] = rec.next_upload_cycles;
  j["gap_cycles"] = rec.gap_cycles;
  return j.dump();
}

FrameRecord parse_frame_record(const std::string& text) {
  FrameRecord rec;
  SequenceFrame& f = rec.row;
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    f.index = j.at("index").get<int>();
    f.time = bits_double(j.at("time").get<std::string>());
    f.frame_bank = j.at("frame_bank").get<int>();
    f.top_copy = j.at("top_copy").get<int>();
    f.top_rebuilt = j.at("top_rebuilt").get<bool>();
    const auto c = j.at("counts").get<std::vector<std::uint64_t>>();
    const auto b = j.at("flags").get<std::vector<bool>>();
    const auto d = j.at("doubles").get<std::vector<std::string>>();
    const auto fig = j.at("figures").get<std::vector<std::string>>();
    if (c.size() != 12 || b.size() != 3 || d.size() != 3 || fig.size() != f.figures.value.size())
      throw std::runtime_error("fields missing");
    f.moved_instances = static_cast<std::uint32_t>(c[0]);
    std::uint64_t* counts[] = {&f.top_level_builds,
                               &f.bottom_level_builds,
                               &f.upload_bytes,
                               &f.upload_words,
                               &f.upload_runs,
                               &f.upload_cycles,
                               &f.stall_cycles,
                               &f.start_cycle,
                               &f.cycles,
                               &f.rays,
                               &f.digest};
    for (std::size_t i = 0; i < std::size(counts); ++i)
      *counts[i] = c[i + 1];
    f.gap = b[0];
    f.hidden = b[1];
    f.checked = b[2];
    f.fps = bits_double(d[0]);
    f.shading_bytes_per_pixel = bits_double(d[1]);
    f.cycles_per_packet = bits_double(d[2]);
    f.figures.cycle = j.at("figures_cycle").get<std::uint64_t>();
    for (std::size_t i = 0; i < fig.size(); ++i)
      f.figures.value[i] = bits_double(fig[i]);
    rec.next_upload_cycles = j.at("next_upload_cycles").get<std::uint64_t>();
    rec.gap_cycles = j.at("gap_cycles").get<std::uint64_t>();
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("a frame record of the journal is damaged: ") + e.what());
  }
  return rec;
}

// ---- bus sweep ------------------------------------------------------------------------------

std::vector<double> parse_bus_sweep(const std::string& text) {
  const auto bad = [&](const std::string& why) {
    return std::runtime_error("bad --bus-sweep '" + text + "': " + why);
  };
  std::vector<double> out;
  std::istringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      throw bad("expected bandwidths in MB/s like 1,8,132");
    }
    if (used != item.size() || !std::isfinite(v) || v <= 0.0 || v > 1e6)
      throw bad("'" + item + "' is not a bandwidth in (0, 1000000] MB/s");
    if (std::ranges::find(out, v) != out.end()) throw bad(item + " is given twice");
    out.push_back(v);
  }
  if (out.empty() || text.back() == ',') throw bad("expected bandwidths in MB/s like 1,8,132");
  return out;
}

std::vector<SequenceResult> run_bus_sweep(const std::string& scene, const ModelSpec& model,
                                          const RenderSettings& settings,
                                          const SequenceOptions& opts,
                                          const std::vector<double>& mb_s) {
  if (model.kind != ModelKind::kCycle)
    throw std::runtime_error("--bus-sweep needs --model cycle (the host bus is timed there)");
  std::vector<SequenceResult> points;
  for (std::size_t i = 0; i < mb_s.size(); ++i) {
    RenderSettings s = settings;
    char kv[64];
    std::snprintf(kv, sizeof kv, "hostbus.mb_s=%.17g", mb_s[i]);
    s.cycle.set.emplace_back(kv);
    SequenceOptions o = opts;
    o.check = opts.check && i == 0;  // the others must give the first point's frames
    progress("bus sweep: " + std::to_string(mb_s[i]) + " MB/s");
    points.push_back(run_sequence(scene, model, s, o));
    const SequenceResult& p = points.back();
    for (std::size_t k = 0; k < p.frames.size(); ++k)
      if (p.frames[k].digest != points.front().frames[k].digest)
        throw std::runtime_error("bus sweep: at " + std::string(kv) + " frame " +
                                 std::to_string(k) + " differs from the first point's");
  }
  return points;
}

// ---- the command ----------------------------------------------------------------------------

namespace {

void refuse_single_frame_options(const RenderOptions& o) {
  if (!o.pixel.empty()) throw std::runtime_error("--pixel traces one frame: drop --frames");
  if (o.exr || o.hits_asked)
    throw std::runtime_error("--exr and --hits write one frame's files: drop them with --frames");
  if (o.trace.any() || o.trace.window_given)
    throw std::runtime_error("--trace and --konata trace one frame: drop them with --frames");
  if (!o.cycle.vcd.empty() || o.cycle.interval != 0)
    throw std::runtime_error("--vcd and --interval trace one frame: drop them with --frames");
}

SequenceOptions sequence_options(const RenderOptions& o) {
  SequenceOptions s;
  s.frames = o.frames;
  s.start = o.time;
  s.frame_gap = o.frame_gap;
  if (o.fps_given && o.dt_given) throw std::runtime_error("give --fps or --dt, not both");
  if (o.fps_given) {
    if (!std::isfinite(o.fps) || o.fps <= 0.0)
      throw std::runtime_error("bad --fps " + std::to_string(o.fps) +
                               ": expected frames per animation second > 0");
    s.dt = 1.0 / o.fps;
  }
  if (o.dt_given) {
    if (!std::isfinite(o.dt) || o.dt < 0.0)
      throw std::runtime_error("bad --dt " + std::to_string(o.dt) +
                               ": expected seconds >= 0 between frames");
    s.dt = o.dt;
  }
  return s;
}

// The shortest frame at the modelled clock (0 without a clock): what the host's rebuild, done
// while the frame before renders, has to fit in.
double shortest_frame_ms(const SequenceResult& r) {
  if (!r.cycle || r.frames.empty()) return 0.0;
  std::uint64_t c = r.frames.front().cycles;
  for (const SequenceFrame& f : r.frames)
    c = std::min(c, f.cycles);
  return static_cast<double>(c) / (r.clock_mhz * 1e3);
}

std::string numbered(const std::string& prefix, int index) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%04d", index);
  return prefix + buf + ".png";
}

// What a sequence (or a bus sweep) leaves: its report, host times, printout, statistics and CSV;
// in a run folder, its journal and the command line that began it.
struct SequenceOutput {
  nlohmann::json report;
  nlohmann::json host = nlohmann::json::object();
  std::string printout, stats, csv;
  std::unique_ptr<RunJournal> journal;
  std::vector<std::string> argv;
};

// What a sequence's journal must agree on to be resumed: everything that changes a frame.
nlohmann::json frames_identity(const RenderOptions& o, const SequenceOptions& so) {
  return {{"command", "render --frames"},
          {"scene", o.scene},
          {"model", o.model},
          {"res", o.res},
          {"time", o.time},
          {"shadows", o.shadows},
          {"depth", o.depth},
          {"bank_mb", o.bank_mb},
          {"preset", o.cycle.preset},
          {"set", o.cycle.set},
          {"frames", so.frames},
          {"dt", so.dt},
          {"frame_gap", so.frame_gap}};
}

std::string frame_key(int index) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "frame%05d", index);
  return buf;
}

// --out-dir: the folder's journal, new or (--resume) with the frames it holds; each frame is
// appended as it finishes.
std::unique_ptr<RunJournal> open_frames_journal(const RenderOptions& opts,
                                                const SequenceOptions& so, SequenceResume& resume) {
  const nlohmann::json id = frames_identity(opts, so);
  auto journal = opts.resume.empty()
                     ? std::make_unique<RunJournal>(opts.out_dir, id, opts.argv)
                     : std::make_unique<RunJournal>(RunJournal::resume(opts.out_dir, id));
  for (const JournalRecord& rec : journal->records()) {
    if (rec.key != frame_key(static_cast<int>(resume.finished.size())))
      throw std::runtime_error("--resume '" + opts.out_dir + "': journal.txt has " + rec.key +
                               " where " + frame_key(static_cast<int>(resume.finished.size())) +
                               " belongs");
    resume.finished.push_back(parse_frame_record(rec.payload));
  }
  RunJournal* j = journal.get();
  resume.on_frame = [j](const FrameRecord& f) {
    j->append(frame_key(f.row.index), frame_record_text(f));
  };
  return journal;
}

SequenceOutput sequence_output(const RenderOptions& opts, const ModelSpec& model,
                               const RenderSettings& settings, const SequenceOptions& so,
                               const std::string& prefix,
                               std::vector<std::pair<std::string, std::string>>& outputs) {
  const FrameSink sink = [&](const SequenceFrame& f, const Rgb8Image& image) {
    write_rgb8(numbered(prefix, f.index), image);
  };
  SequenceOutput out;
  out.argv = opts.argv;
  SequenceResume resume;
  std::optional<StopOnSignal> stop;
  if (!opts.out_dir.empty()) {
    out.journal = open_frames_journal(opts, so, resume);
    out.argv = out.journal->argv();  // command.txt: the command that began the run
    stop.emplace();                  // SIGINT, SIGTERM: start no frame, keep the finished ones
  }
  const SequenceResult r = run_sequence(opts.scene, model, settings, so, sink, resume);
  if (stop_signal() != 0)
    throw Interrupted(stop_signal(), "render --frames stopped by " + signal_name(stop_signal()) +
                                         ": " + std::to_string(r.frames.size()) + " of " +
                                         std::to_string(so.frames) + " frames kept in " +
                                         opts.out_dir + "/journal.txt; go on with: saarcor " +
                                         "render ... --resume " + opts.out_dir);
  if (!resume.finished.empty())
    out.printout = "resumed: " + std::to_string(resume.finished.size()) + " frames from " +
                   opts.out_dir + "/journal.txt, " +
                   std::to_string(r.frames.size() - resume.finished.size()) + " rendered now\n";
  // A run folder keeps host times in host.json.
  out.report = sequence_json(r, opts.out_dir.empty());
  out.printout += sequence_table(r);
  out.csv = sequence_csv(r);
  out.stats = stats_text(sequence_stat_lines(r));
  out.host = sequence_host_json(r);
  char buf[300];
  std::snprintf(buf, sizeof buf,
                "  host: top-level rebuild at most %.2f ms per frame after the first (this host",
                out.host["top_level_rebuild_seconds_max"].get<double>() * 1e3);
  out.printout += buf;
  if (r.cycle) {
    std::snprintf(buf, sizeof buf, "; the shortest frame at the clock: %.2f ms",
                  shortest_frame_ms(r));
    out.printout += buf;
  }
  out.printout += ")\n";
  outputs.push_back({"images", numbered(prefix, 0) + " .. " +
                                   numbered(prefix, static_cast<int>(r.frames.size()) - 1)});
  return out;
}

SequenceOutput bus_sweep_output(const RenderOptions& opts, const ModelSpec& model,
                                const RenderSettings& settings, const SequenceOptions& so,
                                const std::vector<double>& sweep) {
  const std::vector<SequenceResult> points = run_bus_sweep(opts.scene, model, settings, so, sweep);
  SequenceOutput out;
  out.report["bus_sweep"] = bus_sweep_json(points);
  out.printout = sequence_table(points.front()) + "bus sweep:\n" + bus_sweep_table(points);
  // One block of statistics per bandwidth.
  std::vector<std::pair<std::string, std::vector<StatLine>>> blocks;
  for (const SequenceResult& p : points)
    blocks.push_back({"host bus " + hw::json_number(p.bus_mb_s) + " MB/s", sequence_stat_lines(p)});
  out.stats = stats_text_blocks(blocks);
  return out;
}

}  // namespace

namespace {

// --resume DIR names the run folder (--out-dir beside it must name the same one); one sequence
// only: a bus sweep reruns its sequence per bandwidth and keeps no journal.
RenderOptions resolve_frames_resume(const RenderOptions& opts) {
  RenderOptions o = opts;
  if (o.resume.empty()) return o;
  if (!o.bus_sweep.empty())
    throw std::runtime_error("--resume goes on with one sequence; --bus-sweep keeps no journal");
  if (!o.out_dir.empty() && o.out_dir != o.resume)
    throw std::runtime_error("--resume '" + o.resume + "' and --out-dir '" + o.out_dir +
                             "' name two folders: give one");
  o.out_dir = o.resume;
  return o;
}

// The options a sequence refuses or needs, checked before any frame runs; the bus sweep's
// bandwidths.
std::vector<double> check_sequence(const RenderOptions& opts, const ModelSpec& model,
                                   const RenderSettings& settings, const SequenceOptions& so) {
  if (model.kind != ModelKind::kCycle && opts.cycle.any_given())
    throw std::runtime_error(
        "--preset, --set (but kd.* keys), --interval, --host-threads and --vcd apply to --model "
        "cycle only");
  if (!opts.out_dir.empty()) {
    check_out_dir(opts.out_dir);
    if (opts.out_given || !opts.report.empty())
      throw std::runtime_error("--out-dir names every file it writes: drop --out and --report");
  }
  if (!opts.report.empty() && !opts.report.ends_with(".json"))
    throw std::runtime_error("bad --report '" + opts.report + "': expected a .json file name");
  std::vector<double> sweep;
  if (!opts.bus_sweep.empty()) {
    sweep = parse_bus_sweep(opts.bus_sweep);
    if (model.kind != ModelKind::kCycle)
      throw std::runtime_error("--bus-sweep needs --model cycle (the host bus is timed there)");
  }
  if (model.kind == ModelKind::kCycle) resolve_cycle_params(settings.cycle);
  if (!std::isfinite(opts.time) || opts.time < 0.0)
    throw std::runtime_error("bad --time " + std::to_string(opts.time) + ": expected seconds >= 0");
  check_options(model, so);
  return sweep;
}

}  // namespace

int run_frame_sequence(const RenderOptions& options) {
  const RenderOptions opts = resolve_frames_resume(options);
  const ModelSpec model = parse_model(opts.model);
  refuse_single_frame_options(opts);
  SequenceOptions so = sequence_options(opts);
  RenderSettings settings =
      frame_settings(opts.res, opts.time, opts.shadows, opts.depth, opts.bank_mb);
  settings.cycle = opts.cycle;
  const std::vector<double> sweep = check_sequence(opts, model, settings, so);
  const bool in_dir = !opts.out_dir.empty();
  const std::string prefix =
      in_dir ? run_file(opts.out_dir, "frame_") : output_prefix(opts.out, {".png"}) + "_";
  std::vector<std::pair<std::string, std::string>> outputs;
  SequenceOutput out = sweep.empty() ? sequence_output(opts, model, settings, so, prefix, outputs)
                                     : bus_sweep_output(opts, model, settings, so, sweep);
  out.report["configuration"] =
      sequence_configuration_json(opts.time, settings, model.kind == ModelKind::kCycle);
  if (in_dir) {
    RunFolder f{opts.out_dir,
                std::move(out.report),
                {},
                std::move(out.host),
                std::move(out.stats),
                out.argv.empty() ? opts.argv : out.argv,
                {}};
    f.config = f.report["configuration"];
    if (!out.csv.empty()) {
      f.tables.push_back({"frames.csv", std::move(out.csv)});
      outputs.push_back({"csv", run_file(opts.out_dir, "frames.csv")});
    }
    write_run_folder(f);
    if (out.journal) out.journal->seal();
    for (const char* name : {"report.json", "config.json", "command.txt", "host.json"})
      outputs.push_back({name, run_file(opts.out_dir, name)});
  } else if (!opts.report.empty()) {
    write_text_file(opts.report, out.report.dump(2) + "\n");
    outputs.push_back({"report", opts.report});
  }
  std::printf("%s", out.printout.c_str());
  for (const auto& [k, v] : outputs)
    std::printf("  %-11s %s\n", (k + ":").c_str(), v.c_str());
  return 0;
}

}  // namespace saarcor
