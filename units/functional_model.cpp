// The functional fp24 model (docs/compare.md, model 2) on the fast datapath: the frame loop
// (units/frame_loop.h) instantiated with FastDatapath for every built-in format, the RGC's packet
// tiling (paper section 3.1: screen-space packets), and the replay of one pixel's packet.
#include "units/functional_model.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ostream>
#include <stdexcept>
#include <utility>

#include "units/fast_datapath.h"
#include "units/frame_loop.h"

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

std::vector<std::uint32_t> packet_pixels(const PacketTiling& t, int width, int height, int index) {
  std::vector<std::uint32_t> px;
  fill_packet_pixels(t, width, height, index, px);
  return px;
}

namespace {

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

}  // namespace

template <class F>
FunctionalFrame run_functional(const memif::MemoryImage& image, const FunctionalParams& params,
                               const ProgressFn& progress, UnitTap<F>* tap, std::ostream* trace) {
  return run_frame<F, FastDatapath>(image, params, progress, tap, trace);
}

FunctionalFrame run_functional(const memif::MemoryImage& image, const FunctionalParams& params,
                               const ProgressFn& progress) {
  return with_format(image.format(),
                     [&](auto f) { return run_functional<decltype(f)>(image, params, progress); });
}

FunctionalFrame run_functional_packets(const memif::MemoryImage& image,
                                       const FunctionalParams& params,
                                       const std::vector<int>& packets) {
  return with_format(image.format(), [&](auto f) {
    return run_frame<decltype(f), FastDatapath>(image, params, {}, nullptr, nullptr, &packets);
  });
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
    ThreadProgram<F, kMaxPacket, FastDatapath> thread(image, params, units, sink);
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
