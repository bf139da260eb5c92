// Small designs shared by the hw/ tests (docs/hw.md): a pipeline of stages that share
// state only through registers and channels, and a bursty design with long idle gaps, internal
// timers and back-pressure stalls (what idle skipping must handle). With `sleep`, every module
// that may (all but the doubler, which reads another module's register) opts into event
// scheduling (Module::sleep_when_idle) and declares its channels. Test-only header.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "hw/kernel.h"

namespace saarcor::hw::testing {

// ---- design A: source -> doubler -> splitter -> {c, d} -> joiner(+pipeline) -> sink ----------

class Source : public Module {
 public:
  Source(Kernel& k, Channel<std::uint32_t>& out, std::uint32_t items, bool sleep = false)
      : Module(k, "a.source"), out_(out), items_(items) {
    if (sleep) {
      sleep_when_idle();
      produces(out);
    }
  }
  int evaluate() override {
    const std::uint32_t n = count_.get();
    if (n == items_) return 0;
    if ((n * 7u + static_cast<std::uint32_t>(now())) % 5u == 0) {  // deterministic bubbles
      stall();
      return 0;
    }
    if (!out_.can_push()) {
      stall();
      return 0;
    }
    out_.push(n * 3u + 1u);
    count_.set(n + 1);
    return 1;
  }
  void commit() override { count_.commit(); }
  std::uint64_t next_wakeup(std::uint64_t now) const override {
    return count_.get() == items_ ? kNever : now + 1;
  }
  const Reg<std::uint32_t>& count() const { return count_; }

 private:
  Channel<std::uint32_t>& out_;
  std::uint32_t items_;
  Reg<std::uint32_t> count_{0};
};

// Reads the source's committed counter (a registered output of another module).
class Doubler : public Module {
 public:
  Doubler(Kernel& k, Channel<std::uint32_t>& in, Channel<std::uint32_t>& out, const Source& src)
      : Module(k, "a.doubler"), in_(in), out_(out), src_(src) {}
  int evaluate() override {
    if (!in_.can_pop()) return 0;
    if (!out_.can_push()) {
      stall();
      return 0;
    }
    out_.push(in_.pop() * 2u + src_.count().get());
    return 1;
  }
  std::uint64_t next_wakeup(std::uint64_t) const override { return kNever; }

 private:
  Channel<std::uint32_t>&in_, &out_;
  const Source& src_;
};

class Splitter : public Module {
 public:
  Splitter(Kernel& k, Channel<std::uint32_t>& in, Channel<std::uint32_t>& c,
           Channel<std::uint32_t>& d, bool sleep = false)
      : Module(k, "a.splitter"), in_(in), c_(c), d_(d) {
    if (sleep) {
      sleep_when_idle();
      consumes(in);
      produces(c);
      produces(d);
    }
  }
  int evaluate() override {
    if (!in_.can_pop()) return 0;
    Channel<std::uint32_t>& out = toggle_.get() ? d_ : c_;
    if (!out.can_push()) {
      stall();
      return 0;
    }
    out.push(in_.pop());
    toggle_.set(!toggle_.get());
    return 1;
  }
  void commit() override { toggle_.commit(); }
  std::uint64_t next_wakeup(std::uint64_t) const override { return kNever; }

 private:
  Channel<std::uint32_t>&in_, &c_, &d_;
  Reg<bool> toggle_{false};
};

class Joiner : public Module {
 public:
  Joiner(Kernel& k, Channel<std::uint32_t>& c, Channel<std::uint32_t>& d,
         Channel<std::uint32_t>& out, bool sleep = false)
      : Module(k, "a.joiner"), c_(c), d_(d), out_(out), pipe_(k, "a.joiner.pipe", 5) {
    if (sleep) {  // the internal pipeline too: its results becoming visible wake the joiner
      sleep_when_idle();
      consumes(c);
      consumes(d);
      produces(out);
      consumes(pipe_);
      produces(pipe_);
    }
  }
  int evaluate() override {
    int p = 0;
    // Retire from the internal pipeline into the output.
    if (pipe_.can_pop()) {
      if (out_.can_push()) {
        out_.push(pipe_.pop());
        ++p;
      } else {
        stall();
      }
    }
    // Issue: prefer c, then d.
    Channel<std::uint32_t>* in = c_.can_pop() ? &c_ : d_.can_pop() ? &d_ : nullptr;
    if (in != nullptr && pipe_.can_push()) {
      pipe_.push(in->pop() ^ 0x5A5Au);
      ++p;
    }
    return p;
  }
  std::uint64_t next_wakeup(std::uint64_t) const override { return kNever; }

 private:
  Channel<std::uint32_t>&c_, &d_, &out_;
  Pipeline<std::uint32_t> pipe_;
};

class Sink : public Module {
 public:
  Sink(Kernel& k, Channel<std::uint32_t>& in, bool sleep = false) : Module(k, "a.sink"), in_(in) {
    if (sleep) {
      sleep_when_idle();
      consumes(in);
    }
  }
  int evaluate() override {
    // Slow consumer: every third cycle only, so back-pressure reaches the source.
    if (now() % 3 != 0 || !in_.can_pop()) return 0;
    log.emplace_back(now(), in_.pop());
    return 1;
  }
  std::uint64_t next_wakeup(std::uint64_t now) const override {
    return in_.empty() ? kNever : (now / 3 + 1) * 3;
  }
  std::vector<std::pair<std::uint64_t, std::uint32_t>> log;

