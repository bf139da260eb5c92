// Ray source and hit sink of the DynRTP (paper section 3.1: the RGC schedules packets to free
// threads, path a; path g returns the final hits to the RGS; DESIGN.md sections 5 and 7; DIGEST
// D24, D25). For this model the RGS phases take one cycle each and read no memory.
#include "units/dynrtc_units.h"

namespace saarcor::units {

RaySource::RaySource(hw::Kernel& k, std::string name, ThreadTable& t, int depth,
                     RayGenerationController& rgc, int pipeline, ThreadToken first, int count)
    : CycleUnit(k, std::move(name), UnitId::kRgs, t, depth, nullptr),
      rgc_(rgc),
      pipeline_(pipeline),
      count_(count),
      free_list_(count),
      free_(count) {
  has_extra_ = true;
  for (int i = 0; i < count; ++i)
    free_list_.push_back(first + static_cast<ThreadToken>(i));
  retired_ = &stats().counter(this->name() + ".packets_retired", "packets",
                              "primary packets whose thread was freed");
  admitted_ = &stats().counter(this->name() + ".packets_admitted", "packets",
                               "primary packets handed to a free thread");
}

CycleUnit::Fetch RaySource::fetch(const Request&) const {
  return {};
}

bool RaySource::chains(const Request&, const Request&) const {
  return true;
}

void RaySource::retire(ThreadToken thread) {
  free_list_.push_back(thread);
  ++free_;
  ++*retired_;
}

// Admission: in a cycle the RGC grants this pipeline, the next primary packet goes to the oldest
// free thread, on path a.
int RaySource::extra() {
  if (free_list_.empty() || !rgc_.granted(pipeline_, now()) || !rgc_.packets_left(pipeline_, now()))
    return 0;
  ThreadPath* a = outputs_[unit_index(UnitId::kTransformation)];
  if (!a->can_push()) return 0;
  const ThreadToken t = free_list_.front();
  free_list_.pop_front();
  --free_;
  threads_.start_primary(t, rgc_.take(now()));
  a->push(t);
  if (observer_ != nullptr) [[unlikely]]
    observer_->queued(now(), UnitId::kTransformation, t);
  ++*admitted_;
  return 1;
}

std::uint64_t RaySource::extra_wakeup(std::uint64_t now) const {
  if (free_list_.empty() || !rgc_.packets_left(pipeline_, now)) return hw::kNever;
  return rgc_.next_grant(pipeline_, now);
}

}  // namespace saarcor::units
