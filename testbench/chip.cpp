// The chip of Figure 2 instantiated and clocked (README.md "Layout": testbench/ "instantiates the
// chip and clocks it"; docs/cycle-model.md): the RGC, the DynRTPs of units/dynrtp.h and the
// memory system they share, the frame loop, the figures it samples (units/figures.h), and the
// frame with the host's upload beside it.
#include "testbench/chip.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include "hw/kernel.h"
#include "memif/memory_system.h"
#include "units/dynrtc_units.h"
#include "units/dynrtp.h"
#include "units/perfetto_trace.h"
#include "units/recorded_threads.h"

namespace saarcor {
// The chip is built from units/ only (this file's one using-directive).
using namespace units;
namespace {

template <class F, int kLanes>
void collect(FunctionalFrame& frame, RecordedThreads<F, kLanes>& threads) {
  frame.format = F::kFormat;
  frame.width = threads.sink().width;
  frame.height = threads.sink().height;
  frame.params = threads.params();
  collect_frame(frame, threads.units(), threads.sink());
}

constexpr memif::ItemType kCacheItem[kCacheUnits] = {memif::ItemType::kNode, memif::ItemType::kList,
                                                     memif::ItemType::kRow};
constexpr UnitId kTable4Unit[kTable4Units] = {UnitId::kTraversal, UnitId::kList,
                                              UnitId::kTransformation, UnitId::kIntersection};

// The frame buffer: one word per pixel from word 0 of the back bank (FrameRegisters::frame_bank).
void check_frame_buffer(const memif::MemoryImage& image) {
  const auto& r = image.registers();
  if (r.frame_bank != memif::kFrameBank0 && r.frame_bank != memif::kFrameBank1)
    throw std::runtime_error("cycle model: frame_bank " + std::to_string(r.frame_bank) +
                             " is not a frame-buffer bank (0 or 1)");
  const std::uint64_t words = std::uint64_t{r.width} * r.height;
  if (words > image.bank_words())
    throw std::runtime_error("cycle model: a " + std::to_string(r.width) + "x" +
                             std::to_string(r.height) + " frame needs " + std::to_string(words) +
                             " frame-buffer words, a bank holds " +
                             std::to_string(image.bank_words()) + " (raise --bank-mb)");
}

// The frame's image as the hardware left it: the words the RGS wrote into the back bank.
void read_frame_buffer(const memif::MemoryImage& image, int bank, CycleFrame& out) {
  const std::vector<std::uint32_t>& fb = image.bank(bank);
  auto& rgb = out.frame.rgb;
  rgb.resize(out.frame.pixels.size() * 3u);
  for (std::size_t i = 0; i < out.frame.pixels.size(); ++i)
    for (std::size_t k = 0; k < 3; ++k)
      rgb[3 * i + k] = static_cast<std::uint8_t>((fb[i] >> (8 * k)) & 255u);
  out.frame_bank = bank;
}

// The chip of Figure 2: the RGC, `pipelines` DynRTPs and the memory interface they share.
class Chip {
 public:
  Chip(hw::Kernel& k, memif::MemoryImage& image, const CycleParams& p, ThreadTable& threads)
      : mi_(k, image, memory_system_config(p)), rgc_(threads.packets(), p.pipelines) {
    for (int i = 0; i < p.pipelines; ++i)
      pipes_.push_back(std::make_unique<DynRtp>(k, mi_, p, threads, rgc_, i));
  }

  // Every packet handed out, every thread free again and the last pixels written into the frame
  // buffer (checked between cycles).
  bool finished() const {
    if (!rgc_.all_handed_out()) return false;
    for (const auto& d : pipes_)
      if (!d->rgs().idle()) return false;
    return mi_.frame_writes_stored();
  }
  std::uint64_t packets_retired() const {
    std::uint64_t n = 0;
    for (const auto& d : pipes_)
      n += d->rgs().packets_retired();
    return n;
  }
  int pipelines() const { return static_cast<int>(pipes_.size()); }
  int handed_out() const { return rgc_.handed_out(); }
  void charge_packets(PacketCharges* c) { rgc_.set_charges(c); }
  DynRtp& pipeline(int i) { return *pipes_[static_cast<std::size_t>(i)]; }
  void observe(UnitObserver* o) {
    for (auto& d : pipes_)
      d->observe(o);
  }
  memif::MemorySystem& memory() { return mi_; }