 private:
  Channel<std::uint32_t>& in_;
};

struct DesignA {
  explicit DesignA(Kernel& k, std::uint32_t items = 200, bool sleep = false)
      : a(k, "a.ch_a", 3, 2),
        b(k, "a.ch_b", 2, 1),
        c(k, "a.ch_c", 2, 1),
        d(k, "a.ch_d", 5, 4),
        e(k, "a.ch_e", 4, 3),
        sink(k, e, sleep),
        joiner(k, c, d, e, sleep),
        source(k, a, items, sleep),
        splitter(k, b, c, d, sleep),
        doubler(k, a, b, source),
        items_(items) {}
  bool done() const { return sink.log.size() == items_; }
  Channel<std::uint32_t> a, b, c, d, e;
  Sink sink;
  Joiner joiner;
  Source source;
  Splitter splitter;
  Doubler doubler;
  std::uint32_t items_;
};

// ---- design B: bursts, long latencies, a memory with an internal timer, a slow consumer ------

class BurstSource : public Module {
 public:
  BurstSource(Kernel& k, Channel<std::uint32_t>& out, int bursts, bool sleep = false)
      : Module(k, "b.source"), out_(out), bursts_(bursts) {
    if (sleep) {
      sleep_when_idle();
      produces(out);
    }
  }
  int evaluate() override {
    if (burst_.get() == bursts_) return 0;
    const std::uint64_t start = static_cast<std::uint64_t>(burst_.get()) * 700u + 10u;
    if (now() < start) return 0;
    if (!out_.can_push()) {
      stall();
      return 0;
    }
    out_.push(static_cast<std::uint32_t>(burst_.get() * 100 + in_burst_.get()));
    if (in_burst_.get() + 1 == 6) {
      in_burst_.set(0);
      burst_.set(burst_.get() + 1);
    } else {
      in_burst_.set(in_burst_.get() + 1);
    }
    return 1;
  }
  void commit() override {
    burst_.commit();
    in_burst_.commit();
  }
  std::uint64_t next_wakeup(std::uint64_t now) const override {
    if (burst_.get() == bursts_) return kNever;
    const std::uint64_t start = static_cast<std::uint64_t>(burst_.get()) * 700u + 10u;
    return start > now ? start : now + 1;
  }
  std::string dump_state() const override {
    return "burst " + std::to_string(burst_.get()) + " item " + std::to_string(in_burst_.get());
  }
  bool finished() const { return burst_.get() == bursts_; }

 private:
  Channel<std::uint32_t>& out_;
  int bursts_;
  Reg<int> burst_{0}, in_burst_{0};
};

// Accepts one request at a time and answers 37 cycles later (an internal timer, not a channel).
class SlowMemory : public Module {
 public:
  SlowMemory(Kernel& k, Channel<std::uint32_t>& in, Channel<std::uint32_t>& out, bool sleep = false)
      : Module(k, "b.memory"), in_(in), out_(out) {
    if (sleep) {
      sleep_when_idle();
      consumes(in);
      produces(out);
    }
    waiting_ = &stats().counter("b.memory.wait_cycles", "cycles",
                                "cycles with a request in service (counted per cycle)");
  }
  int evaluate() override {
    const Busy b = busy_.get();
    if (b.active) {
      ++*waiting_;  // a per-cycle count: must be repeated in skipped()
      if (now() < b.due) return 0;
      if (!out_.can_push()) {
        stall();
        return 0;
      }
      out_.push(b.value + 1000u);
      busy_.set({});
      return 1;
    }
    if (!in_.can_pop()) return 0;
    busy_.set({true, now() + 37, in_.pop()});
    return 1;
  }
  void commit() override { busy_.commit(); }
  std::uint64_t next_wakeup(std::uint64_t now) const override {
    const Busy b = busy_.get();
    return b.active && b.due > now ? b.due : kNever;
  }
  void skipped(std::uint64_t cycles) override {
    if (busy_.get().active) *waiting_ += cycles;
  }

 private:
  struct Busy {
    bool active = false;
    std::uint64_t due = 0;
    std::uint32_t value = 0;
  };
  Channel<std::uint32_t>&in_, &out_;
  Reg<Busy> busy_{};
  Counter* waiting_;
};

class TimedSink : public Module {
 public:
  TimedSink(Kernel& k, Channel<std::uint32_t>& in, bool sleep = false)
      : Module(k, "b.sink"), in_(in) {
    if (sleep) {
      sleep_when_idle();
      consumes(in);
    }
    latency_ = &stats().histogram("b.sink.gap", "cycles", "cycles between arrivals", 0, 50, 20);
  }
  int evaluate() override {
    if (!in_.can_pop()) return 0;
    const std::uint32_t v = in_.pop();
    latency_->sample(static_cast<double>(now() - last_.get()));
    last_.set(now());
    log.emplace_back(now(), v);
    return 1;
  }
  void commit() override { last_.commit(); }
  std::uint64_t next_wakeup(std::uint64_t) const override { return kNever; }
  std::vector<std::pair<std::uint64_t, std::uint32_t>> log;

 private:
  Channel<std::uint32_t>& in_;
  Reg<std::uint64_t> last_{0};
  Histogram* latency_;
};

struct DesignB {
  explicit DesignB(Kernel& k, int bursts = 5, bool sleep = false)
      : req(k, "b.req", 2, 50),
        resp(k, "b.resp", 3, 20),
        source(k, req, bursts, sleep),
        memory(k, req, resp, sleep),
        sink(k, resp, sleep),
        bursts_(bursts) {}
  bool done() const { return log_size() == static_cast<std::size_t>(bursts_) * 6; }
  std::size_t log_size() const { return sink.log.size(); }
  Channel<std::uint32_t> req, resp;
  BurstSource source;
  SlowMemory memory;
  TimedSink sink;
  int bursts_;
};

}  // namespace saarcor::hw::testing
