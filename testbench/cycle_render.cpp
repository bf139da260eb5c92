// `saarcor render --model cycle`: options, report, Table 4 printout (docs/cycle-model.md).
#include "testbench/cycle_render.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "testbench/heartbeat.h"
#include "testbench/sampling.h"

namespace saarcor {

units::CycleParams resolve_cycle_params(const CycleRenderOptions& opts) {
  units::CycleParams p = units::cycle_preset(opts.preset);
  host::ImageParams trees;  // kd.* keys build the image; checked here so they fail early too
  for (const std::string& kv : opts.set) {
    if (host::is_tree_setting(kv))
      host::apply_tree_setting(trees, kv);
    else
      units::apply_cycle_setting(p, kv);
  }
  units::check_cycle_params(p);
  if (opts.host_threads < 0 || opts.host_threads > 2)
    throw std::runtime_error("bad --host-threads " + std::to_string(opts.host_threads) +
                             ": 1 (thread programs on the simulation's thread) or 2 (thread "
                             "programs ahead on a second thread)");
  if (opts.sample) {
    parse_sample_spec(opts.sample_spec);  // a bad SPEC fails before anything is built
    if (!opts.vcd.empty() || opts.interval != 0)
      throw std::runtime_error("--sample runs the frame's windows only: no --vcd or --interval");
  }
  if (!opts.vcd.empty() && opts.vcd_to < opts.vcd_from)
    throw std::runtime_error("bad --vcd-to " + std::to_string(opts.vcd_to) +
                             ": before --vcd-from " + std::to_string(opts.vcd_from));
  return p;
}

CycleFrame run_cycle_render(const memif::MemoryImage& image, const units::FunctionalParams& shading,
                            const CycleRenderOptions& opts, bool heartbeat,
                            const units::RunTraceOptions& trace) {
  const units::CycleParams p = resolve_cycle_params(opts);
  CycleRunOptions ro;
  ro.shading = shading;
  ro.trace = trace;
  ro.interval = opts.interval;
  if (opts.host_threads != 0)
    ro.programs =
        opts.host_threads == 2 ? units::ProgramMode::kAhead : units::ProgramMode::kPacketFirst;
  // The heartbeat outlives the run; the lambda only borrows it.
  Heartbeat beat("  cycle model", heartbeat && heartbeat_enabled());
  if (beat.enabled())
    ro.progress = [&beat](std::uint64_t cycles, int done, int total) {
      beat.beat(Heartbeat::cycle_status(cycles, done, total, beat.seconds()));
      if (done == total) beat.finish(Heartbeat::cycle_status(cycles, done, total, beat.seconds()));
    };
  std::ofstream vcd;
  if (!opts.vcd.empty()) {
    vcd.open(opts.vcd, std::ios::binary);
    if (!vcd) throw std::runtime_error("cannot write --vcd '" + opts.vcd + "'");
    ro.vcd = &vcd;
    ro.vcd_from = opts.vcd_from;
    ro.vcd_to = opts.vcd_to;
  }
  try {
    CycleFrame f = opts.sample ? run_sampled(image, p, ro, parse_sample_spec(opts.sample_spec))
                               : run_cycle(image, p, ro);
    if (opts.sample_check && f.sampling) check_sampled_packets(image, p, shading, f);
    if (!opts.vcd.empty()) {
      vcd.close();
      if (!vcd) throw std::runtime_error("cannot write --vcd '" + opts.vcd + "'");
    }
    return f;
  } catch (...) {
    if (!opts.vcd.empty()) {
      vcd.close();
      std::error_code ec;
      std::filesystem::remove(opts.vcd, ec);
    }
    throw;
  }
}

namespace {

double per(std::uint64_t a, std::uint64_t b) {
  return b == 0 ? 0.0 : static_cast<double>(a) / static_cast<double>(b);
}

// The RGS's traffic (the table's "shade" column is shading reads + frame-buffer writes, as the
// paper's shading bandwidth), with the paper's bytes per pixel beside it: its shading MB/s over
// its frame rate at 1024x768.
std::string rgs_text(const CycleFrame& c, const Table4Row* paper) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "RGS: shading reads %.0f MB/s, frame-buffer writes %.0f MB/s, %.1f bytes per pixel "
                "(frame in bank %d)",
                c.figures.bw_shading(), c.figures.bw_frame(), c.shading_bytes_per_pixel,
                c.frame_bank);
  std::string s = buf;
  if (paper != nullptr && paper->fps > 0) {
    const double paper_bpp = paper->bw[1] * 1048576.0 / (paper->fps * 1024.0 * 768.0);
    std::snprintf(buf, sizeof buf, "; paper %s %.0f MB/s, %.1f bytes per pixel (ratio %.2f)",
                  paper->scene, paper->bw[1], paper_bpp, c.shading_bytes_per_pixel / paper_bpp);
    s += buf;
  }
  return s + "\n";
}

}  // namespace

