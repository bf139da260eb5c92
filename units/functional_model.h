// The functional fp24 model (docs/compare.md, model 2): the DynRTP's algorithms, untimed, in
// the hardware's float format with the datapath op orders of docs/cycle-model.md and 7. The RGC
// (paper section 3.1) hands screen-space packets of P pixels to one thread program
// (units/thread_program.h) that runs each to completion, packet after packet. The cycle model
// drives the same thread program with timing and must match this model bit for bit.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "fixedfloat/float.h"
#include "memif/image_format.h"
#include "units/thread_program.h"

namespace saarcor::units {

// Work and float ops of one frame, per unit (paper Table 2 names the units): the units' own
// counts as the thread program kept them, and the frame's packets and requests.
struct UnitStats : UnitCounts {
  ff::OpCounts traversal_ops, transformation_ops, intersection_ops, rgs_ops;
  std::uint64_t packets = 0;   // primary packets handed out by the RGC
  std::uint64_t requests = 0;  // thread-program requests served (all units)
};

// The frame's own counters, declared once (units/program_types.h CounterDecl).
inline constexpr CounterDecl<UnitStats> kFrameCounterDecls[] = {
    {"packets", "packets", "ray packets", &UnitStats::packets},
    {"requests", "requests", "thread-program requests served (all units)", &UnitStats::requests},
};

// The float units' op counters (paper Table 2's adders, multipliers, dividers, comparators), per
// unit; "total" is their sum (ff::OpCounts::total).
struct OpUnitDecl {
  const char* name;
  ff::OpCounts UnitStats::*member;
};
inline constexpr OpUnitDecl kOpUnitDecls[] = {
    {"traversal", &UnitStats::traversal_ops},
    {"transformation", &UnitStats::transformation_ops},
    {"intersection", &UnitStats::intersection_ops},
    {"rgs", &UnitStats::rgs_ops},
};
inline constexpr CounterDecl<ff::OpCounts> kOpCounterDecls[] = {
    {"add", "ops", "floating-point additions and subtractions", &ff::OpCounts::add},
    {"mul", "ops", "floating-point multiplications", &ff::OpCounts::mul},
    {"div", "ops", "floating-point divisions", &ff::OpCounts::div},
    {"sqrt", "ops", "floating-point square roots", &ff::OpCounts::sqrt},
    {"cmp", "ops", "floating-point comparisons", &ff::OpCounts::cmp},
};
inline constexpr const char* kOpTotalDesc = "floating-point operations, all kinds";

struct FunctionalFrame {
  ff::Format format = ff::kFp24;
  int width = 0;
  int height = 0;
  FunctionalParams params;
  // Per pixel (row-major, row 0 at the top): the primary ray's closest hit as encodings of
  // `format` (miss: t = +inf, instance = triangle = memif::kNone), its world ray, its counters;
  // zero bytes for a pixel whose packet the run did not trace (FrameSink).
  FrameSink::PixelBuffer pixels;
  std::vector<std::uint8_t> rgb;                 // 3 bytes per pixel (R, G, B), row 0 at the top
  std::array<RayCounters, kRayKinds> by_kind{};  // per ray kind, summed over rays
  std::array<std::uint64_t, kRayKinds> rays_issued{};
  std::array<std::uint64_t, kRayKinds> rays_returned{};
  UnitStats units;
  double seconds = 0.0;  // host time of the run

  const FrameSink::Pixel& at(int x, int y) const {
    return pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                  static_cast<std::size_t>(x)];
  }
};

// The RGC's packets (D38, row-major tiles): P pixels in a tile of tile_width x tile_height
// (2x2 for P = 4; 4x4 for 16; 2x1 for 2), lanes row-major inside the tile, tiles row-major over
// the image; lanes outside the image are memif::kNone.
struct PacketTiling {
  int tile_width = 1;
  int tile_height = 1;
  int tiles_x = 0;
  int tiles_y = 0;
  int count() const { return tiles_x * tiles_y; }
};
PacketTiling packet_tiling(int width, int height, int packet);
// Pixel indices (y*width + x) of packet `index`.
std::vector<std::uint32_t> packet_pixels(const PacketTiling& tiling, int width, int height,
                                         int index);

using ProgressFn = std::function<void(int packets_done, int packets_total)>;

// Renders the frame of `image` (FrameRegisters: resolution, camera, lights). F must be the image's
// format (throws std::runtime_error otherwise). Instantiated for Float<7, 10..23> and Float<8,23>.
// With `tap`, every unit transaction is also reported to it (units/unit_vectors.h). With `trace`,
// every request is written to it as a request-trace line (units/request_trace.h, docs/traces.md:
// the header, then packet after packet, no cycle, DynRTP or thread); `tap` must then be null.
template <class F>
FunctionalFrame run_functional(const memif::MemoryImage& image, const FunctionalParams& params,
                               const ProgressFn& progress = {}, UnitTap<F>* tap = nullptr,
                               std::ostream* trace = nullptr);
// The same, choosing F from image.format() (the formats above; others throw).
FunctionalFrame run_functional(const memif::MemoryImage& image, const FunctionalParams& params,
                               const ProgressFn& progress = {});
// Only the listed packets (indices of packet_tiling, in this order): a sampled frame's check
// (testbench/sampling.h). The other pixels keep the sink's reset records.
FunctionalFrame run_functional_packets(const memif::MemoryImage& image,
                                       const FunctionalParams& params,
                                       const std::vector<int>& packets);

// Replays the packet holding pixel (x, y) (`--pixel x,y`): that pixel's record, and one log line
// per thread-program request (unit, phase, item, mask) in execution order.
struct PixelTrace {
  FrameSink::Pixel pixel;
  std::array<std::uint8_t, 3> rgb{};
  std::vector<std::string> log;
};
PixelTrace trace_pixel(const memif::MemoryImage& image, const FunctionalParams& params, int x,
                       int y);

// Gathers a frame's results from the units' counters and the hit sink (moving the pixels out of
// the sink); the functional and the cycle model share it so both report alike.
template <class F>
void collect_frame(FunctionalFrame& frame, const PipelineUnits<F>& u, FrameSink& sink) {
  UnitStats& s = frame.units;
  static_cast<UnitCounts&>(s) = u;
  s.traversal_ops = u.traversal_ops;
  s.transformation_ops = u.transformation_ops;
  s.intersection_ops = u.intersection_ops;
  s.rgs_ops = u.rgs_ops;
  frame.by_kind = sink.by_kind;
  frame.rays_issued = sink.rays_issued;
  frame.rays_returned = sink.rays_returned;
  frame.rgb.resize(sink.pixels.size() * 3u);
  for (std::size_t i = 0; i < sink.pixels.size(); ++i)
    for (std::size_t k = 0; k < 3; ++k)
      frame.rgb[3u * i + k] = pixel_channel(sink.colour_sum[i][k]);
  frame.pixels = std::move(sink.pixels);
}

}  // namespace saarcor::units
