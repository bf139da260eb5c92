// Simulation speed of the memory interface (docs/memif.md): one and four DynRTPs' caches
// under random item traffic (one request per cache per cycle when accepted), with idle skipping.
// Prints simulated cycles per second and module evaluations per second, and the ratio of the
// latter to the kernel target of 20 million per second measured by hw_bench.
#include <benchmark/benchmark.h>

#include <ctime>
#include <memory>
#include <random>
#include <vector>

#include "memif/memory_system.h"

namespace saarcor::memif {
namespace {

// Issues a request whenever the cache accepts one (a hot window plus uniform indices) and pops
// every response.
class Unit : public hw::Module {
 public:
  Unit(hw::Kernel& k, std::string name, Cache& c, std::uint32_t items, unsigned seed)
      : hw::Module(k, std::move(name)), c_(c), items_(items), rng_(seed) {}
  int evaluate() override {
    int p = 0;
    if (c_.responses().can_pop()) {
      c_.responses().pop();
      ++answered;
      ++p;
    }
    if (c_.requests().can_push()) {
      const std::uint32_t r = static_cast<std::uint32_t>(rng_());
      const std::uint32_t index =
          (r & 3u) != 0 ? (hot_ + (r >> 8) % 64u) % items_ : (r >> 8) % items_;
      if ((r & 0xFF00u) == 0) hot_ = (r >> 16) % items_;
      c_.requests().push({index, {0, sent++}});
      ++p;
    }
    return p;
  }
  std::uint64_t next_wakeup(std::uint64_t) const override { return hw::kNever; }
  std::uint32_t sent = 0;
  std::uint64_t answered = 0;

 private:
  Cache& c_;
  std::uint32_t items_;
  std::mt19937 rng_;
  std::uint32_t hot_ = 0;
};

void BM_MemorySystem(benchmark::State& state) {
  const int pipelines = static_cast<int>(state.range(0));
  constexpr std::uint64_t kCycles = 100000;
  double seconds = 0;
  std::uint64_t cycles = 0, evals = 0, answered = 0;
  for (auto _ : state) {
    MemoryImage img(ff::kFp24, 1u << 16);
    img.regions().base = {0, 20000, 40000};
    hw::Kernel k;
    MemorySystemConfig cfg;
    cfg.pipelines = pipelines;
    MemorySystem mi(k, img, cfg);
    std::vector<std::unique_ptr<Unit>> units;
    for (int p = 0; p < pipelines; ++p) {
      for (int t = 0; t < kItemTypes; ++t) {
        units.push_back(std::make_unique<Unit>(k, "u" + std::to_string(p) + std::to_string(t),
                                               mi.cache(p, static_cast<ItemType>(t)), 20000,
                                               static_cast<unsigned>(7 * p + t)));
      }
    }
    const std::clock_t t0 = std::clock();
    const hw::RunResult r = k.run([] { return false; }, kCycles);
    seconds += static_cast<double>(std::clock() - t0) / CLOCKS_PER_SEC;
    cycles += r.cycles;
    evals += k.module_evaluations();
    for (auto& u : units)
      answered += u->answered;
  }
  const double eps = static_cast<double>(evals) / seconds;
  state.counters["sim_cycles_per_s"] = static_cast<double>(cycles) / seconds;
  state.counters["module_evals_per_s"] = eps;
  state.counters["ratio_to_20M_evals"] = eps / 20e6;
  state.counters["answers_per_cycle"] = static_cast<double>(answered) / static_cast<double>(cycles);
}
BENCHMARK(BM_MemorySystem)->Arg(1)->Arg(4)->Unit(benchmark::kMillisecond)->MinTime(1.0);

}  // namespace
}  // namespace saarcor::memif

BENCHMARK_MAIN();
