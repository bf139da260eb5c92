// The lockstep co-simulation of the cycle model and the Verilated list unit (rtl/lockstep.h).
//
// The model side is one DynRTP as the chip builds it (units/dynrtp.h, the memory system, the
// RGC) over a thread table of one thread program per thread, so the boundary record can read the
// packet state (units/boundary_list.h). Its BoundaryRecorder hands the list unit's events to the
// Lockstep below in cycle order; when the first event of a later cycle arrives, the cycles before
// it are complete and the RTL is clocked through them.
#include "rtl/lockstep.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
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
#include "rtl/list_rtl.h"
#include "units/boundary_list.h"
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

// Thrown from inside the model's cycle when the comparison found a divergence or the replay
// reached its cycle: the kernel is left where it stands.
struct Stop {};

class Lockstep {
 public:
  Lockstep(UnitRtl& rtl, const LockstepOptions& o) : rtl_(rtl), o_(o) { rtl_.reset(); }

  // The model's events of the unit, in cycle order.
  void model_event(const BoundaryEvent& e) {
    if (o_.model_events) o_.model_events(e);
    if (e.cycle > cur_) advance_to(e.cycle);
    pending_.push_back(e);
  }

  // The model finished at cycle `end`: the RTL runs the window on and everything is compared.
  void finish(std::uint64_t end) {
    model_cycles_ = end;
    advance_to(std::max(end, cur_) + static_cast<std::uint64_t>(o_.window) + 1);
    compare(hw::kNever);
    if (o_.write_wave) rtl_.stop_trace();
  }

  bool diverged() const { return diverged_; }
  const Divergence& divergence() const { return div_; }
  const std::string& screen() const { return screen_; }
  const std::array<std::uint64_t, 6>& events() const { return events_; }
  std::uint64_t cycles() const { return cur_; }
  double rtl_seconds() const { return rtl_seconds_; }
  std::uint64_t model_cycles() const { return model_cycles_; }

 private:
  void advance_to(std::uint64_t c) {
    while (cur_ < c) {
      if (o_.until != 0 && cur_ > o_.until) {  // a replay: both sides are complete up to here
        compare(o_.until);
        throw Stop{};
      }
      step();
      pending_.clear();
      ++cur_;
      if (cur_ > static_cast<std::uint64_t>(o_.window))
        compare(cur_ - static_cast<std::uint64_t>(o_.window));
    }
  }

  // One RTL cycle: the model's inputs of cycle cur_ in, the RTL's outputs out.
  void step() {
    std::vector<BoundaryEvent> inputs, outputs;
    for (const BoundaryEvent& e : pending_) {
      remember(model_hist_, e);
      if (e.port == BoundaryPort::kCacheRequest || e.port == BoundaryPort::kOutput) {
        outputs.push_back(e);
        continue;
      }
      ++events_[static_cast<std::size_t>(e.port)];  // driven (the outputs count when compared)
      inputs.push_back(e);
      if (e.port != BoundaryPort::kCacheBlocked) remember(rtl_hist_, e);
    }
    // A cycle's outputs in port order (the model's come in the order its modules ran).
    std::stable_sort(
        outputs.begin(), outputs.end(),
        [](const BoundaryEvent& a, const BoundaryEvent& b) { return a.port < b.port; });
    model_out_.insert(model_out_.end(), outputs.begin(), outputs.end());
    if (o_.write_wave && cur_ == o_.wave_from) rtl_.start_trace(o_.wave);
    outputs.clear();
    const auto t0 = Clock::now();
    rtl_.cycle(cur_, inputs, outputs);
    rtl_seconds_ += std::chrono::duration<double>(Clock::now() - t0).count();
    if (o_.write_wave && cur_ == o_.wave_to) rtl_.stop_trace();
    for (const BoundaryEvent& e : outputs) {
      rtl_out_.push_back(e);
      remember(rtl_hist_, e);
    }
  }

  static void remember(std::deque<BoundaryEvent>& h, const BoundaryEvent& e) {
    h.push_back(e);
    if (h.size() > 256) h.pop_front();
  }

