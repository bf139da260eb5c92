// The RTL adapters' VCD waveform (saarcor-rtl lockstep: the window around a divergence, or a
// replay's): one file from start() to stop(), a dump at each clock edge.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include "verilated_vcd_c.h"

namespace saarcor::rtl {

class Waveform {
 public:
  // Traces `model` (a Verilated top built with --trace) into `path`; throws if it cannot write.
  template <class V>
  void start(V& model, const std::string& path) {
    stop();
    vcd_ = std::make_unique<VerilatedVcdC>();
    model.trace(vcd_.get(), 99);
    vcd_->open(path.c_str());
    if (!vcd_->isOpen()) throw std::runtime_error("cannot write the waveform " + path);
  }
  void stop() {
    if (!vcd_) return;
    vcd_->close();
    vcd_.reset();
  }
  // The signals at time `t` (two time units per cycle: 2c with the clock low, 2c + 1 high).
  void dump(std::uint64_t t) {
    if (vcd_) vcd_->dump(t);
  }

 private:
  std::unique_ptr<VerilatedVcdC> vcd_;
};

}  // namespace saarcor::rtl
