// A Verilated unit top as the lockstep's adapters hold it (rtl/unit_rtl.h): the model in a
// context of its own with tracing allowed, its waveform (rtl/waveform.h), the reset, and the
// clock's two edges with a waveform dump at each (two time units per cycle). The adapters differ
// only in their ports.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "rtl/waveform.h"
#include "verilated.h"

namespace saarcor::rtl {

template <class V>
class VerilatedTop {
 public:
  VerilatedTop() : ctx_(std::make_unique<VerilatedContext>()) {
    ctx_->traceEverOn(true);
    v_ = std::make_unique<V>(ctx_.get());
  }
  // The context goes with the model; Verilator's thread context (which the models built without
  // one of their own use) must not be left pointing at it.
  ~VerilatedTop() {
    wave_.stop();
    v_.reset();
    ctx_.reset();
    Verilated::threadContextp(Verilated::defaultContextp());
  }
  VerilatedTop(const VerilatedTop&) = delete;
  VerilatedTop& operator=(const VerilatedTop&) = delete;

  // Pointer-like, as the std::unique_ptr it wraps: the ports are read in const members too.
  V& operator*() const { return *v_; }
  V* operator->() const { return v_.get(); }

  // Two cycles with rst high; the next cycle is cycle 0.
  void reset() {
    v_->rst = 1;
    for (int i = 0; i < 2; ++i) {
      v_->clk = 0;
      v_->eval();
      v_->clk = 1;
      v_->eval();
    }
    v_->rst = 0;
    cycle_ = 0;
  }
  // The clock low with the cycle's inputs driven: its outputs settle (time 2c).
  void fall() {
    v_->clk = 0;
    v_->eval();
    wave_.dump(2 * cycle_);
  }
  // The rising edge: the registers take the cycle's values (time 2c + 1).
  void rise() {
    v_->clk = 1;
    v_->eval();
    wave_.dump(2 * cycle_ + 1);
    ++cycle_;
  }

  void start_trace(const std::string& path) { wave_.start(*v_, path); }
  void stop_trace() { wave_.stop(); }

 private:
  std::unique_ptr<VerilatedContext> ctx_;
  std::unique_ptr<V> v_;
  Waveform wave_;
  std::uint64_t cycle_ = 0;
};

}  // namespace saarcor::rtl