  static bool before(const BoundaryEvent& a, const BoundaryEvent& b) {
    return a.cycle != b.cycle ? a.cycle < b.cycle : a.port < b.port;
  }
  static bool same_bits(const BoundaryEvent& a, const BoundaryEvent& b) {
    return a.thread == b.thread && a.fields == b.fields && a.field == b.field;
  }

  // Matches the events of both sides up to cycle `upto`, in (cycle, port) order.
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

  static const BoundaryEvent* find(const std::deque<BoundaryEvent>& q, const BoundaryEvent& e) {
    for (const BoundaryEvent& x : q)
      if (x.port == e.port && same_bits(x, e)) return &x;
    return nullptr;
  }

  [[noreturn]] void diverge(const char* kind, const BoundaryEvent* model, const BoundaryEvent* rtl,
                            std::uint64_t other) {
    const BoundaryEvent& e = model != nullptr ? *model : *rtl;
    div_.cycle = e.cycle;
    div_.unit = units::unit_name(rtl_.unit());
    div_.port = units::boundary_port_name(e.port);
    div_.kind = kind;
    div_.other_cycle = other;
    div_.field = "thread";
    if (model != nullptr && rtl != nullptr) {
      div_.model_value = model->thread;
      div_.rtl_value = rtl->thread;
      if (model->thread == rtl->thread)
        for (int k = 0; k < model->fields; ++k)
          if (model->field[static_cast<std::size_t>(k)] !=
              rtl->field[static_cast<std::size_t>(k)]) {
            div_.field = model->names[k];
            div_.model_value = model->field[static_cast<std::size_t>(k)];
            div_.rtl_value = rtl->field[static_cast<std::size_t>(k)];
            break;
          }
    } else {
      div_.field = "event";
      div_.model_value = model != nullptr ? 1 : 0;
      div_.rtl_value = rtl != nullptr ? 1 : 0;
    }
    std::ostringstream s;
    s << "saarcor-rtl lockstep: DIVERGENCE at cycle " << div_.cycle << ", dynrtp0 " << div_.unit
      << " unit, port " << div_.port << ", field " << div_.field << "\n";
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
      if (it->cycle <= cycle) last.push_back(&*it);
    s << "  the last " << last.size() << " events of the " << units::unit_name(rtl_.unit())
      << " unit, " << side << ":\n";
    for (auto it = last.rbegin(); it != last.rend(); ++it)
      s << "    " << units::format_boundary(**it) << "\n";
  }

  UnitRtl& rtl_;
  const LockstepOptions& o_;
  std::uint64_t cur_ = 0;  // the RTL's next cycle
  std::vector<BoundaryEvent> pending_;
  std::deque<BoundaryEvent> model_out_, rtl_out_;
  std::deque<BoundaryEvent> model_hist_, rtl_hist_;
  std::array<std::uint64_t, 6> events_{};
  double rtl_seconds_ = 0;
  std::uint64_t model_cycles_ = 0;
  bool diverged_ = false;
  Divergence div_;
  std::string screen_;
};

