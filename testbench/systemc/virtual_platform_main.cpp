// saarcor-vp: the example virtual platform (docs/systemc.md). A host initiator and the chip's
// TLM-2.0 model on one socket, with the chip's interrupt line on a signal: the host uploads a
// scene and renders the frames of its animation as `saarcor render SCENE --model cycle --frames N`
// does, and the platform writes each frame's image and its figures and SystemC times.
//
//   saarcor-vp [SCENE] [--frames N] [--res WxH] [--time T] [--dt S] [--frame-gap] [--shadows]
//              [--depth N] [--preset P] [--set KEY=VALUE ...] [--out-dir DIR]
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <systemc>
#include <vector>

#include "testbench/image_io.h"
#include "testbench/systemc/chip_tlm.h"
#include "testbench/systemc/host_initiator.h"

namespace saarcor::vp {
namespace {

struct Options {
  PlatformSpec spec;
  std::string out_dir = "vp_out";
};

double number(const std::string& flag, const std::string& text) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !(v >= 0))
    throw std::runtime_error("bad " + flag + " '" + text + "': expected a number >= 0");
  return v;
}

Options parse(int argc, char** argv) {
  Options o;
  bool scene_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--frames") {
      const double n = number(a, value());
      if (n < 1 || n > 10000 || n != static_cast<int>(n))
        throw std::runtime_error("bad --frames: expected 1..10000");
      o.spec.frames = static_cast<int>(n);
    } else if (a == "--res") {
      o.spec.settings.res = parse_resolution(value());
    } else if (a == "--time") {
      o.spec.start = number(a, value());
    } else if (a == "--dt") {
      o.spec.dt = number(a, value());
    } else if (a == "--frame-gap") {
      o.spec.frame_gap = true;
    } else if (a == "--shadows") {
      o.spec.settings.shadows = true;
    } else if (a == "--depth") {
      o.spec.settings.depth = static_cast<int>(number(a, value()));
    } else if (a == "--preset") {
      o.spec.settings.cycle.preset = value();
    } else if (a == "--set") {
      o.spec.settings.cycle.set.push_back(value());
    } else if (a == "--out-dir") {
      o.out_dir = value();
    } else if (a.starts_with("-") || scene_given) {
      throw std::runtime_error(
          "unknown argument '" + a + "' (saarcor-vp [SCENE] [--frames N] " +
          "[--res WxH] [--time T] [--dt S] [--frame-gap] [--shadows] [--depth N] " +
          "[--preset P] " + "[--set K=V] " + "[--out-dir DIR])");
    } else {
      o.spec.scene = a;
      scene_given = true;
    }
  }
  return o;
}

// The chip's configuration as `saarcor render --model cycle` resolves it.
ChipConfig chip_config(const RenderSettings& s) {
  ChipConfig c;
  c.params = resolve_cycle_params(s.cycle);
  c.run.shading = functional_params(s);
  c.bank_words = static_cast<std::uint32_t>(std::llround(s.bank_mb * 262144.0));  // as the image
  return c;
}

std::uint64_t ps(const sc_core::sc_time& t) {
  return static_cast<std::uint64_t>(t.value());  // the time resolution is 1 ps (the default)
}

nlohmann::json frame_json(const HostFrame& h, const ChipFrame& c, const std::string& image) {
  return {{"frame", h.index},
          {"time", h.time},
          {"frame_bank", h.frame_bank},
          {"cycles", h.cycles},
          {"rays", h.rays},
          {"upload_bytes", h.upload_bytes},
          {"upload_cycles", h.upload_cycles},
          {"upload_in_gap", h.gap},
          {"load_cycles", h.load_cycles},
          {"start_written_ps", ps(h.start_written)},
          {"start_ps", ps(c.start)},
          {"end_ps", ps(c.end)},
          {"end_seen_ps", ps(h.end_seen)},
          {"image", image}};
}

void report(const Options& o, const HostInitiator& host, const ChipTlm& chip, double clock_mhz) {
  std::filesystem::create_directories(o.out_dir);
  nlohmann::json frames = nlohmann::json::array();
  for (std::size_t k = 0; k < host.frames().size(); ++k) {
    const HostFrame& h = host.frames()[k];
    const ChipFrame& c = chip.frames().at(k);
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.png", h.index);
    write_rgb8((std::filesystem::path(o.out_dir) / name).string(), h.image);
    frames.push_back(frame_json(h, c, name));
    std::printf(
        "frame %d: START at %s, began at %s, ended at %s: %llu cycles = %s at %g MHz "
        "(upload %llu B, %llu cycles)\n",
        h.index, h.start_written.to_string().c_str(), c.start.to_string().c_str(),
        c.end.to_string().c_str(), static_cast<unsigned long long>(h.cycles),
        chip.cycles_time(h.cycles).to_string().c_str(), clock_mhz,
        static_cast<unsigned long long>(h.upload_bytes),
        static_cast<unsigned long long>(h.upload_cycles));
  }
  const nlohmann::json j = {{"scene", o.spec.scene},
                            {"resolution", std::to_string(o.spec.settings.res.width) + "x" +
                                               std::to_string(o.spec.settings.res.height)},
                            {"clock_mhz", clock_mhz},
                            {"initial_load",
                             {{"bytes", host.frames().front().upload_bytes},
                              {"cycles", host.frames().front().load_cycles}}},
                            {"frames", frames}};
  std::ofstream((std::filesystem::path(o.out_dir) / "platform.json").string()) << j.dump(1) << "\n";
  std::printf("images and platform.json: %s\n", o.out_dir.c_str());
}

int run(int argc, char** argv) {
  const Options o = parse(argc, argv);
  const ChipConfig config = chip_config(o.spec.settings);
  ChipTlm chip("chip", config);
  HostInitiator host("host", o.spec, chip.frame_end_event());
  sc_core::sc_signal<bool> irq("irq");
  host.socket.bind(chip.socket);
  chip.irq.bind(irq);
  sc_core::sc_start();
  if (!host.error().empty()) throw std::runtime_error(host.error());
  if (static_cast<int>(host.frames().size()) != o.spec.frames)
    throw std::runtime_error("the platform stopped after " + std::to_string(host.frames().size()) +
                             " frames");
  report(o, host, chip, config.params.clock_mhz);
  return 0;
}

}  // namespace
}  // namespace saarcor::vp

int sc_main(int argc, char** argv) {
  try {
    return saarcor::vp::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "saarcor-vp: %s\n", e.what());
    return 1;
  }
}
