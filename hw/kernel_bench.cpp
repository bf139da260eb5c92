// Kernel speed (docs/hw.md): simulated cycles per second and module evaluations per
// second for a design of 20 modules and 40 channels with traffic, with and without idle
// skipping. Target: >= 20 million module evaluations per second on one core; each run prints its
// ratio to that target, and the skipping runs their speed-up over stepping every cycle.
//
// Two traffic shapes: "busy" (tokens circulate all the time: the per-evaluation cost) and
// "bursty" (a burst of tokens every 2000 cycles through long-latency channels, as a memory-bound
// model spends most cycles waiting: what idle skipping is for).
#include <benchmark/benchmark.h>

#include <array>
#include <cstdio>
#include <ctime>
#include <memory>
#include <vector>

#include "hw/kernel.h"

namespace saarcor::hw {
namespace {

constexpr int kModules = 20;
constexpr double kTargetEvalsPerSecond = 20e6;

struct Token {
  std::uint32_t id = 0;
  std::uint32_t ttl = 0;
};

// Forwards tokens from two inputs to two outputs (round-robin between inputs, output chosen by the
// token), drops them when their ttl runs out; module 0 also injects bursts.
class Hop : public Module {
 public:
  Hop(Kernel& k, int index, std::uint64_t burst_period, int burst_size)
      : Module(k, "hop" + std::to_string(index)),
        index_(index),
        burst_period_(burst_period),
        burst_size_(burst_size) {}
  void connect(Channel<Token>* in0, Channel<Token>* in1, Channel<Token>* out0,
               Channel<Token>* out1) {
    in_ = {in0, in1};
    out_ = {out0, out1};
  }
  int evaluate() override {
    int p = 0;
    const int first = rr_.get();
    for (int k = 0; k < 2; ++k) {
      Channel<Token>& in = *in_[(first + k) & 1];
      if (!in.can_pop()) continue;
      const Token& t = in.peek();
      if (t.ttl == 0) {
        in.pop();
        ++delivered;
        ++p;
        continue;
      }
      Channel<Token>& out = *out_[(t.id + t.ttl) & 1];
      if (!out.can_push()) {
        stall();
        continue;
      }
      Token n = in.pop();
      --n.ttl;
      out.push(n);
      ++p;
    }
    if (burst_period_ == 0 && now() == 0) {  // busy traffic: tokens that never expire
      for (int o = 0; o < 2; ++o)
        out_[o]->push({static_cast<std::uint32_t>(2 * index_ + o), ~0u});
      p += 2;
    }
    if (burst_period_ != 0 && index_ == 0 && now() % burst_period_ == 0) {
      for (int b = 0; b < burst_size_ && out_[b & 1]->can_push(); ++b) {
        out_[b & 1]->push({next_id_++, 40});
        ++p;
      }
    }
    if (p) rr_.set(first ^ 1);
    return p;
  }
  void commit() override { rr_.commit(); }
  std::uint64_t next_wakeup(std::uint64_t now) const override {
    if (burst_period_ == 0 || index_ != 0) return kNever;  // busy tokens: no timers
    return (now / burst_period_ + 1) * burst_period_;
  }
  std::uint64_t delivered = 0;

 private:
  int index_;
  std::uint64_t burst_period_;
  int burst_size_;
  std::array<Channel<Token>*, 2> in_{}, out_{};
  Reg<int> rr_{0};
  std::uint32_t next_id_ = 0;
};

struct Design {
  Design(Kernel& k, bool bursty) {
    for (int i = 0; i < kModules; ++i) {
      hops.push_back(std::make_unique<Hop>(k, i, bursty ? 2000 : 0, 16));
    }
    // Channel 2i goes i -> i+1, channel 2i+1 goes i -> i+7 (mod 20): 40 channels.
    for (int i = 0; i < kModules; ++i) {
      const int lat0 = bursty ? 20 + i % 5 : 1 + i % 3;
      const int lat1 = bursty ? 35 + i % 7 : 2 + i % 2;
      chans.push_back(
          std::make_unique<Channel<Token>>(k, "c" + std::to_string(2 * i), lat0 + 2, lat0));
      chans.push_back(
          std::make_unique<Channel<Token>>(k, "c" + std::to_string(2 * i + 1), lat1 + 2, lat1));
    }
    for (int i = 0; i < kModules; ++i) {
      const int prev1 = (i + kModules - 1) % kModules, prev7 = (i + kModules - 7) % kModules;
      hops[i]->connect(chans[2 * prev1].get(), chans[2 * prev7 + 1].get(), chans[2 * i].get(),
                       chans[2 * i + 1].get());
    }
  }
  std::vector<std::unique_ptr<Hop>> hops;
  std::vector<std::unique_ptr<Channel<Token>>> chans;
};

void run_kernel(benchmark::State& state, bool bursty, bool skip) {
  constexpr std::uint64_t kCycles = 200000;
  std::uint64_t cycles = 0, evaluations = 0, hop_evaluations = 0;
  double seconds = 0;
  for (auto _ : state) {
    Kernel k({.idle_skip = skip, .watchdog_cycles = 0});
    Design d(k, bursty);
    // Processor time, not wall time: the machine is shared, and one core is the target.
    const std::clock_t t0 = std::clock();
    const RunResult r = k.run([] { return false; }, kCycles);
    const std::clock_t t1 = std::clock();
    benchmark::DoNotOptimize(r.cycles);
    seconds += static_cast<double>(t1 - t0) / CLOCKS_PER_SEC;
    cycles += r.cycles;
    evaluations += k.module_evaluations();
    hop_evaluations += k.evaluated_cycles() * kModules;
  }
  const double evals_per_s = static_cast<double>(hop_evaluations) / seconds;
  state.counters["sim_cycles_per_s"] = static_cast<double>(cycles) / seconds;
  state.counters["module_evals_per_s"] = evals_per_s;
  state.counters["ratio_to_20M_evals"] = evals_per_s / kTargetEvalsPerSecond;
  // Cycles covered per second counting skipped ones as 20 evaluations each: the speed a user sees.
  state.counters["effective_evals_per_s"] = static_cast<double>(cycles) * kModules / seconds;
  (void)evaluations;
}

void BM_KernelBusy_Step(benchmark::State& s) {
  run_kernel(s, false, false);
}
void BM_KernelBusy_Skip(benchmark::State& s) {
  run_kernel(s, false, true);
}
void BM_KernelBursty_Step(benchmark::State& s) {
  run_kernel(s, true, false);
}
void BM_KernelBursty_Skip(benchmark::State& s) {
  run_kernel(s, true, true);
}
BENCHMARK(BM_KernelBusy_Step)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_KernelBusy_Skip)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_KernelBursty_Step)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_KernelBursty_Skip)->Unit(benchmark::kMillisecond)->MinTime(1.0);

}  // namespace
}  // namespace saarcor::hw

BENCHMARK_MAIN();
