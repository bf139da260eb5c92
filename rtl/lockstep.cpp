// The lockstep co-simulation of the cycle model and the Verilated units (rtl/lockstep.h).
//
// The model side is one DynRTP as the chip builds it (units/dynrtp.h, the memory system, the
// RGC) over a thread table of one thread program per thread, so the boundary record can read the
// packet state (units/boundary_traversal.h, units/boundary_list.h). Its BoundaryRecorder hands the
// events of the units in the run to the Cosim below in cycle order; when the first event of a
// later cycle arrives, the cycles before it are complete and every RTL unit is clocked through
// them, each beside its own comparer (Lockstep).
#include "rtl/lockstep.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/image_builder.h"
#include "host/scene.h"
#include "host/tree_settings.h"
#include "hw/kernel.h"
#include "memif/memory_system.h"
#include "rtl/cache_rtl.h"
#include "rtl/dynrtc_rtl.h"
#include "rtl/intersection_rtl.h"
#include "rtl/list_rtl.h"
#include "rtl/transformation_rtl.h"
#include "rtl/traversal_rtl.h"
#include "rtl/unit_ports.h"
#include "units/boundary_cache.h"
#include "units/boundary_intersection.h"
#include "units/boundary_list.h"
#include "units/boundary_transformation.h"
#include "units/boundary_traversal.h"
#include "units/cycle_params.h"
#include "units/dynrtc_units.h"
#include "units/dynrtp.h"
#include "units/fast_datapath.h"
#include "units/functional_model.h"
#include "units/thread_program.h"

namespace saarcor::rtl {
namespace {

using Clock = std::chrono::steady_clock;
using units::BoundaryEvent;
using units::BoundaryPort;
using units::UnitId;

// One thread program per thread (the cycle model's per-step mode), with its packet state in
// reach of the boundary record.
template <class F, int kLanes>
class LockstepThreads final : public units::ThreadTable {
 public:
  LockstepThreads(const memif::MemoryImage& image, const units::FunctionalParams& params,
                  int threads)
      : params_(params), units_(params.mode) {
    w_ = static_cast<int>(image.registers().width);
    h_ = static_cast<int>(image.registers().height);
    tiling_ = units::packet_tiling(w_, h_, params.packet);
    sink_.reset(w_, h_);
    for (int i = 0; i < threads; ++i) {
      programs_.push_back(std::make_unique<units::ThreadProgram<F, kLanes, units::FastDatapath>>(
          image, params_, units_, sink_));
      requests_.push_back(programs_.back()->request());
    }
  }
  void execute(std::uint32_t t) override {
    programs_[t]->execute();
    requests_[t] = programs_[t]->request();
  }
  void start_primary(std::uint32_t t, int packet) override {
    programs_[t]->start_primary(units::packet_pixels(tiling_, w_, h_, packet));
    requests_[t] = programs_[t]->request();
  }
  int packets() const override { return tiling_.count(); }
  const std::vector<units::RgsAccess>& rgs_memory(std::uint32_t t) const override {
    return programs_[t]->rgs_memory();
  }
  const units::PacketState<F, kLanes, units::FastDatapath>& state(std::uint32_t t) const {
    return programs_[t]->state();
  }

 private:
  units::FunctionalParams params_;
  units::PipelineUnits<F> units_;
  units::FrameSink sink_;
  units::PacketTiling tiling_;
  int w_ = 0, h_ = 0;
  std::vector<std::unique_ptr<units::ThreadProgram<F, kLanes, units::FastDatapath>>> programs_;
};

// Thrown from inside the model's cycle when a comparison found a divergence or the replay reached
// its cycle: the kernel is left where it stands.
struct Stop {};

// One RTL unit beside the model's: its inputs of a cycle driven, its outputs matched with the
// model's `window` cycles behind the clock.
class Lockstep {
 public:
  // The whole DynRTC (unit kNone) takes every event of the run: its boundary's inputs, and every
  // unit's and cache's outputs to compare.
  Lockstep(UnitRtl& rtl, const LockstepOptions& o)
      : rtl_(rtl), o_(o), whole_(rtl.unit() == UnitId::kNone) {
    rtl_.reset();
  }

  // A model event of cycle cur_ (the driver clocks the RTL before the events of a later cycle).
  void model_event(BoundaryEvent e) { pending_.push_back(std::move(e)); }

  // One RTL cycle: the model's inputs of the cycle in, the RTL's outputs out.
  void step(std::uint64_t cur) {
    std::vector<BoundaryEvent> inputs, outputs;
    for (BoundaryEvent& e : pending_) {
      remember(model_hist_, e);
      if (is_output(e)) {
        outputs.push_back(std::move(e));
        continue;
      }
      // The whole DynRTC is given its boundary only: the rest is what its own units compute.
      if (whole_ && !at_dynrtc_boundary(e)) continue;
      ++events_[static_cast<std::size_t>(e.port)];  // given (the outputs count when compared)
      if (e.port != BoundaryPort::kCacheBlocked) remember(rtl_hist_, e);
      inputs.push_back(std::move(e));
    }
    pending_.clear();
    in_port_order(outputs);
    for (BoundaryEvent& e : outputs)
      model_out_.push_back(std::move(e));
    if (o_.write_wave && cur == o_.wave_from) rtl_.start_trace(wave_file(o_, rtl_.name()));
    outputs.clear();
    const auto t0 = Clock::now();
    rtl_.cycle(cur, inputs, outputs);
    rtl_seconds_ += std::chrono::duration<double>(Clock::now() - t0).count();
    if (o_.write_wave && cur == o_.wave_to) rtl_.stop_trace();
    in_port_order(outputs);
    for (BoundaryEvent& e : outputs) {
      remember(rtl_hist_, e);
      rtl_out_.push_back(std::move(e));
    }
  }

