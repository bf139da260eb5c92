// Ray source and hit sink of the DynRTP (paper section 3.1: the RGC schedules packets to free
// threads, path a; path g returns the final hits to the RGS; DESIGN.md sections 5 and 7; DIGEST
// D24, D25). For this model the RGS phases take one cycle each and read no memory.
#include "units/dynrtc_units.h"

namespace saarcor::units {

RaySource::RaySource(hw::Kernel& k, std::string name, ThreadTable& t, int depth)
    : CycleUnit(k, std::move(name), UnitId::kRgs, t, depth, nullptr),
      free_list_(t.size()),
      free_(t.size()),
      packets_(t.packets()) {
  has_extra_ = true;
  for (int i = 0; i < t.size(); ++i)
    free_list_.push_back(static_cast<ThreadToken>(i));
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

// Admission: the next primary packet goes to the oldest free thread, on path a.
int RaySource::extra() {
  if (free_list_.empty() || next_packet_ >= packets_) return 0;
  ThreadPath* a = outputs_[unit_index(UnitId::kTransformation)];
  if (!a->can_push()) return 0;
  const ThreadToken t = free_list_.front();
  free_list_.pop_front();
  --free_;
  threads_.start_primary(t, next_packet_++);
  a->push(t);
  ++*admitted_;
  return 1;
}

std::uint64_t RaySource::extra_wakeup(std::uint64_t now) const {
  return free_list_.empty() || next_packet_ >= packets_ ? hw::kNever : now + 1;
}

}  // namespace saarcor::units
