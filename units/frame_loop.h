// The functional model's frame loop (docs/compare.md, model 2; paper section 3.1: the RGC
// schedules screen-space packets): one thread program, one packet after another, to completion,
// for a datapath policy D chosen at compile time. It names no policy: units/functional_model.cpp
// instantiates it with FastDatapath (run_functional), units/reference_model.cpp with
// ReferenceDatapath (run_reference).
#pragma once

#include <chrono>
#include <cstdint>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "units/functional_model.h"
#include "units/request_trace.h"

namespace saarcor::units {

// Pixel indices (y*width + x) of packet `index` into px (reused: no allocation per packet).
inline void fill_packet_pixels(const PacketTiling& t, int width, int height, int index,
                               std::vector<std::uint32_t>& px) {
  px.assign(static_cast<std::size_t>(t.tile_width * t.tile_height), memif::kNone);
  const int x0 = (index % t.tiles_x) * t.tile_width;
  const int y0 = (index / t.tiles_x) * t.tile_height;
  for (int j = 0; j < t.tile_height; ++j)
    for (int i = 0; i < t.tile_width; ++i) {
      const int x = x0 + i, y = y0 + j;
      if (x < width && y < height)
        px[static_cast<std::size_t>(j * t.tile_width + i)] =
            static_cast<std::uint32_t>(y * width + x);
    }
}

inline void check_image(const memif::MemoryImage& image) {
  const auto& r = image.registers();
  if (r.width < 1 || r.height < 1 || r.width > 16384 || r.height > 16384)
    throw std::runtime_error("functional model: frame registers give a resolution of " +
                             std::to_string(r.width) + "x" + std::to_string(r.height) +
                             " (1..16384 per side)");
}

// ThreadProgram::run() with a request-trace line per request (the same requests in the same
// order). Returns the number of requests served.
template <class F, class D>
std::uint64_t run_traced(ThreadProgram<F, kMaxPacket, D>& thread, PipelineUnits<F>& units,
                         TraceTap<F>& tap, int packet, std::ostream& out) {
  TraceLine line;
  line.packet = packet;
  units.tap = &tap;
  std::uint32_t n = 0;
  while (!thread.done()) {
    const Request r = thread.request();
    line.seq = n++;
    line.unit = r.unit;
    line.phase = r.phase;
    line.item = r.item;
    line.steps = r.steps;
    line.mask = r.mask;
    line.kind = thread.kind();
    tap.begin();
    thread.execute();
    line.txn = tap.take();
    out << format_trace_line(line) << '\n';
  }
  units.tap = nullptr;
  return n;
}

// run_functional's frame with datapath D (see there). `packets`: only these packets, in this
// order (a sampled frame's, testbench/sampling.h); null: every packet in tiling order.
template <class F, class D>
FunctionalFrame run_frame(const memif::MemoryImage& image, const FunctionalParams& params,
                          const ProgressFn& progress, UnitTap<F>* tap, std::ostream* trace,
                          const std::vector<int>* packets = nullptr) {
  if (tap != nullptr && trace != nullptr)
    throw std::logic_error("functional model: a tap and a trace at once");
  const auto t0 = std::chrono::steady_clock::now();
  check_image(image);
  const int w = static_cast<int>(image.registers().width);
  const int h = static_cast<int>(image.registers().height);
  const PacketTiling tiling = packet_tiling(w, h, params.packet);
  PipelineUnits<F> units(params.mode);
  units.tap = tap;
  FrameSink sink;
  sink.reset(w, h, packets == nullptr);
  ThreadProgram<F, kMaxPacket, D> thread(image, params, units, sink);
  FunctionalFrame frame;
  frame.format = F::kFormat;
  frame.width = w;
  frame.height = h;
  frame.params = params;
  const int total = packets != nullptr ? static_cast<int>(packets->size()) : tiling.count();
  std::vector<std::uint32_t> pixels;  // reused: no allocation per packet
  TraceTap<F> trace_tap;
  if (trace != nullptr) *trace << kTraceHeader << '\n';
  for (int p = 0; p < total; ++p) {
    const int index = packets != nullptr ? (*packets)[static_cast<std::size_t>(p)] : p;
    if (index < 0 || index >= tiling.count())
      throw std::runtime_error("functional model: packet " + std::to_string(index) + " of " +
                               std::to_string(tiling.count()));
    fill_packet_pixels(tiling, w, h, index, pixels);
    thread.start_primary(pixels);
    frame.units.requests +=
        trace != nullptr ? run_traced(thread, units, trace_tap, index, *trace) : thread.run();
    if (progress && ((p + 1) % 1024 == 0 || p + 1 == total)) progress(p + 1, total);
  }
  frame.units.packets = static_cast<std::uint64_t>(total);
  const std::uint64_t requests = frame.units.requests;
  collect_frame(frame, units, sink);
  frame.units.requests = requests;
  frame.units.packets = static_cast<std::uint64_t>(total);
  frame.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return frame;
}

}  // namespace saarcor::units