const std::vector<Table4Row>& paper_table4() {
  static const std::vector<Table4Row> rows = {
      {"Scene6", 15.3, {68, 16, 85, 41}, {99, 97, 99}, {8, 218, 226}},
      {"Castle", 5.9, {73, 18, 74, 48}, {99, 82, 94}, {50, 138, 188}},
      {"Office", 12.4, {76, 16, 72, 36}, {99, 71, 90}, {69, 246, 246}},
      {"Quake3", 8.5, {87, 15, 45, 21}, {99, 49, 79}, {104, 197, 301}},
      {"Quake3-p", 6.8, {92, 13, 35, 16}, {99, 66, 82}, {65, 157, 222}},
      {"UT2003", 6.5, {82, 19, 66, 42}, {98, 63, 86}, {105, 152, 257}},
      {"Conference", 5.7, {89, 25, 51, 28}, {98, 63, 78}, {135, 132, 267}},
      {"Terrain", 4.2, {80, 27, 34, 18}, {97, 27, 43}, {283, 98, 381}},
      {"SunCOR", 8.7, {46, 36, 29, 12}, {90, 2, 6}, {513, 202, 715}},
  };
  return rows;
}

const Table4Row* paper_row_for(const std::string& scene) {
  // The room is the built-in or its glTF export (scenes/room.glb), wherever it is given from.
  const bool room =
      scene == "builtin:room" || std::filesystem::path(scene).filename() == "room.glb";
  const std::string name = room                         ? "Scene6"
                           : scene == "builtin:suncor"  ? "SunCOR"
                           : scene == "builtin:terrain" ? "Terrain"
                                                        : "";
  for (const Table4Row& r : paper_table4())
    if (name == r.scene) return &r;
  return nullptr;
}

std::string table4_text(const CycleFrame& c, const std::string& scene) {
  std::string s;
  char buf[512];
  s += "Table 4 layout (paper: 1024x768, 90 MHz, 1 DynRTP, 64 threads; the paper's fps scaled to "
       "this frame's " +
       std::to_string(c.frame.width) + "x" + std::to_string(c.frame.height) + " pixels)\n";
  s +=
      "                       |        | usage %             | cache hit %    | bandwidth MB/s     "
      "| cycles/ | Mrays\n";
  s +=
      "scene                  |    fps | trav list xfrm  int | trav list xfrm | dynrtc shade total "
      "| packet  | /s\n";
  const auto& f = c.figures;
  std::snprintf(buf, sizeof buf,
                "%-22s | %6.1f | %4.0f %4.0f %4.0f %4.0f | %4.0f %4.0f %4.0f | %6.0f %5.0f %5.0f "
                "| %7.1f | %5.2f\n",
                ("model " + scene).substr(0, 22).c_str(), c.fps, f.usage(0), f.usage(1), f.usage(2),
                f.usage(3), f.cache_hit(0), f.cache_hit(1), f.cache_hit(2), f.bw_dynrtc(),
                f.bw_rgs(), f.bw_total(), per(c.cycles, c.packets), c.rays_per_s / 1e6);
  s += buf;
  if (const Table4Row* r = paper_row_for(scene)) {
    // The paper's cycles per packet and rays/s follow from its fps at 1024x768 and 4-ray packets.
    // Its frame rate at this frame's pixel count, so the fps column compares like with like.
    const double rays = r->fps * 1024.0 * 768.0;
    const double pixels = static_cast<double>(c.frame.width) * c.frame.height;
    const double fps = pixels > 0.0 ? rays / pixels : r->fps;
    std::snprintf(buf, sizeof buf,
                  "%-22s | %6.1f | %4.0f %4.0f %4.0f %4.0f | %4.0f %4.0f %4.0f | %6.0f %5.0f %5.0f "
                  "| %7.1f | %5.2f\n",
                  (std::string("paper ") + r->scene).c_str(), fps, r->usage[0], r->usage[1],
                  r->usage[2], r->usage[3], r->hit[0], r->hit[1], r->hit[2], r->bw[0], r->bw[1],
                  r->bw[2], 90e6 / (rays / 4.0), rays / 1e6);
    s += buf;
  }
  s += rgs_text(c, paper_row_for(scene));
  s += sampling_text(c);
  const units::UnitStats& u = c.frame.units;
  std::snprintf(buf, sizeof buf,
                "per ray: %.2f traversal steps, %.2f list entries, %.2f mailbox skips, %.2f "
                "intersections; SIMD efficiency %.2f; traversal/intersection ops %.2f\n",
                per(c.per_ray_sum.traversal_steps, c.rays), per(c.per_ray_sum.list_entries, c.rays),
                per(c.per_ray_sum.mailbox_skips, c.rays), per(c.per_ray_sum.intersections, c.rays),
                c.simd_efficiency, per(u.traversal_ops.total(), u.intersection_ops.total()));
  s += buf;
  if (c.per_pipeline.size() > 1) {
    s += std::to_string(c.per_pipeline.size()) +
         " DynRTPs (usage: the mean over them; the paper's row is one DynRTP), packets each:";
    for (const CycleFrame::PipelineCount& pc : c.per_pipeline)
      s += " " + std::to_string(pc.packets);
    s += "\n";
  }
  return s;
}

}  // namespace saarcor
