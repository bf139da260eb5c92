// The shared stages of the DynRTP units (docs/cycle-model.md "Units").
#include "units/cycle_unit.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace saarcor::units {

CycleUnit::CycleUnit(hw::Kernel& kernel, std::string name, UnitId id, ThreadTable& threads,
                     int depth, memif::Cache* cache)
    : hw::Module(kernel, std::move(name)),
      threads_(threads),
      id_(id),
      depth_(depth),
      cache_(cache),
      waiting_(static_cast<std::size_t>(threads.size()), 0),
      ready_(threads.size()),
      pipeline_(threads.size()) {
  // Event scheduling: a unit depends on its paths, its cache's channels and its pipeline timer.
  sleep_when_idle();
  if (cache_ != nullptr) {
    cache_requests_ = &cache_->requests();
    cache_responses_ = &cache_->responses();
    produces(*cache_requests_);
    consumes(*cache_responses_);
  }
  issued_ = &stats().counter(this->name() + ".issue_cycles", "cycles",
                             "cycles in which the unit issued a step (its usage)");
  served_ =
      &stats().counter(this->name() + ".requests", "requests", "thread-program requests served");
}

// Each step is called only when it has something to do (the tests are what the step would test
// first), in the script's order.
int CycleUnit::evaluate() {
  int progress = 0;
  if (deliver_at_ <= now()) progress += deliver();
  if (steps_left_ != 0 || chained_ || !ready_.empty()) progress += issue();
  if (cache_responses_ != nullptr && cache_responses_->can_pop()) progress += receive();
  if (fetching_) {
    progress += accept(nullptr);
  } else if (ThreadPath* from = waiting_input()) {
    progress += accept(from);
  }
  if (has_extra_) progress += extra();
  if (progress == 0 && inside_ > 0) stall();  // threads inside, all waiting for memory
  return progress;
}

int CycleUnit::deliver() {
  int moved = 0;
  while (!pipeline_.empty() && pipeline_.front().done_at <= now()) {
    if (!leave(pipeline_.front().thread)) {
      stall();
      break;
    }
    pipeline_.pop_front();
    ++moved;
  }
  deliver_at_ = pipeline_.empty() ? hw::kNever : pipeline_.front().done_at;
  return moved;
}

int CycleUnit::issue() {
  if (steps_left_ == 0) {
    ThreadToken t;
    if (chained_) {
      t = chain_thread_;
      chained_ = false;
    } else if (!ready_.empty()) {
      t = ready_.front();
      ready_.pop_front();
    } else {
      return 0;
    }
    const Request r = threads_.request(t);  // a copy: execute() replaces the table's entry
    threads_.execute(t);
    ++*served_;
    steps_left_ = r.steps < 1 ? 1 : r.steps;
    const Request& next = threads_.request(t);
    std::uint64_t done_at = 0;
    if (hold(t)) {
      // The unit keeps the thread for memory traffic and lets it leave itself (leave()); a trace
      // shows the request as issuing until it left (done_at 0, as a chain).
    } else if (next.unit == id_ && chains(r, next)) {
      chained_ = true;
      chain_thread_ = t;
    } else {
      done_at = now() + static_cast<std::uint64_t>(steps_left_ - 1 + depth_);
      if (pipeline_.empty()) deliver_at_ = done_at;  // later entries are due no earlier
      pipeline_.push_back({done_at, t});
    }
    if (observer_ != nullptr) [[unlikely]]
      observer_->issued(now(), id_, t, r, steps_left_, done_at);
  }
  --steps_left_;
  ++*issued_;
  return 1;
}

int CycleUnit::receive() {
  if (cache_responses_ == nullptr || !cache_responses_->can_pop()) return 0;
  const ThreadToken t = cache_responses_->peek().label.tag;
  if (observer_ != nullptr) [[unlikely]]
    observer_->cache_response(now(), id_, cache_responses_->peek());
  cache_responses_->drop();
  if (--waiting_[t] == 0) {
    --waiting_threads_;
    ready_.push_back(t);
    if (observer_ != nullptr) [[unlikely]]
      observer_->ready(now(), t);
  }
  return 1;
}

int CycleUnit::accept(ThreadPath* from) {
  if (!fetching_) {
    const ThreadToken t = from->pop();
    ++inside_;
    const Fetch f = fetch(threads_.request(t));
    if (observer_ != nullptr) [[unlikely]]
      observer_->accepted(now(), id_, t, f.count);
    if (f.count == 0) {
      ready_.push_back(t);
      return 1;
    }
    fetching_ = true;
    fetch_thread_ = t;
    fetch_next_ = f.first;
    fetch_left_ = f.count;
    waiting_[t] = f.count;
    ++waiting_threads_;
  }
  // One cache request per cycle (a matrix's rows go out over consecutive cycles, D32).
  if (!cache_requests_->can_push()) {
    if (observer_ != nullptr) [[unlikely]]
      observer_->cache_blocked(now(), id_);
    stall();
    return 0;
  }
  const memif::CacheRequest req{fetch_next_,
                                {static_cast<std::uint16_t>(unit_index(id_)), fetch_thread_}};
  cache_requests_->push(req);
  if (observer_ != nullptr) [[unlikely]]
    observer_->cache_request(now(), id_, req);
  ++fetch_next_;
  if (--fetch_left_ == 0) {
    fetching_ = false;
    if (observer_ != nullptr) [[unlikely]]
      observer_->fetched(now(), fetch_thread_);
  }
  return 1;
}

std::uint64_t CycleUnit::next_wakeup(std::uint64_t now) const {
  if (steps_left_ > 0 || chained_ || !ready_.empty() || fetching_) return now + 1;
  std::uint64_t t = hw::kNever;
  if (!pipeline_.empty()) t = std::max(now + 1, deliver_at_);
  if (has_extra_) t = std::min(t, extra_wakeup(now));
  return t;
}

std::string CycleUnit::dump_state() const {
  std::ostringstream s;
  s << "threads inside " << inside_ << ", waiting for the cache " << waiting_threads_ << ", ready "
    << ready_.size() << ", in the pipeline " << pipeline_.size();
  if (fetching_) s << ", fetching for thread " << fetch_thread_ << " (" << fetch_left_ << " left)";
  if (!pipeline_.empty())
    s << ", next out: thread " << pipeline_.front().thread << " at cycle "
      << pipeline_.front().done_at;
  for (std::size_t t = 0; t < waiting_.size(); ++t)
    if (waiting_[t] > 0) {
      const Request& r = threads_.request(static_cast<ThreadToken>(t));
      s << "\n  thread " << t << " waits for " << waiting_[t] << " item(s) for "
        << phase_name(r.phase) << " item " << r.item;
    }
  return s.str();
}

}  // namespace saarcor::units
