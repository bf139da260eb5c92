// The simulation kernel (docs/hw.md): clock, two-phase cycle, idle skip, watchdog.
// Also the out-of-line parts of Module and ChannelBase, which register with the kernel.
#include "hw/kernel.h"

#include <algorithm>
#include <bit>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "hw/vcd.h"

namespace saarcor::hw {

// ---- ChannelBase ------------------------------------------------------------------------------

ChannelBase::ChannelBase(Kernel& kernel, std::string name, int capacity, int latency, int width)
    : now_(&kernel.cycle_),
      capacity_(capacity),
      latency_(latency),
      width_(width),
      schedule_(&kernel.schedule_),
      moves_(&kernel.moves_),
      name_(std::move(name)) {
  if (capacity < 1 || latency < 1 || width < 1) {
    throw std::logic_error("channel '" + name_ +
                           "': capacity, latency and width must be >= 1 (got " +
                           std::to_string(capacity) + ", " + std::to_string(latency) + ", " +
                           std::to_string(width) + ")");
  }
  std::size_t slots = 1;
  while (slots < static_cast<std::size_t>(capacity))
    slots *= 2;
  ready_at_.assign(slots, kNever);
  mask_ = slots - 1;
  kernel.add_channel(this);
}

void ChannelBase::misuse(const char* what) const {
  throw std::logic_error("channel '" + name_ + "' at cycle " + std::to_string(*now_) + ": " + what);
}

// Called between cycles only: the occupancy is a committed one.
void ChannelBase::flush_stats() {
  pushes_stat_->value += tail_ - flushed_pushes_;
  flushed_pushes_ = tail_;
  max_occupancy_stat_->set_max(std::max(max_count_, tail_ - head_));
}

// ---- Module -------------------------------------------------------------------------------------

Module::Module(Kernel& kernel, std::string name)
    : now_(&kernel.cycle_), kernel_(&kernel), name_(std::move(name)) {
  kernel.add_module(this);
}

Stats& Module::stats() const {
  return kernel_->stats();
}

void Module::account_now() {
  if (accounted_ < *now_) {
    kernel_->account(this);
  }
}

void Module::consumes(ChannelBase& c) {
  if (c.consumer_ != nullptr && c.consumer_ != this)
    throw std::logic_error("channel '" + c.name() + "': consumed by both '" + c.consumer_->name() +
                           "' and '" + name_ + "'");
  if (c.consumer_ == this) return;
  c.consumer_ = this;
  c.consumer_slot_ = slot_;
  inputs_.push_back(&c);
}

void Module::produces(ChannelBase& c) {
  if (c.producer_ != nullptr && c.producer_ != this)
    throw std::logic_error("channel '" + c.name() + "': produced by both '" + c.producer_->name() +
                           "' and '" + name_ + "'");
  c.producer_ = this;
  c.producer_slot_ = slot_;
}

// ---- Kernel -------------------------------------------------------------------------------------

Kernel::Kernel(KernelConfig config) : config_(config), rng_(config.shuffle_seed) {}

Kernel::~Kernel() = default;

void Kernel::add_module(Module* m) {
  if (m->name().empty()) throw std::logic_error("kernel: a module needs a name");
  m->busy_stat_ = &stats_.counter(m->name() + ".busy_cycles", "cycles",
                                  "cycles in which the module made progress");
  m->stall_stat_ = &stats_.counter(m->name() + ".stall_cycles", "cycles",
                                   "cycles in which the module had work but was blocked");
  m->accounted_ = cycle_;
  // Slots 1.. in registration order (the order of evaluation).
  m->slot_ = modules_.size() + 1;
  schedule_.resize(m->slot_ + 1);
  due_.resize(schedule_.words());
  always_.resize(schedule_.words());
  modules_.push_back(m);
  order_.push_back(m);
  awake_.resize(modules_.size());
}

void Kernel::add_channel(ChannelBase* c) {
  c->pushes_stat_ = &stats_.counter(c->name() + ".pushes", "items", "items pushed");
  c->max_occupancy_stat_ =
      &stats_.counter(c->name() + ".max_occupancy", "items", "largest committed occupancy");
  stats_.formula(c->name() + ".avg_occupancy", "items", "committed occupancy averaged over cycles",
                 [this, c] {
                   // The occupancy at the start of each cycle so far: an item popped in cycle q
                   // after its push in cycle p counted in cycles p+1 .. q, one still held in p+1 ..
                   // cycle_-1.
                   if (cycle_ == 0) return 0.0;
                   const std::uint64_t area =
                       c->pop_cycles_ - c->push_cycles_ + (c->tail_ - c->head_) * (cycle_ - 1);
                   return static_cast<double>(area) / static_cast<double>(cycle_);
                 });
  channels_.push_back(c);
}

int Kernel::step() {
  wake_all();
  const int total = step_cycle();
  account_all();
  return total;
}

// Also settles who is scheduled: a module's sleeps_ is known only after its constructor, so the
// modules that do not sleep (evaluated in every evaluated cycle, kept out of the schedule) and the
// channel ends that post wakes (those of sleepers; the others post to the sink) are fixed here.
void Kernel::wake_all() {
  for (ChannelBase* c : channels_) {
    c->consumer_slot_ = c->consumer_ != nullptr && c->consumer_->sleeps_ ? c->consumer_->slot_ : 0;
    c->producer_slot_ = c->producer_ != nullptr && c->producer_->sleeps_ ? c->producer_->slot_ : 0;
  }
  std::fill(always_.begin(), always_.end(), 0);
  for (const Module* m : modules_) {
    if (m->sleeps_) {
      schedule_.wake(m->slot_, cycle_, cycle_);
    } else {
      schedule_.cancel(m->slot_);
      always_[m->slot_ / 64] |= std::uint64_t{1} << (m->slot_ % 64);
    }
  }
}

// Counts the cycles a module was not evaluated in (asleep, or jumped over by the idle skip) as
// repeats of its last evaluated cycle: no progress, the same stall.
void Kernel::account(Module* m) {
  const std::uint64_t n = cycle_ - m->accounted_;
  if (n == 0) return;
  if (m->stalled_) m->stall_count_ += n;
  if (!m->skipped_is_noop_) m->skipped(n);
  m->accounted_ = cycle_;
}

void Kernel::account_all() {
  for (Module* m : modules_) {
    account(m);
    m->busy_stat_->value += m->busy_count_;
    m->stall_stat_->value += m->stall_count_;
    m->busy_count_ = m->stall_count_ = 0;
  }
  for (ChannelBase* c : channels_)
    c->flush_stats();
}

int Kernel::step_cycle() {
  if (config_.shuffle_seed != 0) std::shuffle(order_.begin(), order_.end(), rng_);
  const std::uint64_t now = cycle_, next = cycle_ + 1;
  const std::uint64_t moves_before = moves_;
  std::uint64_t* const due = due_.data();
  schedule_.take(now, due);
  int progress = 0;
  Module** const busy = awake_.data();  // the modules to commit: those that made progress
  std::size_t busy_count = 0, evaluated = 0;
  // Evaluates one module and settles its cycle at once: statistics, and its next wake cycle (an
  // idle module's state and inputs are final for this cycle: it staged nothing, and other
  // modules' pushes and pops can only wake it earlier).
  auto evaluate = [&](Module* m) {
    if (m->accounted_ != now) account(m);
    m->stalled_ = false;
    const int p = m->evaluate();
    m->last_progress_ = p;
    m->accounted_ = next;
    m->stall_count_ += m->stalled_;
    progress += p;
    ++evaluated;
    if (p > 0) {
      ++m->busy_count_;
      busy[busy_count++] = m;
    }
    if (m->sleeps_) {
      const std::uint64_t at = p > 0 ? next : idle_wakeup(*m);
      if (at != kNever) schedule_.wake(m->slot_, at, now);
    }
  };
  // Without idle skipping every module is due every cycle (the reference for the figures).
  const bool all = !config_.idle_skip;
  if (config_.shuffle_seed != 0) {
    for (Module* m : order_)
      if (all || !m->sleeps_ || (due[m->slot_ / 64] >> (m->slot_ % 64) & 1) != 0) evaluate(m);
  } else if (all) {
    for (Module* m : modules_)
      evaluate(m);
  } else {
    for (std::size_t w = 0, words = due_.size(); w < words; ++w)
      for (std::uint64_t bits = due[w] | always_[w]; bits != 0; bits &= bits - 1)
        evaluate(modules_[w * 64 + static_cast<std::size_t>(std::countr_zero(bits)) - 1]);
  }
  evaluations_ += evaluated;
  ++evaluated_;
  if (tracer_) tracer_->sample(cycle_, modules_, channels_);
  // An idle module staged nothing (module.h: progress 0 = nothing changed): only the others
  // commit, after every evaluation (a module may read another's committed register).
  for (std::size_t i = 0; i < busy_count; ++i)
    if (!busy[i]->commit_is_noop_) busy[i]->commit();
  const int total = progress + static_cast<int>(moves_ - moves_before);
  ++cycle_;
  if (total > 0) progress_mark_ = cycle_;
  if (config_.time_series_period != 0 && cycle_ % config_.time_series_period == 0) {
    account_all();
    stats_.set_time_series_period(config_.time_series_period);
    stats_.sample(cycle_);
  }
  return total;
}

// A sleeping module's next evaluation after an idle cycle: its own timers, or the first item on
// one of its inputs that becomes visible later (pushes and pops after now wake it themselves).
std::uint64_t Kernel::idle_wakeup(const Module& m) const {
  std::uint64_t t = m.next_wakeup(cycle_);
  for (const ChannelBase* c : m.inputs_) {
    const std::uint64_t r = c->front_ready_cycle();
    if (r > cycle_ && r < t) t = r;
  }
  return std::max(t, cycle_ + 1);
}

std::uint64_t Kernel::next_event() const {
  const std::uint64_t last = cycle_ - 1;  // the idle cycle just evaluated
  std::uint64_t t = kNever;
  for (const Module* m : modules_)
    t = std::min(t, m->next_wakeup(last));
  for (const ChannelBase* c : channels_) {
    const std::uint64_t r = c->front_ready_cycle();
    if (r > last) t = std::min(t, r);
  }
  return std::max(t, cycle_);
}

void Kernel::skip_to(std::uint64_t target) {
  // The jumped-over cycles are counted lazily (account) like a sleeping module's.
  skipped_ += target - cycle_;
  cycle_ = target;
  if (config_.time_series_period != 0 && cycle_ % config_.time_series_period == 0) {
    account_all();
    stats_.set_time_series_period(config_.time_series_period);
    stats_.sample(cycle_);
  }
}

RunResult Kernel::run(const std::function<bool()>& done, std::uint64_t max_cycles) {
  RunResult r = run_cycles(done, max_cycles);
  account_all();
  return r;
}

RunResult Kernel::run_cycles(const std::function<bool()>& done, std::uint64_t max_cycles) {
  const std::uint64_t limit = max_cycles > kNever - cycle_ ? kNever : cycle_ + max_cycles;
  progress_mark_ = cycle_;
  const std::uint64_t wd = config_.watchdog_cycles;
  wake_all();  // the caller may have changed module state between runs
  for (;;) {
    if (done()) return {RunResult::Status::kDone, cycle_, {}};
    if (cycle_ >= limit) return {RunResult::Status::kCycleLimit, cycle_, {}};
    if (wd != 0 && cycle_ - progress_mark_ >= wd) {
      account_all();
      return {RunResult::Status::kWatchdog, cycle_, state_report()};
    }
    if (step_cycle() != 0 || !config_.idle_skip) continue;
    // Idle cycle: jump to the earliest cycle where anything (or anything we report) can change.
    std::uint64_t target = std::min(next_event(), limit);
    for (const Module* m : modules_) {  // a sleeper's pending wake (next_event covers the rest)
      if (m->sleeps_) target = std::min(target, schedule_.wake_cycle(m->slot_));
      if (m->bounds_skip_) {
        target = std::min(target, m->skip_bound(cycle_));
      }
    }
    if (wd != 0) target = std::min(target, progress_mark_ + wd);
    const std::uint64_t period = config_.time_series_period;
    if (period != 0) target = std::min(target, (cycle_ / period + 1) * period);
    if (tracer_ && cycle_ < trace_from_) target = std::min(target, trace_from_);
    if (target == kNever) {  // no watchdog, no limit, and nothing can ever happen again
      account_all();
      return {RunResult::Status::kWatchdog, cycle_,
              "nothing can change any more (no pending event)\n" + state_report()};
    }
    if (target > cycle_) skip_to(target);
  }
}

std::uint64_t Kernel::run_to_completion(const std::function<bool()>& done,
                                        std::uint64_t max_cycles) {
  const RunResult r = run(done, max_cycles);
  if (r.status == RunResult::Status::kWatchdog) {
    throw std::runtime_error("simulation stopped by the watchdog at cycle " +
                             std::to_string(r.cycles) + "\n" + r.report);
  }
  if (r.status == RunResult::Status::kCycleLimit) {
    throw std::runtime_error("simulation reached its cycle limit at cycle " +
                             std::to_string(r.cycles) + " without completing\n" + state_report());
  }
  return r.cycles;
}

std::string Kernel::state_report() const {
  std::ostringstream os;
  os << "cycle " << cycle_ << ", no progress since cycle " << progress_mark_ << "\n";
  for (const Module* m : modules_) {
    os << "module " << m->name() << (m->stalled_ ? " [stalled]" : "") << ":";
    const std::string s = m->dump_state();
    os << (s.empty() ? " (no state dump)" : " " + s) << "\n";
  }
  for (const ChannelBase* c : channels_) {
    os << "channel " << c->name() << ": " << c->occupancy() << "/" << c->capacity();
    if (!c->empty()) os << ", front ready at cycle " << c->front_ready_cycle();
    os << "\n";
  }
  return os.str();
}

void Kernel::trace_vcd(std::ostream& out, std::uint64_t from, std::uint64_t to) {
  if (to < from) throw std::runtime_error("VCD window ends before it starts");
  tracer_ = std::make_unique<VcdTracer>(out, from, to);
  trace_from_ = from;
}

void Kernel::finish_trace() {
  if (tracer_) tracer_->finish(cycle_);
}

}  // namespace saarcor::hw