  // Matches the events of both sides up to cycle `upto`, in (cycle, port) order (within a cycle
  // and port, by thread).
  void compare(std::uint64_t upto) {
    for (;;) {
      const bool m = !model_out_.empty() && model_out_.front().cycle <= upto;
      const bool r = !rtl_out_.empty() && rtl_out_.front().cycle <= upto;
      if (!m && !r) return;
      if (m && r && !before(model_out_.front(), rtl_out_.front()) &&
          !before(rtl_out_.front(), model_out_.front())) {
        const BoundaryEvent& a = model_out_.front();
        const BoundaryEvent& b = rtl_out_.front();
        if (!same_bits(a, b)) diverge(a.thread == b.thread ? "payload" : "order", &a, &b, 0);
        ++events_[static_cast<std::size_t>(a.port)];
        model_out_.pop_front();
        rtl_out_.pop_front();
        continue;
      }
      if (m && (!r || before(model_out_.front(), rtl_out_.front()))) {
        const BoundaryEvent& a = model_out_.front();
        const BoundaryEvent* late = find(rtl_out_, a);
        diverge(late != nullptr ? "timing" : "missing", &a, nullptr,
                late != nullptr ? late->cycle : 0);
      }
      const BoundaryEvent& b = rtl_out_.front();
      const BoundaryEvent* late = find(model_out_, b);
      diverge(late != nullptr ? "timing" : "extra", nullptr, &b, late != nullptr ? late->cycle : 0);
    }
  }

  void stop_trace() { rtl_.stop_trace(); }
  bool diverged() const { return diverged_; }
  const Divergence& divergence() const { return div_; }
  const std::string& screen() const { return screen_; }
  const std::array<std::uint64_t, units::kBoundaryPorts>& events() const { return events_; }
  double rtl_seconds() const { return rtl_seconds_; }

 private:
  // The events of the last cycles: the window behind the clock and the 16 events before it.
  void remember(std::deque<BoundaryEvent>& h, const BoundaryEvent& e) const {
    h.push_back(e);
    const std::uint64_t keep = 2 * static_cast<std::uint64_t>(o_.window) + 64;
    while (h.size() > 16 && h.front().cycle + keep < e.cycle)
      h.pop_front();
  }

  // What the RTL computes (compared), as opposed to what it is given: a unit's cache requests
  // and threads leaving; a cache's lookups, replies and line requests; in the whole DynRTC also
  // the routing's work (each cache's line request taken, its fills).
  bool is_output(const BoundaryEvent& e) const {
    if (e.cache)
      return e.port == BoundaryPort::kCacheAccept || e.port == BoundaryPort::kCacheReply ||
             e.port == BoundaryPort::kMemRequest ||
             (whole_ && (e.port == BoundaryPort::kMemTaken || e.port == BoundaryPort::kMemFill));
    return e.port == BoundaryPort::kCacheRequest || e.port == BoundaryPort::kOutput;
  }

  // Events of a cycle are ordered by port, then by the unit or cache whose they are.
  static int source(const BoundaryEvent& e) {
    return 2 * (units::kMaxUnits * e.dynrtp + units::unit_index(e.unit)) + (e.cache ? 1 : 0);
  }
  static bool before(const BoundaryEvent& a, const BoundaryEvent& b) {
    if (a.cycle != b.cycle) return a.cycle < b.cycle;
    return a.port != b.port ? a.port < b.port : source(a) < source(b);
  }
  // A cycle's events in (port, source, thread) order: the model's come in the order its modules
  // ran, the RTL's in its ports' order; a unit with two output ports (the traversal unit) may let
  // two threads go in one cycle.
  static void in_port_order(std::vector<BoundaryEvent>& v) {
    std::stable_sort(v.begin(), v.end(), [](const BoundaryEvent& a, const BoundaryEvent& b) {
      if (a.port != b.port) return a.port < b.port;
      return source(a) != source(b) ? source(a) < source(b) : a.thread < b.thread;
    });
  }
  static bool same_bits(const BoundaryEvent& a, const BoundaryEvent& b) {
    return source(a) == source(b) && a.thread == b.thread && a.fields == b.fields &&
           a.field == b.field && a.wide == b.wide;
  }
  // The name of the unit or cache an event is of.
  std::string source_name(const BoundaryEvent& e) const {
    if (!whole_) return rtl_.name();
    return e.cache ? units::cache_name(e.unit) : units::unit_name(e.unit);
  }

  static const BoundaryEvent* find(const std::deque<BoundaryEvent>& q, const BoundaryEvent& e) {
    for (const BoundaryEvent& x : q)
      if (x.port == e.port && same_bits(x, e)) return &x;
    return nullptr;
  }

