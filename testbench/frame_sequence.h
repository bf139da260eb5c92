// `saarcor render SCENE --frames N`: a dynamic scene frame after frame (paper section 2: objects
// move under affine transforms, only the top-level index is rebuilt; section 5: the host uploads
// the changes "in parallel to rendering", so its influence is "completely negligible"). For each
// frame the host samples the animation, rebuilds the top-level tree (bottom-level trees are reused
// and their rebuilds counted), computes the words of the memory image that changed and uploads
// them over the modelled host bus while the previous frame renders, into the top-level copy that
// frame does not read (two copies; a write into what a frame in flight reads is refused by the
// bus); what cannot go there (a relayout, a moved light) waits for the frame to end (a frame gap).
// The frame buffers swap every frame. Each frame is checked bit for bit against the functional
// model. docs/frames.md has the timeline, the rules and the report.
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "testbench/image_io.h"
#include "testbench/render_cmd.h"
#include "testbench/report.h"
#include "units/figures.h"

namespace saarcor {

struct SequenceOptions {
  int frames = 1;
  double start = 0.0;  // the first frame's animation time (--time)
  double dt = -1.0;    // seconds between frames; < 0: the animation's length / frames (0 if static)
  // One top-level copy: every upload waits for the frame in flight to end (the alternative to
  // double buffering, for comparison: --frame-gap).
  bool frame_gap = false;
  // The cycle model: render each frame with the functional model too and require the same hit
  // records, image and rays (the bus sweep checks its first point so and the others by digest).
  bool check = true;
};

// One frame. The upload of a row is the one that brought this frame's changes, sent while the
// previous frame rendered (frame 0's is the initial load, reported apart).
struct SequenceFrame {
  int index = 0;
  double time = 0.0;   // animation seconds
  int frame_bank = 0;  // the frame-buffer bank the frame is written to (memif kFrameBank0/1)
  int top_copy = 0;    // the top-level copy the registers name
  bool top_rebuilt = false;
  std::uint32_t moved_instances = 0;      // since the previous frame (encoded matrices)
  std::uint64_t top_level_builds = 0;     // trees built for this frame: 0 or 1
  std::uint64_t bottom_level_builds = 0;  // always 0: the objects' trees are reused
  std::uint64_t upload_bytes = 0;         // SRAM words that changed, plus the registers
  std::uint64_t upload_words = 0;         // of them, SRAM words
  std::uint64_t upload_runs = 0;          // runs of consecutive words
  bool gap = false;                       // the upload waited for the previous frame to end
  // Cycle model: the upload's cycles from the previous frame's start until its last word was
  // stored; hidden when that is within the previous frame's render; stall = how long this frame
  // started after the previous frame's render ended.
  std::uint64_t upload_cycles = 0;
  bool hidden = false;
  std::uint64_t stall_cycles = 0;
  std::uint64_t start_cycle = 0;  // on the sequence's clock (frame 0 starts at 0)
  std::uint64_t cycles = 0;       // rendering
  double fps = 0.0;               // rendering alone, at the modelled clock
  std::uint64_t rays = 0;
  units::CycleFigures figures;  // the frame's Table 4 figures (units/figures.h)
  double shading_bytes_per_pixel = 0.0;
  double cycles_per_packet = 0.0;
  std::uint64_t digest = 0;  // FNV-1a of the hit records and the image
  bool checked = false;      // compared with the functional model (equal, or the run throws)
  double host_rebuild_seconds = 0.0;  // host wall clock of the top-level rebuild (host.json only)
  double host_seconds = 0.0;          // host wall clock of the frame's models (host.json only)
};

struct SequenceResult {
  std::string scene;
  std::string model;
  int width = 0, height = 0;
  double dt = 0.0;
  double clock_mhz = 0.0;  // cycle model
  double bus_mb_s = 0.0;   // cycle model: hostbus.mb_s
  bool cycle = false;
  bool frame_gap = false;
  std::uint64_t instances = 0, dynamic_instances = 0, objects = 0;
  std::uint64_t initial_load_bytes = 0;   // every data word of banks 2-5 and the registers
  std::uint64_t initial_load_cycles = 0;  // cycle model: over the bus, nothing rendering
  // Scene-bank bytes of one top-level copy (its node and list slots and the instance records):
  // what double buffering costs (the second copy).
  std::uint64_t top_copy_bytes = 0;
  std::vector<SequenceFrame> frames;
  // The whole sequence on its clock: from frame 0's start to the last frame's end.
  std::uint64_t total_cycles() const;
  double fps() const;          // frames / total time
  double render_fps() const;   // frames / the sum of render times (uploads free)
  int hidden_uploads() const;  // of frames 1..N-1
  int gaps() const;            // of frames 1..N-1: uploads that waited for the frame's end
  // The lowest bus bandwidth (MB/s) at which each frame's upload would fit behind the previous
  // frame's render (upload bytes / that render's time; no bank contention): the largest over the
  // frames whose upload is not in a gap. 0 with one frame.
  double break_even_mb_s() const;
};

// Called once per frame, in order, with its row and its image.
using FrameSink = std::function<void(const SequenceFrame&, const Rgb8Image&)>;

// A finished frame as a run folder's journal keeps it (testbench/run_journal.h): its row without
// host seconds, and what its render measured of the next frame's upload (the bus cycles it took
// beside this frame; with a frame gap, the cycles it took alone after it).
struct FrameRecord {
  SequenceFrame row;
  std::uint64_t next_upload_cycles = 0;
  std::uint64_t gap_cycles = 0;
};
// One line (every double as its bits: exact) and back; throws one line on a damaged record.
std::string frame_record_text(const FrameRecord& r);
FrameRecord parse_frame_record(const std::string& text);

// A sequence that goes on from frames a stopped run finished, and tells of each frame it finishes.
struct SequenceResume {
  // Frames 0..K-1 of a stopped run: not rendered again; the host replays their rebuilds and
  // uploads, so frame K starts from the state it had, and their rows are taken as they were.
  std::vector<FrameRecord> finished;
  // Called with each frame rendered now, after the sink has its image.
  std::function<void(const FrameRecord&)> on_frame;
};

// Runs the sequence: loads `scene`, builds its image at opts.start with two top-level copies (one
// with frame_gap), then frame after frame as above. `model` is the cycle model or a functional
// model (no timing: upload bytes, rebuilds and images only). Throws std::runtime_error with one
// line on bad input, on a frame whose results differ from the functional model's, and on an upload
// the host bus refuses.
// After SIGINT or SIGTERM (testbench/run_journal.h stop_signal) no frame starts: the result holds
// the frames that finished.
SequenceResult run_sequence(const std::string& scene, const ModelSpec& model,
                            const RenderSettings& settings, const SequenceOptions& opts,
                            const FrameSink& sink = {}, const SequenceResume& resume = {});

// --bus-sweep: the sequence once per host-bus bandwidth (MB/s); every point's frames must have
// the first point's digests. Returns one result per bandwidth (printed by testbench/report.h's
// bus_sweep_table).
std::vector<SequenceResult> run_bus_sweep(const std::string& scene, const ModelSpec& model,
                                          const RenderSettings& settings,
                                          const SequenceOptions& opts,
                                          const std::vector<double>& mb_s);

// "1,4,16.5" as bandwidths in (0, 10^6] MB/s; throws "bad --bus-sweep ..." otherwise.
std::vector<double> parse_bus_sweep(const std::string& text);

// `saarcor render ... --frames N`: checks the options, runs the sequence (or the bus sweep),
// writes the numbered images and the report. Returns 0; throws one line on bad input.
int run_frame_sequence(const RenderOptions& opts);

}  // namespace saarcor
