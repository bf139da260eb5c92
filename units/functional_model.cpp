// The functional fp24 model's frame loop (docs/compare.md, model 2; paper section 3.1: the RGC
// schedules screen-space packets): one thread program, one packet after another, to completion.
#include "units/functional_model.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ostream>
#include <stdexcept>
#include <utility>

#include "units/request_trace.h"

namespace saarcor::units {

PacketTiling packet_tiling(int width, int height, int packet) {
  if (packet < 1 || packet > kMaxPacket || (packet & (packet - 1)) != 0)
    throw std::runtime_error("functional model: packet width " + std::to_string(packet) +
                             " is not a power of two in 1..64");
  if (width < 1 || height < 1)
    throw std::runtime_error("functional model: resolution " + std::to_string(width) + "x" +
                             std::to_string(height) + " is empty");
  int log2p = 0;
  while ((1 << log2p) < packet)
    ++log2p;
  PacketTiling t;
  t.tile_width = 1 << ((log2p + 1) / 2);
  t.tile_height = packet / t.tile_width;
  t.tiles_x = (width + t.tile_width - 1) / t.tile_width;
  t.tiles_y = (height + t.tile_height - 1) / t.tile_height;
  return t;
}

namespace {

void fill_packet_pixels(const PacketTiling& t, int width, int height, int index,
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

}  // namespace

std::vector<std::uint32_t> packet_pixels(const PacketTiling& t, int width, int height, int index) {
  std::vector<std::uint32_t> px;
  fill_packet_pixels(t, width, height, index, px);
  return px;
}

namespace {

void check_image(const memif::MemoryImage& image) {
  const auto& r = image.registers();
  if (r.width < 1 || r.height < 1 || r.width > 16384 || r.height > 16384)
    throw std::runtime_error("functional model: frame registers give a resolution of " +
                             std::to_string(r.width) + "x" + std::to_string(r.height) +
                             " (1..16384 per side)");
}

// Calls fn(Float<E,M>{}) for the image's format.
template <class Fn>
decltype(auto) with_format(const ff::Format& f, Fn&& fn) {
  if (f.exp_bits == 8 && f.man_bits == 23) return fn(ff::Float<8, 23>{});
  if (f.exp_bits == 7) {
    switch (f.man_bits) {
      case 10:
        return fn(ff::Float<7, 10>{});
      case 11:
        return fn(ff::Float<7, 11>{});
      case 12:
        return fn(ff::Float<7, 12>{});
      case 13:
        return fn(ff::Float<7, 13>{});
      case 14:
        return fn(ff::Float<7, 14>{});
      case 15:
        return fn(ff::Float<7, 15>{});
      case 16:
        return fn(ff::Float<7, 16>{});
      case 17:
        return fn(ff::Float<7, 17>{});
      case 18:
        return fn(ff::Float<7, 18>{});
      case 19:
        return fn(ff::Float<7, 19>{});
      case 20:
        return fn(ff::Float<7, 20>{});
      case 21:
        return fn(ff::Float<7, 21>{});
      case 22:
        return fn(ff::Float<7, 22>{});
      case 23:
        return fn(ff::Float<7, 23>{});
      default:
        break;
    }
  }
  throw std::runtime_error("functional model: float format " + ff::format_name(f) +
                           " is not built in (e7m10..e7m23, e8m23)");
}

// ThreadProgram::run() with a request-trace line per request (the same requests in the same
// order). Returns the number of requests served.
template <class F>
std::uint64_t run_traced(ThreadProgram<F>& thread, PipelineUnits<F>& units, TraceTap<F>& tap,
                         int packet, std::ostream& out) {
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

}  // namespace

template <class F>
FunctionalFrame run_functional(const memif::MemoryImage& image, const FunctionalParams& params,
                               const ProgressFn& progress, UnitTap<F>* tap, std::ostream* trace) {
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
  sink.reset(w, h);
  ThreadProgram<F> thread(image, params, units, sink);
  FunctionalFrame frame;
  frame.format = F::kFormat;
  frame.width = w;
  frame.height = h;
  frame.params = params;
  const int total = tiling.count();
  std::vector<std::uint32_t> pixels;  // reused: no allocation per packet
  TraceTap<F> trace_tap;
  if (trace != nullptr) *trace << kTraceHeader << '\n';
  for (int p = 0; p < total; ++p) {
    fill_packet_pixels(tiling, w, h, p, pixels);
    thread.start_primary(pixels);
    frame.units.requests +=
        trace != nullptr ? run_traced(thread, units, trace_tap, p, *trace) : thread.run();
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

FunctionalFrame run_functional(const memif::MemoryImage& image, const FunctionalParams& params,
                               const ProgressFn& progress) {
  return with_format(image.format(),
                     [&](auto f) { return run_functional<decltype(f)>(image, params, progress); });
}

PixelTrace trace_pixel(const memif::MemoryImage& image, const FunctionalParams& params, int x,
                       int y) {
  check_image(image);
  const int w = static_cast<int>(image.registers().width);
  const int h = static_cast<int>(image.registers().height);
  if (x < 0 || y < 0 || x >= w || y >= h)
    throw std::runtime_error("functional model: pixel " + std::to_string(x) + "," +
                             std::to_string(y) + " lies outside the " + std::to_string(w) + "x" +
                             std::to_string(h) + " frame");
  return with_format(image.format(), [&](auto f) {
    using F = decltype(f);
    const PacketTiling tiling = packet_tiling(w, h, params.packet);
    const int index = (y / tiling.tile_height) * tiling.tiles_x + x / tiling.tile_width;
    PipelineUnits<F> units(params.mode);
    FrameSink sink;
    sink.reset(w, h);
    ThreadProgram<F> thread(image, params, units, sink);
    thread.start_primary(packet_pixels(tiling, w, h, index));
    PixelTrace trace;
    while (!thread.done()) {
      const Request r = thread.request();
      char line[160];
      std::snprintf(line, sizeof line, "%-14s %-18s item=%-10u steps=%-3d mask=%llx %s",
                    unit_name(r.unit), phase_name(r.phase), r.item, r.steps,
                    static_cast<unsigned long long>(r.mask), ray_kind_name(thread.kind()));
      trace.log.emplace_back(line);
      thread.execute();
    }
    const std::size_t i =
        static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
    trace.pixel = sink.pixels[i];
    for (std::size_t k = 0; k < 3; ++k)
      trace.rgb[k] = pixel_channel(sink.colour_sum[i][k]);
    return trace;
  });
}

#define SAARCOR_INSTANTIATE(E, M)                                            \
  template FunctionalFrame run_functional<ff::Float<E, M>>(                  \
      const memif::MemoryImage&, const FunctionalParams&, const ProgressFn&, \
      UnitTap<ff::Float<E, M>>*, std::ostream*);
SAARCOR_INSTANTIATE(7, 10)
SAARCOR_INSTANTIATE(7, 11)
SAARCOR_INSTANTIATE(7, 12)
SAARCOR_INSTANTIATE(7, 13)
SAARCOR_INSTANTIATE(7, 14)
SAARCOR_INSTANTIATE(7, 15)
SAARCOR_INSTANTIATE(7, 16)
SAARCOR_INSTANTIATE(7, 17)
SAARCOR_INSTANTIATE(7, 18)
SAARCOR_INSTANTIATE(7, 19)
SAARCOR_INSTANTIATE(7, 20)
SAARCOR_INSTANTIATE(7, 21)
SAARCOR_INSTANTIATE(7, 22)
SAARCOR_INSTANTIATE(7, 23)
SAARCOR_INSTANTIATE(8, 23)
#undef SAARCOR_INSTANTIATE

}  // namespace saarcor::units