  // The field that differs (the thread when the threads differ; "event" when one side has none).
  void first_difference(const BoundaryEvent* model, const BoundaryEvent* rtl) {
    div_.field = "event";
    div_.model_value = model != nullptr ? 1 : 0;
    div_.rtl_value = rtl != nullptr ? 1 : 0;
    if (model == nullptr || rtl == nullptr) return;
    div_.field = "thread";
    div_.model_value = model->thread;
    div_.rtl_value = rtl->thread;
    if (model->thread != rtl->thread) return;
    for (int k = 0; k < model->fields; ++k) {
      const auto i = static_cast<std::size_t>(k);
      if (model->field[i] == rtl->field[i]) continue;
      div_.field = model->names[k];
      div_.model_value = model->field[i];
      div_.rtl_value = rtl->field[i];
      return;
    }
    // The fields agree: the first wide word that differs (a ray's or a hit record's).
    for (std::size_t k = 0; k < model->wide.size() && k < rtl->wide.size(); ++k) {
      if (model->wide[k] == rtl->wide[k]) continue;
      div_.field = "wide[" + std::to_string(k) + "]";
      div_.model_value = model->wide[k];
      div_.rtl_value = rtl->wide[k];
      return;
    }
  }

  [[noreturn]] void diverge(const char* kind, const BoundaryEvent* model, const BoundaryEvent* rtl,
                            std::uint64_t other) {
    const BoundaryEvent& e = model != nullptr ? *model : *rtl;
    div_.cycle = e.cycle;
    div_.unit = source_name(e);
    div_.dynrtp = e.dynrtp;
    div_.port = units::boundary_port_name(e.port);
    div_.kind = kind;
    div_.other_cycle = other;
    first_difference(model, rtl);
    std::ostringstream s;
    s << "saarcor-rtl lockstep: DIVERGENCE at cycle " << div_.cycle << ", dynrtp" << div_.dynrtp
      << " " << div_.unit << " unit, port " << div_.port << ", field " << div_.field << "\n";
    s << "  class: " << kind;
    if (div_.kind == "timing")
      s << " (" << (model != nullptr ? "the RTL has it at cycle " : "the model has it at cycle ")
        << other << ")";
    s << "\n  model value 0x" << std::hex << div_.model_value << ", RTL value 0x" << div_.rtl_value
      << std::dec << "\n";
    s << "  model: " << (model != nullptr ? units::format_boundary(*model) : "(nothing)") << "\n";
    s << "  RTL:   " << (rtl != nullptr ? units::format_boundary(*rtl) : "(nothing)") << "\n";
    history(s, "model", model_hist_, div_.cycle);
    history(s, "RTL", rtl_hist_, div_.cycle);
    screen_ = s.str();
    diverged_ = true;
    throw Stop{};
  }

  void history(std::ostringstream& s, const char* side, const std::deque<BoundaryEvent>& h,
               std::uint64_t cycle) const {
    std::vector<const BoundaryEvent*> last;
    for (auto it = h.rbegin(); it != h.rend() && last.size() < 16; ++it)
      if (it->cycle <= cycle && source_name(*it) == div_.unit && it->dynrtp == div_.dynrtp)
        last.push_back(&*it);
    s << "  the last " << last.size() << " events of the " << div_.unit << " unit, " << side
      << ":\n";
    for (auto it = last.rbegin(); it != last.rend(); ++it)
      s << "    " << units::format_boundary(**it) << "\n";
  }

  UnitRtl& rtl_;
  const LockstepOptions& o_;
  bool whole_;
  std::vector<BoundaryEvent> pending_;
  std::deque<BoundaryEvent> model_out_, rtl_out_;
  std::deque<BoundaryEvent> model_hist_, rtl_hist_;
  std::array<std::uint64_t, units::kBoundaryPorts> events_{};
  double rtl_seconds_ = 0;
  bool diverged_ = false;
  Divergence div_;
  std::string screen_;
};

// The RTL units clocked together: the model's events (in cycle order) go to their unit's
// Lockstep; when the first event of a later cycle arrives, the cycles before it are complete and
// every unit is clocked through them.
class Cosim {
 public:
  explicit Cosim(const LockstepOptions& o) : o_(o) {}
  void add(UnitRtl& rtl) {
    Lockstep* l = &steps_.emplace_back(rtl, o_);
    if (rtl.unit() == UnitId::kNone)
      whole_ = l;
    else
      (rtl.cache() ? caches_ : units_)[static_cast<std::size_t>(units::unit_index(rtl.unit()))] = l;
  }

  void model_event(const BoundaryEvent& e) {
    if (o_.model_events) o_.model_events(e);
    Lockstep* u =
        whole_ != nullptr
            ? whole_
            : (e.cache ? caches_ : units_)[static_cast<std::size_t>(units::unit_index(e.unit))];
    if (u == nullptr) return;
    if (e.cycle > cur_) advance_to(e.cycle);
    u->model_event(e);
  }

  // The model finished at cycle `end`: the RTL runs the window on and everything is compared.
  void finish(std::uint64_t end) {
    model_cycles_ = end;
    advance_to(std::max(end, cur_) + static_cast<std::uint64_t>(o_.window) + 1);
    for (Lockstep& u : steps_)
      u.compare(hw::kNever);
    if (o_.write_wave)
      for (Lockstep& u : steps_)
        u.stop_trace();
  }