 private:
  memif::MemorySystem mi_;
  RayGenerationController rgc_;
  std::vector<std::unique_ptr<DynRtp>> pipes_;
};

// The run's traces (units/run_trace.h, units/perfetto_trace.h), all fed by one fan of hooks; none
// when the run traces nothing.
class Tracers {
 public:
  Tracers(const RunTraceOptions& o, const ThreadTable& threads, Chip& chip, const CycleParams& p) {
    if (o.trace != nullptr || o.konata != nullptr) {
      run_ = std::make_unique<RunTracer>(o, threads, p.threads);
      fan_.add(run_.get());
    }
    if (o.perfetto != nullptr) {
      PerfettoChip pc{p.pipelines, p.threads, p.clock_mhz, p.cache_misses, {}};
      for (int i = 0; i < p.pipelines; ++i) {
        std::array<const memif::Cache*, kCacheUnits> row{};
        for (int c = 0; c < kCacheUnits; ++c)
          row[static_cast<std::size_t>(c)] = &chip.memory().cache(i, kCacheItem[c]);
        pc.caches.push_back(row);
      }
      timeline_ = std::make_unique<PerfettoTracer>(o, threads, std::move(pc));
      fan_.add(timeline_.get());
      for (int i = 0; i < p.pipelines; ++i)
        for (int c = 0; c < kCacheUnits; ++c)
          chip.memory().cache(i, kCacheItem[c]).set_observer(timeline_.get());
    }
    if (o.any()) chip.observe(&fan_);
  }
  // Writes the files; `cycles`: the frame's length (a timeline window after it is an error).
  void finish(std::uint64_t cycles) {
    if (run_) run_->finish();
    if (timeline_) timeline_->finish(cycles);
  }

 private:
  ObserverFan fan_;
  std::unique_ptr<RunTracer> run_;
  std::unique_ptr<PerfettoTracer> timeline_;
};

// The chip's counters the frame reads, per DynRTP: references into the hw/ registry taken once
// from the modules that declare them, read in place (no name lookup): the Table 4 units' issue,
// stall and served counts, the caches' requests, hits, merges, misses and memory bytes, the RGS's
// packets, requests served and its shading and frame-buffer bytes. The frame's counts and each
// interval's (the registry's time series, --interval) are read from the same counters.
struct ChipCounters {
  struct Unit {
    const hw::Counter *issued, *stalled, *served;
  };
  struct CacheCounters {
    memif::Cache::Counters counts;
    const hw::Counter* bytes;
  };
  struct Pipeline {
    std::array<Unit, kTable4Units> units;
    std::array<CacheCounters, kCacheUnits> caches;
    const hw::Counter *admitted, *served, *shading, *frame;
  };
  std::vector<Pipeline> pipelines;

  explicit ChipCounters(Chip& chip) {
    memif::MemorySystem& mi = chip.memory();
    for (int p = 0; p < chip.pipelines(); ++p) {
      DynRtp& d = chip.pipeline(p);
      Pipeline& pc = pipelines.emplace_back();
      for (int i = 0; i < kTable4Units; ++i) {
        const CycleUnit& u = d.unit(kTable4Unit[i]);
        pc.units[static_cast<std::size_t>(i)] = {&u.issue_counter(), &u.stall_counter(),
                                                 &u.served_counter()};
      }
      for (int c = 0; c < kCacheUnits; ++c) {
        const memif::Cache& cache = mi.cache(p, kCacheItem[c]);
        pc.caches[static_cast<std::size_t>(c)] = {cache.counters(),
                                                  &mi.controller().client_counter(cache.client())};
      }
      pc.admitted = &d.rgs().admitted_counter();
      pc.served = &d.rgs().served_counter();
      pc.shading = &mi.controller().client_counter(mi.shading_client(p));
      pc.frame = &mi.controller().client_counter(mi.frame_client(p));
    }
  }