const ListBuild& choose_build(const units::CycleParams& p, const std::string& fault) {
  int faulty = 0;  // ListBuild::fault
  if (fault == "mailbox-never-hits")
    faulty = 1;
  else if (fault == "priorities-swapped")
    faulty = 2;
  else if (!fault.empty())
    throw std::runtime_error("lockstep: unknown fault '" + fault +
                             "' (known: mailbox-never-hits, priorities-swapped)");
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

template <class F, int kLanes>
void run_model(const memif::MemoryImage& image_in, const units::CycleParams& p,
               const units::FunctionalParams& shading, Lockstep* ls) {
  memif::MemoryImage image = image_in;
  LockstepThreads<F, kLanes> threads(image, units::functional_params(p, shading), p.threads);
  hw::KernelConfig kc;
  kc.watchdog_cycles = p.watchdog;
  hw::Kernel k(kc);
  memif::MemorySystem mi(k, image, units::memory_system_config(p));
  units::RayGenerationController rgc(threads.packets(), 1);
  units::DynRtp d(k, mi, p, threads, rgc, 0);
  units::ListPayload<F, kLanes, units::FastDatapath> payload(
      threads,
      [&](units::ThreadToken t) -> const units::PacketState<F, kLanes, units::FastDatapath>& {
        return threads.state(t);
      });
  units::BoundaryRecorder rec(threads, p.threads, {UnitId::kList}, payload,
                              [&](const BoundaryEvent& e) { ls->model_event(e); });
  if (ls != nullptr) d.observe(&rec);  // (none: the model alone, for the speed beside it)
  const auto done = [&] {
    return rgc.all_handed_out() && d.rgs().idle() && mi.frame_writes_stored();
  };
  const hw::RunResult r = k.run(done);
  if (r.status == hw::RunResult::Status::kWatchdog)
    throw std::runtime_error("lockstep: the cycle model's watchdog fired at cycle " +
                             std::to_string(r.cycles));
  if (ls != nullptr) ls->finish(k.now());
}

// The cycle model alone on the same thread table (a program per thread), for its speed.
template <class F, int kLanes>
double model_alone(const memif::MemoryImage& image, const units::CycleParams& p,
                   const units::FunctionalParams& shading) {
  const auto t0 = Clock::now();
  run_model<F, kLanes>(image, p, shading, nullptr);
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

LockstepResult run_lockstep(const LockstepOptions& o) {
  for (const std::string& u : o.units)
    if (u != "list")
      throw std::runtime_error("lockstep: unknown unit '" + u + "' (the RTL units: list)");
  if (o.width < 1 || o.height < 1) throw std::runtime_error("lockstep: --res must be positive");
  units::CycleParams p = units::prototype_params();
  host::ImageParams ip;
  for (const std::string& kv : o.set)
    if (host::is_tree_setting(kv))
      host::apply_tree_setting(ip, kv);
    else
      units::apply_cycle_setting(p, kv);
  units::check_cycle_params(p);
  if (p.pipelines != 1)
    throw std::runtime_error("lockstep: the harness drives one DynRTP (pipelines=1), not " +
                             std::to_string(p.pipelines));
  const ListBuild& build = choose_build(p, o.fault);
  ip.width = o.width;
  ip.height = o.height;
  ip.max_depth = static_cast<std::uint32_t>(o.depth);
  const host::BuiltImage built = host::build_image(host::load_scene(o.scene), ip);
  units::FunctionalParams shading;
  shading.shadows = o.shadows;
  shading.secondary = o.depth > 0;
  shading.max_depth = o.depth > 0 ? o.depth : -1;

  std::unique_ptr<UnitRtl> rtl = make_list_unit_rtl(build);
  if (o.wrap_rtl) rtl = o.wrap_rtl(std::move(rtl));
  Lockstep ls(*rtl, o);
  const auto t1 = Clock::now();
  try {
    using Fp24 = ff::Float<7, 16>;
    if (p.packet <= 4)
      run_model<Fp24, 4>(built.image, p, shading, &ls);
    else
      run_model<Fp24, units::kMaxPacket>(built.image, p, shading, &ls);
  } catch (const Stop&) {
  }
  LockstepResult res;
  res.seconds = std::chrono::duration<double>(Clock::now() - t1).count();
  res.build = build.name;
  res.diverged = ls.diverged();
  res.divergence = ls.divergence();
  res.screen = ls.screen();
  res.events = ls.events();
  res.cycles = ls.cycles();
  res.rtl_seconds = ls.rtl_seconds();
  res.model_cycles = ls.model_cycles();
  if (o.bench && !res.diverged) {
    using Fp24 = ff::Float<7, 16>;
    res.model_seconds = p.packet <= 4
                            ? model_alone<Fp24, 4>(built.image, p, shading)
                            : model_alone<Fp24, units::kMaxPacket>(built.image, p, shading);
  }
  return res;
}

}  // namespace saarcor::rtl