  const std::deque<Lockstep>& units() const { return steps_; }
  std::uint64_t cycles() const { return cur_; }
  std::uint64_t model_cycles() const { return model_cycles_; }

 private:
  void advance_to(std::uint64_t c) {
    const auto window = static_cast<std::uint64_t>(o_.window);
    while (cur_ < c) {
      if (o_.until != 0 && cur_ > o_.until) {  // a replay: both sides are complete up to here
        for (Lockstep& u : steps_)
          u.compare(o_.until);
        throw Stop{};
      }
      for (Lockstep& u : steps_)
        u.step(cur_);
      ++cur_;
      if (cur_ > window)
        for (Lockstep& u : steps_)
          u.compare(cur_ - window);
    }
  }

  const LockstepOptions& o_;
  std::deque<Lockstep> steps_;  // (a deque: the pointers below stay valid)
  std::array<Lockstep*, units::kMaxUnits> units_{}, caches_{};  // by the (served) unit
  Lockstep* whole_ = nullptr;                                   // the whole DynRTC's
  std::uint64_t cur_ = 0;                                       // the RTL's next cycle
  std::uint64_t model_cycles_ = 0;
};

// The fault builds (LockstepOptions::fault) of a unit: its fault number, 0 for none.
int fault_of(const std::string& unit, const std::string& fault) {
  if (fault.empty() || unit == "dynrtc") return 0;  // (the whole DynRTC has no fault builds)
  if (unit.ends_with("-cache")) return fault == "merge-wrong-target" ? 1 : 0;
  if (unit == "intersection") return fault == "strict-uv" ? 1 : 0;
  if (unit == "transformation")
    return fault == "n-plus-one-off" ? 1 : fault == "row-out-of-order" ? 2 : 0;
  if (unit == "list")
    return fault == "mailbox-never-hits" ? 1 : fault == "priorities-swapped" ? 2 : 0;
  if (fault == "pop-off") return 1;
  if (fault == "short-pipeline") return 2;
  return fault == "priorities-swapped" ? 3 : 0;
}

const ListBuild& choose_list_build(const units::CycleParams& p, int faulty) {
  std::string built;
  for (const ListBuild& b : list_builds()) {
    if (b.fault == faulty && b.threads == p.threads && b.packet == p.packet &&
        b.mailbox == p.mailbox && b.triangle_mailbox == p.triangle_mailbox &&
        b.depth == p.list_depth())
      return b;
    if (b.fault == faulty)
      built += " [threads=" + std::to_string(b.threads) + " packet=" + std::to_string(b.packet) +
               " mailbox=" + std::to_string(b.mailbox) +
               " triangle_mailbox=" + std::to_string(b.triangle_mailbox) +
               " lat.cmp=" + std::to_string(b.depth) + "]";
  }
  throw std::runtime_error(
      "lockstep: no Verilated list unit for threads=" + std::to_string(p.threads) +
      " packet=" + std::to_string(p.packet) + " mailbox=" + std::to_string(p.mailbox) +
      " triangle_mailbox=" + std::to_string(p.triangle_mailbox) +
      " lat.cmp=" + std::to_string(p.list_depth()) + "; built:" + built);
}

std::string intersection_config(int threads, int packet, int add, int mul, int div, int cmp) {
  return "threads=" + std::to_string(threads) + " packet=" + std::to_string(packet) +
         " lat.add=" + std::to_string(add) + " lat.mul=" + std::to_string(mul) +
         " lat.div=" + std::to_string(div) + " lat.cmp=" + std::to_string(cmp);
}

const IntersectionBuild& choose_intersection_build(const units::CycleParams& p, int faulty) {
  std::string built;
  for (const IntersectionBuild& b : intersection_builds()) {
    if (b.fault == faulty && b.threads == p.threads && b.packet == p.packet &&
        b.lat_add == p.lat_add && b.lat_mul == p.lat_mul && b.lat_div == p.lat_div &&
        b.lat_cmp == p.lat_cmp)
      return b;
    if (b.fault == faulty)
      built +=
          " [" +
          intersection_config(b.threads, b.packet, b.lat_add, b.lat_mul, b.lat_div, b.lat_cmp) +
          "]";
  }
  throw std::runtime_error(
      "lockstep: no Verilated intersection unit for " +
      intersection_config(p.threads, p.packet, p.lat_add, p.lat_mul, p.lat_div, p.lat_cmp) +
      "; built:" + built);
}

const TransformationBuild& choose_transformation_build(const units::CycleParams& p, int faulty) {
  std::string built;
  const auto config = [](int threads, int packet, int add, int mul) {
    return "threads=" + std::to_string(threads) + " packet=" + std::to_string(packet) +
           " lat.add=" + std::to_string(add) + " lat.mul=" + std::to_string(mul);
  };
  for (const TransformationBuild& b : transformation_builds()) {
    if (b.fault == faulty && b.threads == p.threads && b.packet == p.packet &&
        b.lat_add == p.lat_add && b.lat_mul == p.lat_mul)
      return b;
    if (b.fault == faulty) built += " [" + config(b.threads, b.packet, b.lat_add, b.lat_mul) + "]";
  }
  throw std::runtime_error("lockstep: no Verilated transformation unit for " +
                           config(p.threads, p.packet, p.lat_add, p.lat_mul) + "; built:" + built);
}

std::string traversal_config(int threads, int packet, int stack, int add, int div, int cmp) {
  return "threads=" + std::to_string(threads) + " packet=" + std::to_string(packet) +
         " stack=" + std::to_string(stack) + " lat.add=" + std::to_string(add) +
         " lat.div=" + std::to_string(div) + " lat.cmp=" + std::to_string(cmp);
}

// The traversal unit is built for the defaults of the rules it does not parameterise.
const TraversalBuild& choose_traversal_build(const units::CycleParams& p, int faulty) {
  if (!p.skip_empty || !p.clip_exit_only || p.clip_faces_per_step != 1)
    throw std::runtime_error(
        "lockstep: the Verilated traversal unit is built for traversal.skip_empty=1, "
        "clip.exit_only=1 and clip.faces_per_step=1 only");
  std::string built;
  for (const TraversalBuild& b : traversal_builds()) {
    if (b.fault == faulty && b.threads == p.threads && b.packet == p.packet && b.stack == p.stack &&
        b.lat_add == p.lat_add && b.lat_div == p.lat_div && b.lat_cmp == p.lat_cmp)
      return b;
    if (b.fault == faulty)
      built += " [" +
               traversal_config(b.threads, b.packet, b.stack, b.lat_add, b.lat_div, b.lat_cmp) +
               "]";
  }
  throw std::runtime_error(
      "lockstep: no Verilated traversal unit for " +
      traversal_config(p.threads, p.packet, p.stack, p.lat_add, p.lat_div, p.lat_cmp) +
      "; built:" + built);
}

// What the model records: the units' events and the caches' (units/boundary_cache.h).
struct Recorded {
  std::vector<UnitId> units;
  std::vector<memif::ItemType> caches;
  bool port = false;  // the memory controller's cache port (the whole DynRTC's boundary)
};

template <class F, int kLanes>
void run_model(const memif::MemoryImage& image_in, const units::CycleParams& p,
               const units::FunctionalParams& shading, const Recorded& recorded, Cosim* cs,
               std::vector<std::uint32_t>* frame = nullptr) {
  using State = units::PacketState<F, kLanes, units::FastDatapath>;
  memif::MemoryImage image = image_in;
  // DynRTP q's threads are ids [q x threads, (q + 1) x threads) of one table (units::DynRtp).
  LockstepThreads<F, kLanes> threads(image, units::functional_params(p, shading),
                                     p.threads * p.pipelines);
  hw::KernelConfig kc;
  kc.watchdog_cycles = p.watchdog;
  hw::Kernel k(kc);
  memif::MemorySystem mi(k, image, units::memory_system_config(p));
  units::RayGenerationController rgc(threads.packets(), p.pipelines);
  std::vector<std::unique_ptr<units::DynRtp>> pipes;
  for (int q = 0; q < p.pipelines; ++q)
    pipes.push_back(std::make_unique<units::DynRtp>(k, mi, p, threads, rgc, q));
  const auto state = [&](units::ThreadToken t) -> const State& { return threads.state(t); };
  units::ListPayload<F, kLanes, units::FastDatapath> list(threads, state);
  units::TraversalPayload<F, kLanes, units::FastDatapath> traversal(threads, state);
  units::IntersectionPayload<F, kLanes, units::FastDatapath> intersection(threads, state);
  units::TransformationPayload<F, kLanes, units::FastDatapath> transformation(threads, state);
  units::UnitPayloads payloads(threads);
  payloads.set(UnitId::kTransformation, transformation);
  payloads.set(UnitId::kIntersection, intersection);
  payloads.set(UnitId::kList, list);
  payloads.set(UnitId::kTraversal, traversal);
  const auto sink = [&](const BoundaryEvent& e) { cs->model_event(e); };
  units::BoundaryRecorder rec(threads, p.threads, recorded.units, payloads, sink);
  std::optional<units::CacheRecorder> caches;  // (the units' hooks through it to `rec`)
  if (cs != nullptr && !recorded.caches.empty())
    caches.emplace(mi, image, recorded.caches, &rec, sink, p.pipelines, p.threads);
  if (caches && recorded.port) caches->record_port(mi);
  if (cs != nullptr)  // (none: the model alone, for the speed beside it)
    for (auto& d : pipes)
      d->observe(caches ? static_cast<units::UnitObserver*>(&*caches) : &rec);
  const auto done = [&] {
    bool idle = rgc.all_handed_out() && mi.frame_writes_stored();
    for (const auto& d : pipes)
      idle = idle && d->rgs().idle();
    return idle;
  };
  const hw::RunResult r = k.run(done);
  if (r.status == hw::RunResult::Status::kWatchdog)
    throw std::runtime_error("lockstep: the cycle model's watchdog fired at cycle " +
                             std::to_string(r.cycles));
  if (cs == nullptr) return;
  cs->finish(k.now());
  if (frame == nullptr) return;
  const auto& bank = image.bank(static_cast<int>(image.registers().frame_bank));
  const std::size_t pixels = static_cast<std::size_t>(image.registers().width) *
                             static_cast<std::size_t>(image.registers().height);
  frame->assign(bank.begin(), bank.begin() + static_cast<std::ptrdiff_t>(pixels));
}

// The cycle model alone on the same thread table (a program per thread), for its speed.
template <class F, int kLanes>
double model_alone(const memif::MemoryImage& image, const units::CycleParams& p,
                   const units::FunctionalParams& shading) {
  const auto t0 = Clock::now();
  run_model<F, kLanes>(image, p, shading, Recorded{}, nullptr);
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

std::string lockstep_command(const LockstepOptions& o) {
  std::string s = "saarcor-rtl lockstep " + o.scene + " --units ";
  for (std::size_t i = 0; i < o.units.size(); ++i)
    s += (i != 0 ? "," : "") + o.units[i];
  s += " --res " + std::to_string(o.width) + "x" + std::to_string(o.height);
  for (const std::string& kv : o.set)
    s += " --set " + kv;
  if (o.shadows) s += " --shadows";
  if (o.depth != 0) s += " --depth " + std::to_string(o.depth);
  if (!o.fault.empty()) s += " --fault " + o.fault;
  return s;
}

std::string wave_file(const LockstepOptions& o, const std::string& unit) {
  if (o.units.size() < 2 && (o.units.empty() || o.units[0] != "caches")) return o.wave;
  const std::size_t dot = o.wave.rfind('.');
  const std::size_t slash = o.wave.rfind('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
    return o.wave + "." + unit;
  return o.wave.substr(0, dot) + "." + unit + o.wave.substr(dot);
}

const LockstepUnit& LockstepResult::unit(const std::string& name) const {
  for (const LockstepUnit& u : units)
    if (u.unit == name) return u;
  throw std::logic_error("lockstep: the " + name + " unit did not run");
}

namespace {

// The cycle model's parameters of the run (one DynRTP).
units::CycleParams run_params(const LockstepOptions& o, host::ImageParams& ip) {
  units::CycleParams p = units::prototype_params();
  for (const std::string& kv : o.set)
    if (host::is_tree_setting(kv))
      host::apply_tree_setting(ip, kv);
    else
      units::apply_cycle_setting(p, kv);
  units::check_cycle_params(p);
  const bool whole = o.units.size() == 1 && o.units[0] == "dynrtc";
  if (p.pipelines != 1 && !(whole && p.pipelines == 2))
    throw std::runtime_error(
        "lockstep: the harness drives one DynRTP (pipelines=1), or two whole "
        "DynRTCs (--units dynrtc, pipelines=2), not " +
        std::to_string(p.pipelines));
  return p;
}

// The unit a cache name serves (node-cache: traversal, list-cache: list, row-cache:
// transformation), kNone for another name.
UnitId cache_of(const std::string& name) {
  for (UnitId u : {UnitId::kTraversal, UnitId::kList, UnitId::kTransformation})
    if (name == units::cache_name(u)) return u;
  return UnitId::kNone;
}

// The run's units with `caches` standing for the three caches.
std::vector<std::string> expand_units(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  for (const std::string& n : names)
    if (n == "caches")
      out.insert(out.end(), {"node-cache", "list-cache", "row-cache"});
    else
      out.push_back(n);
  return out;
}

std::string cache_config(int hit, int misses, int targets, int rq, int mq) {
  return "cache.hit_latency=" + std::to_string(hit) + " cache.misses=" + std::to_string(misses) +
         " cache.merge_targets=" + std::to_string(targets) +
         " cache.request_queue=" + std::to_string(rq) + " cache.memory_queue=" + std::to_string(mq);
}

// The cache build whose timing parameters are the run's and whose arrays hold the run's cache
// (its lines, its ways, a power of two, and the item words; the labels' thread bits).
const CacheBuild& choose_cache_build(const units::CycleParams& p, UnitId unit, int faulty) {
  const auto& c = p.cache[unit == UnitId::kTraversal ? 0 : unit == UnitId::kList ? 1 : 2];
  const int words = unit == UnitId::kTraversal ? 2 : unit == UnitId::kList ? 1 : 3;
  const std::string name = units::cache_name(unit);
  if ((c.ways & (c.ways - 1)) != 0)
    throw std::runtime_error("lockstep: the Verilated " + name +
                             " takes a power of two of ways, not " + std::to_string(c.ways));
  if (p.threads * p.pipelines > 4096)
    throw std::runtime_error("lockstep: the Verilated caches label at most 4096 threads");
  std::string built;
  for (const CacheBuild& b : cache_builds()) {
    if (b.fault != faulty) continue;
    if (b.hit_latency == p.cache_hit_latency && b.misses == p.cache_misses &&
        b.targets == p.cache_merge_targets && b.request_queue == p.cache_request_queue &&
        b.memory_queue == p.cache_memory_queue && c.items <= b.items && c.ways <= b.ways &&
        words <= b.words)
      return b;
    built += " [" +
             cache_config(b.hit_latency, b.misses, b.targets, b.request_queue, b.memory_queue) +
             " items<=" + std::to_string(b.items) + " ways<=" + std::to_string(b.ways) + "]";
  }
  throw std::runtime_error("lockstep: no Verilated " + name + " for " +
                           cache_config(p.cache_hit_latency, p.cache_misses, p.cache_merge_targets,
                                        p.cache_request_queue, p.cache_memory_queue) +
                           " items=" + std::to_string(c.items) + " ways=" + std::to_string(c.ways) +
                           "; built:" + built);
}

// The Verilated build of each unit in o.units for the run's parameters (and fault): a list, a
// traversal or an intersection unit build.
struct Chosen {
  const CacheBuild* cache = nullptr;
  UnitId served = UnitId::kNone;  // the cache's unit
  const ListBuild* list = nullptr;
  const TraversalBuild* traversal = nullptr;
  const IntersectionBuild* intersection = nullptr;
  const TransformationBuild* transformation = nullptr;
  const DynrtcBuild* dynrtc = nullptr;
};

// The whole DynRTC's build: the units' parameters of the run, everything else the prototype's
// (the latencies, the caches' timing, up to 512 items and 4 ways, one response a cycle through a
// routing whose port channel holds 4).
const DynrtcBuild& choose_dynrtc_build(const units::CycleParams& p) {
  const units::CycleParams proto = units::prototype_params();
  const auto& c = p.cache;
  bool caches_fit = true;
  for (const auto& k : c)
    caches_fit = caches_fit && k.items <= 512 && (k.items & (k.items - 1)) == 0 && k.ways <= 4 &&
                 (k.ways & (k.ways - 1)) == 0;
  if (p.lat_add != proto.lat_add || p.lat_mul != proto.lat_mul || p.lat_div != proto.lat_div ||
      p.lat_cmp != proto.lat_cmp || p.cache_hit_latency != proto.cache_hit_latency ||
      p.cache_misses != proto.cache_misses || p.cache_merge_targets != proto.cache_merge_targets ||
      p.cache_request_queue != proto.cache_request_queue ||
      p.cache_memory_queue != proto.cache_memory_queue || p.routing_responses != 1 ||
      std::max(p.mem_port_capacity, 2) != 4 || !caches_fit || !p.skip_empty || !p.clip_exit_only ||
      p.clip_faces_per_step != 1)
    throw std::runtime_error(
        "lockstep: the Verilated whole DynRTC is built for the prototype's latencies, cache "
        "timing, routing, port and traversal rules (caches of up to 512 items and 4 ways, "
        "powers of two)");
  std::string built;
  for (const DynrtcBuild& b : dynrtc_builds()) {
    if (b.threads == p.threads && b.packet == p.packet && b.stack == p.stack &&
        b.mailbox == p.mailbox && b.triangle_mailbox == p.triangle_mailbox)
      return b;
    built += " [threads=" + std::to_string(b.threads) + " packet=" + std::to_string(b.packet) +
             " stack=" + std::to_string(b.stack) + " mailbox=" + std::to_string(b.mailbox) +
             " triangle_mailbox=" + std::to_string(b.triangle_mailbox) + "]";
  }
  throw std::runtime_error(
      "lockstep: no Verilated whole DynRTC for threads=" + std::to_string(p.threads) +
      " packet=" + std::to_string(p.packet) + " stack=" + std::to_string(p.stack) +
      " mailbox=" + std::to_string(p.mailbox) +
      " triangle_mailbox=" + std::to_string(p.triangle_mailbox) + "; built:" + built);
}
std::vector<Chosen> choose_builds(const LockstepOptions& o, const units::CycleParams& p,
                                  std::vector<LockstepUnit>& info) {
  bool fault_used = o.fault.empty();
  std::vector<Chosen> chosen;
  for (const std::string& u : expand_units(o.units)) {
    if (u != "traversal" && u != "list" && u != "intersection" && u != "transformation" &&
        u != "dynrtc" && cache_of(u) == UnitId::kNone)
      throw std::runtime_error("lockstep: unknown unit '" + u +
                               "' (the RTL units: traversal, list, transformation, intersection, "
                               "node-cache, list-cache, row-cache; caches: the three; dynrtc: "
                               "the whole DynRTC)");
    if (u == "dynrtc" && o.units.size() != 1)
      throw std::runtime_error("lockstep: the whole DynRTC (dynrtc) runs alone: it has every unit");
    for (const LockstepUnit& x : info)
      if (x.unit == u) throw std::runtime_error("lockstep: unit '" + u + "' given twice");
    const int fault = fault_of(u, o.fault);
    fault_used = fault_used || fault != 0;
    LockstepUnit& x = info.emplace_back();
    x.unit = u;
    Chosen& c = chosen.emplace_back();
    if (u == "dynrtc")
      x.build = (c.dynrtc = &choose_dynrtc_build(p))->name;
    else if (cache_of(u) != UnitId::kNone)
      x.build = (c.cache = &choose_cache_build(p, c.served = cache_of(u), fault))->name;
    else if (u == "list")
      x.build = (c.list = &choose_list_build(p, fault))->name;
    else if (u == "intersection")
      x.build = (c.intersection = &choose_intersection_build(p, fault))->name;
    else if (u == "transformation")
      x.build = (c.transformation = &choose_transformation_build(p, fault))->name;
    else
      x.build = (c.traversal = &choose_traversal_build(p, fault))->name;
  }
  if (!fault_used)
    throw std::runtime_error(
        "lockstep: no unit of the run has the fault '" + o.fault +
        "' (list: mailbox-never-hits, priorities-swapped; traversal: "
        "pop-off, short-pipeline, priorities-swapped; intersection: "
        "strict-uv; transformation: n-plus-one-off, row-out-of-order; the caches: "
        "merge-wrong-target)");
  return chosen;
}

memif::ItemType cache_type(UnitId served) {
  return served == UnitId::kTraversal ? memif::ItemType::kNode
         : served == UnitId::kList    ? memif::ItemType::kList
                                      : memif::ItemType::kRow;
}

// The Verilated unit or cache of a chosen build.
std::unique_ptr<UnitRtl> make_rtl(const Chosen& c, const units::CycleParams& p,
                                  const memif::MemoryImage& image) {
  if (c.dynrtc != nullptr) {
    std::vector<DynrtcConfig> configs(static_cast<std::size_t>(p.pipelines));
    for (int q = 0; q < p.pipelines; ++q) {
      DynrtcConfig& config = configs[static_cast<std::size_t>(q)];
      config.frame = image.registers();
      for (int k = 0; k < memif::kItemTypes; ++k) {
        const auto type = static_cast<memif::ItemType>(k);
        const auto t = static_cast<std::size_t>(k);
        config.caches[t] = {p.cache[t].items, p.cache[t].ways, image.item_words(type),
                            image.regions().base[t]};
        config.clients[t] = memif::MemorySystem::cache_client(q, type);
      }
    }
    return make_dynrtc_rtl(*c.dynrtc, configs);
  }
  if (c.cache != nullptr) {
    const memif::ItemType type = cache_type(c.served);
    const auto& sizes = p.cache[static_cast<std::size_t>(type)];
    return make_cache_unit_rtl(*c.cache, c.served,
                               {sizes.items, sizes.ways, image.item_words(type),
                                image.regions().base[static_cast<std::size_t>(type)]});
  }
  if (c.list != nullptr) return make_list_unit_rtl(*c.list);
  if (c.intersection != nullptr) return make_intersection_unit_rtl(*c.intersection);
  if (c.transformation != nullptr)
    return make_transformation_unit_rtl(*c.transformation, image.registers());
  return make_traversal_unit_rtl(*c.traversal, image.registers());
}

// What the model records for a chosen build: its unit's or cache's events; the whole DynRTC's
// are every unit's and cache's and the controller port's.
void record(const Chosen& c, const UnitRtl& rtl, Recorded& recorded) {
  if (c.dynrtc != nullptr) {
    recorded.units = {UnitId::kTransformation, UnitId::kTraversal, UnitId::kList,
                      UnitId::kIntersection};
    recorded.caches = {memif::ItemType::kNode, memif::ItemType::kList, memif::ItemType::kRow};
    recorded.port = true;
  } else if (c.cache != nullptr) {
    recorded.caches.push_back(cache_type(c.served));
  } else {
    recorded.units.push_back(rtl.unit());
  }
}

}  // namespace

LockstepResult run_lockstep(const LockstepOptions& o) {
  if (o.width < 1 || o.height < 1) throw std::runtime_error("lockstep: --res must be positive");
  if (o.units.empty()) throw std::runtime_error("lockstep: no unit to run");
  host::ImageParams ip;
  const units::CycleParams p = run_params(o, ip);
  ip.width = o.width;
  ip.height = o.height;
  ip.max_depth = static_cast<std::uint32_t>(o.depth);
  LockstepResult res;
  const std::vector<Chosen> chosen = choose_builds(o, p, res.units);  // before the scene: fast
  const host::BuiltImage built = host::build_image(host::load_scene(o.scene), ip);
  units::FunctionalParams shading;
  shading.shadows = o.shadows;
  shading.secondary = o.depth > 0;
  shading.max_depth = o.depth > 0 ? o.depth : -1;

  std::vector<std::unique_ptr<UnitRtl>> rtl;
  Recorded recorded;
  Cosim cs(o);
  for (const Chosen& c : chosen) {
    rtl.push_back(make_rtl(c, p, built.image));
    if (o.wrap_rtl) rtl.back() = o.wrap_rtl(std::move(rtl.back()));
    record(c, *rtl.back(), recorded);
    cs.add(*rtl.back());
  }
  const auto t1 = Clock::now();
  using Fp24 = ff::Float<7, 16>;
  try {
    if (p.packet <= 4)
      run_model<Fp24, 4>(built.image, p, shading, recorded, &cs, &res.frame);
    else
      run_model<Fp24, units::kMaxPacket>(built.image, p, shading, recorded, &cs, &res.frame);
  } catch (const Stop&) {
  }
  res.seconds = std::chrono::duration<double>(Clock::now() - t1).count();
  std::size_t i = 0;
  for (const Lockstep& u : cs.units()) {
    res.units[i++].events = u.events();
    res.rtl_seconds += u.rtl_seconds();
    if (!u.diverged() || res.diverged) continue;
    res.diverged = true;
    res.divergence = u.divergence();
    res.screen = u.screen();
  }
  res.cycles = cs.cycles();
  res.model_cycles = cs.model_cycles();
  if (o.bench && !res.diverged)
    res.model_seconds = p.packet <= 4
                            ? model_alone<Fp24, 4>(built.image, p, shading)
                            : model_alone<Fp24, units::kMaxPacket>(built.image, p, shading);
  return res;
}

}  // namespace saarcor::rtl