  // Table 4's counts at `cycle`, each counter's value given by `read(counter)`.
  template <class Read>
  FigureCounts figure_counts(std::uint64_t cycle, const Read& read) const {
    FigureCounts s;
    s.cycle = cycle;
    s.pipelines = static_cast<int>(pipelines.size());
    for (const Pipeline& p : pipelines) {
      for (std::size_t i = 0; i < kTable4Units; ++i)
        s.issued[i] += read(p.units[i].issued);
      for (std::size_t c = 0; c < kCacheUnits; ++c) {
        const CacheCounters& cc = p.caches[c];
        s.requests[c] += read(cc.counts.requests);
        s.hits[c] += read(cc.counts.hits) + read(cc.counts.merges);
        s.bytes[c] += read(cc.bytes);
      }
      s.shading_bytes += read(p.shading);
      s.frame_bytes += read(p.frame);
    }
    return s;
  }
};

FigureCounts snapshot(const hw::Kernel& k, const ChipCounters& cc) {
  return cc.figure_counts(k.now(), [](const hw::Counter* c) { return c->value; });
}

// The figures of each span of the registry's time series (sampled by simulate every `interval`
// cycles and at the frame's end), from the frame's start counts on.
std::vector<CycleFigures> interval_figures(hw::Kernel& k, const ChipCounters& cc,
                                           const FigureCounts& start, std::uint64_t interval,
                                           double clock_mhz) {
  hw::Stats& st = k.stats();
  st.set_time_series_period(interval);
  std::vector<CycleFigures> series;
  FigureCounts last = start;
  for (const std::vector<double>& row : st.time_series()) {
    const auto cycle = static_cast<std::uint64_t>(row[0]);
    if (cycle <= last.cycle) continue;
    const FigureCounts now = cc.figure_counts(cycle, [&](const hw::Counter* c) {
      return static_cast<std::uint64_t>(row[st.time_series_column(*c)]);
    });
    series.push_back(compute_figures(last, now, clock_mhz));
    last = now;
  }
  return series;
}

// With several DynRTPs each thread also names its pipeline (thread t is pipeline t / threads').
template <class F, int kLanes>
std::string thread_report(RecordedThreads<F, kLanes>& threads, const CycleParams& p) {
  std::ostringstream s;
  s << "threads (id: unit, phase, item, rays):";
  for (int t = 0; t < threads.size(); ++t) {
    const Request r = threads.request(static_cast<std::uint32_t>(t));
    if (r.unit == UnitId::kNone) continue;
    s << "\n  thread " << t;
    if (p.pipelines > 1) s << " (dynrtp" << t / p.threads << ")";
    s << ": " << unit_name(r.unit) << ", " << phase_name(r.phase);
    if (r.item != memif::kNone) s << ", item " << r.item;
    s << ", mask 0x" << std::hex << threads.mask(static_cast<std::uint32_t>(t)) << std::dec;
  }
  return s.str();
}

// Runs the kernel until `done` (by default: the chip has retired every packet) in spans of
// opt.interval cycles (--interval; 65536 without), sampling the registry's time series after each
// span, and reporting progress.
template <class F, int kLanes>
void simulate(hw::Kernel& k, Chip& chip, RecordedThreads<F, kLanes>& threads, const CycleParams& p,
              const CycleRunOptions& opt, std::function<bool()> done = {}) {
  if (!done) done = [&] { return chip.finished(); };
  const std::uint64_t chunk = opt.interval != 0 ? opt.interval : 65536;
  while (!done()) {
    std::uint64_t budget = chunk;
    if (opt.max_cycles != 0) {
      if (k.now() >= opt.max_cycles)
        throw std::runtime_error("cycle model: the frame did not finish within " +
                                 std::to_string(opt.max_cycles) + " cycles");
      budget = std::min(budget, opt.max_cycles - k.now());
    }
    const hw::RunResult r = k.run(done, budget);
    if (r.status == hw::RunResult::Status::kWatchdog)
      throw std::runtime_error("cycle model: watchdog at cycle " + std::to_string(r.cycles) +
                               ": no progress for " + std::to_string(p.watchdog) + " cycles\n" +
                               thread_report(threads, p) + "\n" + r.report);
    // --interval: the registry's time series, sampled where each span's run ends.
    if (opt.interval != 0) k.stats().sample(k.now());
    if (opt.progress)
      opt.progress(k.now(), static_cast<int>(chip.packets_retired()), threads.packets());
  }
}

// simulate() until the frame's end, reading the chip's counts at each of opt.marks (the cycle
// after which that many packets were handed out) into `marks`.
template <class F, int kLanes>
void simulate_marked(hw::Kernel& k, Chip& chip, RecordedThreads<F, kLanes>& threads,
                     const CycleParams& p, const CycleRunOptions& opt, const ChipCounters& cc,
                     std::vector<FigureCounts>& marks) {
  for (int m : opt.marks) {
    simulate(k, chip, threads, p, opt, [&] { return chip.finished() || chip.handed_out() >= m; });
    if (chip.handed_out() < m)
      throw std::logic_error("cycle model: mark " + std::to_string(m) + " beyond the " +
                             std::to_string(chip.handed_out()) + " packets handed out");
    marks.push_back(snapshot(k, cc));
  }
  simulate(k, chip, threads, p, opt);
}

// Queues the host's upload (refused here when it writes what the frame reads) and runs the frame
// until it or the upload is done, whichever comes first. Returns true when the upload is not.
template <class F, int kLanes>
bool start_upload(hw::Kernel& k, Chip& chip, RecordedThreads<F, kLanes>& threads,
                  const CycleParams& p, const CycleRunOptions& opt, const memif::HostUpload& upload,
                  CycleFrame& out) {
  memif::HostBus& host = chip.memory().host();
  host.upload(upload);
  out.upload_bytes = upload.bytes();
  simulate(k, chip, threads, p, opt, [&] { return chip.finished() || host.stored(); });
  if (!host.stored()) return true;
  out.upload_cycles = k.now();
  return false;
}

// The frame is done and its upload is not: the bus goes on alone until its last word is stored
// (the next frame cannot start before). A slow bus may wait longer than the watchdog's span for
// its next burst's credit, so the watchdog allows that wait.
void finish_upload(hw::Kernel& k, Chip& chip, const CycleParams& p, CycleFrame& out) {
  const memif::HostBus& host = chip.memory().host();
  const double burst_cycles =
      4.0 * p.hostbus_burst_words * p.clock_mhz * 1e6 / (p.hostbus_mb_s * 1048576.0);
  k.config().watchdog_cycles =
      std::max<std::uint64_t>(p.watchdog, static_cast<std::uint64_t>(2.0 * burst_cycles) + 16);
  const hw::RunResult r = k.run([&] { return host.stored(); });
  if (r.status != hw::RunResult::Status::kDone)
    throw std::runtime_error("cycle model: the host upload stopped at cycle " +
                             std::to_string(r.cycles) + "\n" + r.report);
  out.upload_cycles = k.now();
}

// Per pipeline and in total: packets, unit issue and stall cycles, requests, cache counts, read
// from the chip's counters.
void collect_units(const ChipCounters& cc, const FigureCounts& end, CycleFrame& out) {
  std::uint64_t served = 0;
  out.per_pipeline.resize(cc.pipelines.size());
  for (std::size_t pi = 0; pi < cc.pipelines.size(); ++pi) {
    const ChipCounters::Pipeline& p = cc.pipelines[pi];
    CycleFrame::PipelineCount& pc = out.per_pipeline[pi];
    pc.packets = p.admitted->value;
    served += p.served->value;
    for (std::size_t i = 0; i < kTable4Units; ++i) {
      const ChipCounters::Unit& u = p.units[i];
      pc.issue_cycles[i] = u.issued->value;
      out.issue_cycles[i] += u.issued->value;
      out.stall_cycles[i] += u.stalled->value;
      out.requests[i] += u.served->value;
    }
    for (std::size_t c = 0; c < kCacheUnits; ++c) {
      const memif::Cache::Counters& k = p.caches[c].counts;
      CycleFrame::CacheCount& count = out.caches[c];
      count.requests += k.requests->value;
      count.hits += k.hits->value;
      count.misses += k.misses->value;
      count.merges += k.merges->value;
    }
  }
  for (std::uint64_t r : out.requests)
    served += r;
  out.frame.units.requests = served;
  out.frame.units.packets = out.packets;
  for (std::size_t c = 0; c < kCacheUnits; ++c)
    out.caches[c].mem_bytes = end.bytes[c];
}

// The frame's rays, rates and SIMD efficiency at the modelled clock.
void frame_rates(const CycleParams& p, CycleFrame& out) {
  for (int kd = 0; kd < kRayKinds; ++kd) {
    out.rays += out.frame.rays_issued[static_cast<std::size_t>(kd)];
    out.per_ray_sum += out.frame.by_kind[static_cast<std::size_t>(kd)];
  }
  const double seconds = static_cast<double>(out.cycles) / (p.clock_mhz * 1e6);
  out.fps = seconds > 0 ? 1.0 / seconds : 0.0;
  out.rays_per_s = seconds > 0 ? static_cast<double>(out.rays) / seconds : 0.0;
  const std::uint64_t steps = out.frame.units.traversal_steps;
  out.simd_efficiency = steps == 0 ? 0.0
                                   : static_cast<double>(out.per_ray_sum.traversal_steps) /
                                         static_cast<double>(steps) / p.packet;
}

// The parameters, the options and the image's frame buffer, before anything is built.
void check_run(const memif::MemoryImage& image, const CycleParams& p, const CycleRunOptions& opt) {
  check_cycle_params(p);
  check_frame_buffer(image);
  if (opt.programs == ProgramMode::kAhead && opt.ahead_packets < 1)
    throw std::runtime_error("cycle model: ahead_packets must be >= 1 (got " +
                             std::to_string(opt.ahead_packets) + ")");
}

// The frame as the RGS left it: the image read back from the bank it wrote, and its traffic.
void collect_rgs(const memif::MemoryImage& image, int bank, const FigureCounts& end,
                 CycleFrame& out) {
  read_frame_buffer(image, bank, out);
  out.shading_bytes = end.shading_bytes;
  out.frame_bytes = end.frame_bytes;
  const double pixels = static_cast<double>(out.frame.width) * out.frame.height;
  out.shading_bytes_per_pixel =
      pixels > 0 ? static_cast<double>(end.shading_bytes + end.frame_bytes) / pixels : 0.0;
}

// A sampled frame's charges (units::PacketCharges), fed by the chip's RGS, when asked for.
std::unique_ptr<PacketCharges> charge_packets(Chip& chip, int packets, const CycleParams& p,
                                              const CycleRunOptions& opt) {
  if (!opt.charge_packets) return nullptr;
  auto c = std::make_unique<PacketCharges>(packets, p.pipelines * p.threads);
  chip.charge_packets(c.get());
  return c;
}

// The charges at the frame's end `now`; its cycles after the last retirement are no packet's.
void collect_charges(const PacketCharges& c, std::uint64_t now, CycleFrame& out) {
  out.packet_charges = c.charges();
  out.uncharged_cycles = c.empty_cycles() + (now - c.last_event());
}

// The kernel's watchdog, evaluation order and idle skipping.
hw::KernelConfig kernel_config(const CycleParams& p, const CycleRunOptions& opt) {
  hw::KernelConfig kc;
  kc.watchdog_cycles = p.watchdog;
  kc.shuffle_seed = opt.shuffle_seed;
  kc.idle_skip = opt.idle_skip;
  return kc;
}

template <class F, int kLanes>
CycleFrame run_cycle_format(const memif::MemoryImage& image_in, const CycleParams& p,
                            const CycleRunOptions& opt, const memif::HostUpload* upload) {
  const auto t0 = std::chrono::steady_clock::now();
  check_run(image_in, p, opt);
  // The chip's memory. Without an upload, a copy: the RGS writes its frame-buffer bank and the
  // caller's image stays unchanged (several runs may share it, as a sweep's points do). With one,
  // the caller's image (run_cycle's mutable overload): the upload's words and the frame's pixels
  // stay in it for the next frame.
  std::optional<memif::MemoryImage> copy;
  if (upload == nullptr) copy.emplace(image_in);
  memif::MemoryImage& image = copy ? *copy : const_cast<memif::MemoryImage&>(image_in);
  // The bank this frame is written into (an upload brings the next frame's registers).
  const int frame_bank = static_cast<int>(image.registers().frame_bank);
  RecordedThreads<F, kLanes> threads(image, functional_params(p, opt.shading),
                                     p.pipelines * p.threads, opt.programs, opt.ahead_packets,
                                     opt.trace, opt.packet_order);
  hw::Kernel k(kernel_config(p, opt));
  Chip chip(k, image, p, threads);
  if (opt.vcd != nullptr) k.trace_vcd(*opt.vcd, opt.vcd_from, opt.vcd_to);
  Tracers tracers(opt.trace, threads, chip, p);

  CycleFrame out;
  out.params = p;
  out.packets = static_cast<std::uint64_t>(threads.packets());
  const std::unique_ptr<PacketCharges> charges = charge_packets(chip, threads.packets(), p, opt);
  const ChipCounters counters(chip);
  const FigureCounts start = snapshot(k, counters);
  const bool uploading = upload != nullptr && start_upload(k, chip, threads, p, opt, *upload, out);
  simulate_marked(k, chip, threads, p, opt, counters, out.marks);
  if (opt.vcd != nullptr) k.finish_trace();
  tracers.finish(k.now());
  const FigureCounts end = snapshot(k, counters);
  if (opt.interval != 0)
    out.series = interval_figures(k, counters, start, opt.interval, p.clock_mhz);
  out.cycles = k.now();
  if (charges) collect_charges(*charges, k.now(), out);
  if (uploading) finish_upload(k, chip, p, out);

  threads.finish();
  collect(out.frame, threads);
  collect_rgs(image, frame_bank, end, out);
  out.figures = compute_figures(start, end, p.clock_mhz);
  collect_units(counters, end, out);
  frame_rates(p, out);
  out.packets_retired = chip.packets_retired();
  out.skipped_cycles = k.skipped_cycles();
  out.host_threads = opt.programs == ProgramMode::kAhead ? 2 : 1;
  out.programs = opt.programs;
  out.module_evaluations = k.module_evaluations();
  out.stats_json = k.stats().json();
  out.host_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.frame.seconds = out.host_seconds;
  out.sim_cycles_per_s =
      out.host_seconds > 0 ? static_cast<double>(out.cycles) / out.host_seconds : 0.0;
  return out;
}

CycleFrame run_cycle_image(const memif::MemoryImage& image, const CycleParams& params,
                           const CycleRunOptions& options, const memif::HostUpload* upload) {
  // The prototype's P = 4 gets thread programs with 4-lane packet arrays (ThreadProgram's
  // kLanes); wider packets the full 64.
  if (image.format() == ff::kFp24) {
    if (params.packet <= 4)
      return run_cycle_format<ff::Float<7, 16>, 4>(image, params, options, upload);
    return run_cycle_format<ff::Float<7, 16>, kMaxPacket>(image, params, options, upload);
  }
  // The widest format with fp24's exponent, for the width study (docs/cycle-model.md, "Datapath
  // width"): 31-bit values, a matrix row in four words instead of three.
  if (image.format() == ff::Format{7, 23}) {
    if (params.packet <= 4)
      return run_cycle_format<ff::Float<7, 23>, 4>(image, params, options, upload);
    return run_cycle_format<ff::Float<7, 23>, kMaxPacket>(image, params, options, upload);
  }
  throw std::runtime_error("cycle model: the image is in " + ff::format_name(image.format()) +
                           "; the cycle model is built for fp24 (e7m16) and e7m23");
}

}  // namespace

CycleFrame run_cycle(const memif::MemoryImage& image, const CycleParams& params,
                     const CycleRunOptions& options) {
  return run_cycle_image(image, params, options, nullptr);
}

CycleFrame run_cycle(memif::MemoryImage& image, const CycleParams& params,
                     const CycleRunOptions& options, const memif::HostUpload& upload) {
  return run_cycle_image(image, params, options, &upload);
}

std::uint64_t run_upload(memif::MemoryImage& image, const CycleParams& params,
                         memif::HostUpload upload) {
  upload.frame_reads.clear();  // no frame in flight
  hw::KernelConfig kc;
  // A slow bus may wait longer than the watchdog's span for its next burst's credit.
  const double burst_cycles =
      4.0 * params.hostbus_burst_words * params.clock_mhz * 1e6 / (params.hostbus_mb_s * 1048576.0);
  kc.watchdog_cycles =
      std::max<std::uint64_t>(params.watchdog, static_cast<std::uint64_t>(2.0 * burst_cycles) + 16);
  hw::Kernel k(kc);
  memif::MemorySystem mi(k, image, memory_system_config(params));
  mi.host().upload(upload);
  return k.run_to_completion([&] { return mi.host().stored(); });
}

}  // namespace saarcor
