// The host of the example virtual platform (docs/systemc.md): a TLM-2.0 initiator that does over
// the chip's socket what the host of `saarcor render SCENE --frames N` does over the modelled host
// bus (testbench/frame_sequence.h, docs/frames.md). It loads the scene and builds its memory image
// with two top-level copies, writes every data word of banks 2-5 and the frame registers, and for
// each frame writes START; while the frame renders it samples the animation, rebuilds the top
// level and posts the words that changed and the next frame's registers (into the copy the frame
// does not read; an upload that would touch what the frame reads waits for the frame's end, a
// frame gap), then waits for the chip's frame-end event and reads the frame back.
#pragma once

#include <tlm_utils/simple_initiator_socket.h>
#include <cstdint>
#include <string>
#include <systemc>
#include <tlm>
#include <vector>

#include "testbench/hit_buffer.h"
#include "testbench/render_cmd.h"

namespace saarcor::vp {

struct PlatformSpec {
  std::string scene = "builtin:dynamic";
  RenderSettings settings;  // --res, --shadows, --depth, --bank-mb, the cycle model's --set
  int frames = 2;
  double start = 0.0;  // the first frame's animation time
  double dt = -1.0;    // seconds between frames; < 0: the animation's length / frames
  // One top-level copy: every upload waits for the frame in flight to end (render --frame-gap).
  bool frame_gap = false;
};

// One frame as the host saw it over the socket.
struct HostFrame {
  int index = 0;
  double time = 0.0;  // animation seconds
  int frame_bank = 0;
  sc_core::sc_time start_written;  // when the host wrote START
  sc_core::sc_time end_seen;       // when the frame-end event reached the host
  // Read from the chip's registers after the frame's end.
  std::uint64_t cycles = 0, rays = 0, load_cycles = 0;
  std::uint64_t upload_bytes = 0;   // what the host sent for this frame (frame 0: the initial load)
  std::uint64_t upload_cycles = 0;  // that upload's cycles, as `render --frames` reports them
                                    // (frame 0: 0; its load_cycles are the initial load's)
  bool gap = false;                 // the upload waited for the previous frame's end
  Rgb8Image image;                  // read from the frame-buffer bank
};

class HostInitiator : public sc_core::sc_module {
 public:
  tlm_utils::simple_initiator_socket<HostInitiator> socket;

  // `frame_end`: the chip's frame-end event. Loads the scene and builds its image; throws
  // std::runtime_error (one line) for a bad scene or settings.
  HostInitiator(sc_core::sc_module_name name, PlatformSpec spec,
                const sc_core::sc_event& frame_end);

  const std::vector<HostFrame>& frames() const { return frames_; }
  // The error that stopped the host (a refused transaction, a bad scene), "" if none.
  const std::string& error() const { return error_; }

 private:
  void run();
  void sequence();
  void transfer(tlm::tlm_command command, std::uint64_t address, std::uint32_t* words,
                std::size_t count);
  void write(std::uint64_t address, const std::uint32_t* words, std::size_t count);
  std::uint32_t read_word(std::uint64_t address);
  std::uint64_t read_pair(std::uint32_t lo_index);
  std::uint64_t post(const std::vector<memif::UploadRun>& runs,
                     const memif::FrameRegisters& registers, const memif::SceneRegions& regions);
  void read_back(HostFrame& f, int width, int height);
  HostFrame load(PreparedScene& prep, memif::MemoryImage& board);
  HostFrame prepare(PreparedScene& prep, const memif::MemoryImage& board,
                    const std::vector<memif::BankRange>& reads, int index, double dt,
                    std::vector<memif::UploadRun>& runs);

  PlatformSpec spec_;
  PreparedScene prep_;
  const sc_core::sc_event& frame_end_;
  std::vector<HostFrame> frames_;
  std::string error_;
};

}  // namespace saarcor::vp
