// The ray generation and shading unit with the RGC's admission (paper section 3.1: the RGC
// schedules packets to free threads, path a; path g returns the final hits to the RGS, which
// shades them, spawns secondary rays and writes the finished pixels into the frame buffer;
// docs/cycle-model.md, docs/memif.md and docs/shading.md; docs/shading.md "Shading traffic";
// decisions D24, D25).
#include <algorithm>
#include <bit>
#include <stdexcept>

#include "units/dynrtc_units.h"

namespace saarcor::units {

RaySource::RaySource(hw::Kernel& k, std::string name, ThreadTable& t, int depth,
                     RayGenerationController& rgc, int pipeline, ThreadToken first, int count,
                     RgsPorts ports)
    : CycleUnit(k, std::move(name), UnitId::kRgs, t, depth, nullptr),
      rgc_(rgc),
      pipeline_(pipeline),
      first_(first),
      count_(count),
      free_list_(count),
      free_(count),
      ports_(ports),
      held_(static_cast<std::size_t>(count)),
      reading_(count),
      shading_(count),
      writing_(count),
      leaving_(count),
      waves_(count) {
  has_extra_ = true;
  for (int i = 0; i < count; ++i)
    free_list_.push_back(first + static_cast<ThreadToken>(i));
  if (ports_.shading != nullptr) {
    produces(ports_.shading->requests);
    consumes(ports_.shading->responses);
  }
  if (ports_.frame != nullptr) produces(ports_.frame->requests);
  if (ports_.shading != nullptr && ports_.shading->lane != nullptr && ports_.lane_window != 0) {
    virtual_ = hw::CycleMarks(ports_.lane_window);
  }
  retired_ = &stats().counter(this->name() + ".packets_retired", "packets",
                              "primary packets whose thread was freed");
  admitted_ = &stats().counter(this->name() + ".packets_admitted", "packets",
                               "primary packets handed to a free thread");
  reads_ = &stats().counter(this->name() + ".shading_reads", "requests",
                            "shading-bank read requests (records, materials, texels, lights)");
  writes_ = &stats().counter(this->name() + ".frame_writes", "words",
                             "finished pixels written into the frame buffer");
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
  if (PacketCharges* c = rgc_.charges()) [[unlikely]]
    c->retire(thread, now());
}

// A request with memory accesses keeps its thread (without memory ports, as in the unit tests
// with mock neighbours, every request goes through the pipeline).
bool RaySource::hold(ThreadToken thread) {
  if (ports_.shading == nullptr || ports_.frame == nullptr) return false;
  const std::vector<RgsAccess>& access = threads_.rgs_memory(thread);
  if (access.empty()) return false;
  Held& h = held(thread);
  h.access = &access;
  h.reads = static_cast<std::size_t>(
      std::find_if(access.begin(), access.end(), [](const RgsAccess& a) { return a.write; }) -
      access.begin());
  h.next = 0;
  h.outstanding = 0;
  if (h.reads == 0)
    shade(thread, h);  // writes only: the colours are ready, shading done after the depth
  else
    reading_.push_back(thread);
  ++active_;
  return true;
}

int RaySource::extra() {
  int progress = 0;
  if (active_ != 0) progress += receive_shading() + issue_read() + write_and_leave();
  return progress + admit();
}

// Admission: in a cycle the RGC grants this pipeline, the next primary packet goes to the oldest
// free thread, on path a.
int RaySource::admit() {
  if (free_list_.empty() || !rgc_.granted(pipeline_, now()) || !rgc_.packets_left(pipeline_, now()))
    return 0;
  ThreadPath* a = outputs_[unit_index(UnitId::kTransformation)];
  if (!a->can_push()) return 0;
  const ThreadToken t = free_list_.front();
  free_list_.pop_front();
  --free_;
  const int ordinal = rgc_.take(now());
  threads_.start_primary(t, ordinal);
  if (PacketCharges* c = rgc_.charges()) [[unlikely]]
    c->admit(t, ordinal, now());
  a->push(t);
  if (observer_ != nullptr) [[unlikely]]
    observer_->queued(now(), UnitId::kTransformation, t);
  ++*admitted_;
  return 1;
}

// One shading-bank response per cycle (the port's width). A thread's wave complete: its next
// wave queues for the read port behind the reads already waiting; its last read starts its
// shading, done `depth` cycles later.
int RaySource::receive_shading() {
  ThreadToken t;
  if (memif::MemoryController::Lane* lane = ports_.shading->lane) {
    // Through a lane only a wave's last response is an event (the others were taken as they
    // became visible: marked cycles).
    if (waves_.empty() || waves_.front().last > now()) {
      return 0;
    }
    const Wave w = waves_.front();
    waves_.pop_front();
    if (static_cast<ThreadToken>(lane->pop_through(w.reads)) != w.thread) {
      throw std::logic_error(name() + ": a wave's responses out of order");
    }
    t = w.thread;
    held(t).outstanding = 1;  // its last read
  } else {
    auto& responses = ports_.shading->responses;
    if (!responses.can_pop()) {
      return 0;
    }
    t = static_cast<ThreadToken>(responses.pop().tag);
  }
  Held& h = held(t);
  if (--h.outstanding == 0) {
    if (h.next < h.reads)
      reading_.push_back(t);
    else
      shade(t, h);
  }
  return 1;
}

void RaySource::mark_virtual(std::uint64_t c) {
  if (c - virtual_from_ >= virtual_.window()) [[unlikely]] {
    beyond_window();
  }
  virtual_marked_ += virtual_.mark(c) ? 1 : 0;
}

void RaySource::beyond_window() const {
  throw std::logic_error(name() + ": a planned cycle beyond the window");
}

// A cycle in which the stepped RGS would only have pushed a planned request or taken a response
// that ends no wave: busy, not stalled (the kernel counts the stall of an idle evaluation, and of
// the cycles after it, as repeats of it).
int RaySource::evaluate() {
  const int p = CycleUnit::evaluate();
  if (virtual_marked_ != 0 && virtual_.take(now())) {
    --virtual_marked_;
    if (p == 0) {
      count_cycles(1, 0, stalled() ? 1 : 0);
    }
  }
  virtual_from_ = now() + 1;
  return p;
}

void RaySource::skipped(std::uint64_t cycles) {
  if (virtual_marked_ != 0) {
    const std::uint64_t n = virtual_.take(now() - cycles, now());
    virtual_marked_ -= n;
    count_cycles(n, 0, stalled() ? n : 0);
  }
  virtual_from_ = now();
}

std::uint64_t RaySource::issue_access(memif::MemoryController::Port& port, std::uint16_t client,
                                      ThreadToken t, Held& h, std::uint64_t at) {
  const RgsAccess& a = (*h.access)[h.next++];
  memif::MemRequest m;
  m.client = client;
  m.tag = t;
  m.bank = a.bank;
  m.words = a.words;
  m.write = a.write;
  m.offset = a.offset;
  m.data[0] = a.data;
  if (a.write) m.counted_bytes = 3;  // a pixel's RGB8: 3 bytes of the word count (D36)
  if (port.lane != nullptr) {
    return port.lane->push_at(m, at);
  }
  port.requests.push(m);
  return 0;
}

// One read per cycle on the shading port: the front thread's wave, back to back; a thread leaves
// the queue at the end of its wave (the next one waits for this one's words).
int RaySource::issue_read() {
  if (reading_.empty() || now() < read_free_at_ || !can_push(*ports_.shading)) {
    return 0;
  }
  const ThreadToken t = reading_.front();
  Held& h = held(t);
  // The wave: the reads from the next on with its wave number.
  const std::vector<RgsAccess>& access = *h.access;
  std::size_t end = h.next + 1;
  while (end < h.reads && access[end].wave == access[h.next].wave) {
    ++end;
  }
  const std::size_t first = h.next;
  std::uint64_t visible = issue_access(*ports_.shading, ports_.shading_client, t, h, now());
  memif::MemoryController::Lane* const lane = ports_.shading->lane;
  if (lane != nullptr) {
    // The rest of the wave (up to kPlan reads) in the cycles the port takes them.
    std::uint64_t last = now();
    for (int planned = 0; h.next != end && planned < kPlan; ++planned) {
      const std::uint64_t at = lane->next_push_cycle(last + 1);
      if (!lane->plannable(at)) {
        break;
      }
      mark_virtual(visible);  // a response before the wave's last
      mark_virtual(at);
      visible = issue_access(*ports_.shading, ports_.shading_client, t, h, at);
      last = at;
    }
    read_free_at_ = last + 1;
  }
  h.outstanding += static_cast<int>(h.next - first);
  *reads_ += h.next - first;
  if (h.next != end) {
    if (lane != nullptr) {
      mark_virtual(visible);
    }
    return 1;
  }
  if (lane != nullptr) {
    waves_.push_back({t, static_cast<std::uint32_t>(h.outstanding), visible});
  }
  reading_.pop_front();
  return 1;
}

// Shading done: the thread's pixels go to the frame port, one word per cycle; a thread without
// writes, or whose last write went out, leaves (or is freed) in that cycle, in order.
int RaySource::write_and_leave() {
  int progress = 0;
  while (!shading_.empty() && held(shading_.front()).due <= now()) {
    const ThreadToken t = shading_.front();
    shading_.pop_front();
    (held(t).next < held(t).access->size() ? writing_ : leaving_).push_back(t);
  }
  if (!writing_.empty() && now() >= write_free_at_ && can_push(*ports_.frame)) {
    const ThreadToken t = writing_.front();
    Held& h = held(t);
    issue_access(*ports_.frame, ports_.frame_client, t, h, now());
    ++*writes_;
    ++progress;
    if (memif::MemoryController::Lane* lane = ports_.frame->lane) {
      // The packet's writes but its last (which frees the thread: an event) pushed ahead.
      std::uint64_t last = now();
      for (int planned = 0; h.access->size() - h.next >= 2 && planned < kPlan; ++planned) {
        const std::uint64_t at = lane->next_push_cycle(last + 1);
        if (!lane->plannable(at)) {
          break;
        }
        mark_virtual(at);
        issue_access(*ports_.frame, ports_.frame_client, t, h, at);
        ++*writes_;
        last = at;
      }
      write_free_at_ = last + 1;
    }
    if (h.next == h.access->size()) {
      writing_.pop_front();
      leaving_.push_back(t);
    }
  }
  while (!leaving_.empty() && leave(leaving_.front())) {
    leaving_.pop_front();
    --active_;
    ++progress;
  }
  return progress;
}

// After a cycle without progress. A read or write waiting for its full port sleeps until the
// memory controller's pop frees a slot (the port's channel wakes the RGS then): the RGS spends
// about a third of a shaded frame's cycles waiting for its ports.
std::uint64_t RaySource::extra_wakeup(std::uint64_t now) const {
  if (!leaving_.empty()) return now + 1;
  std::uint64_t t = shading_.empty() ? hw::kNever : std::max(now + 1, held(shading_.front()).due);
  if (!reading_.empty())
    t = std::min(t, std::max({now + 1, read_free_at_, push_ready_cycle(*ports_.shading)}));
  if (!writing_.empty())
    t = std::min(t, std::max({now + 1, write_free_at_, push_ready_cycle(*ports_.frame)}));
  // A lane's response wakes no one: the RGS takes a wave's last in the cycle it becomes visible.
  if (!waves_.empty()) {
    t = std::min(t, std::max(now + 1, waves_.front().last));
  }
  if (free_list_.empty() || !rgc_.packets_left(pipeline_, now)) return t;
  return std::min(t, rgc_.next_grant(pipeline_, now));
}

}  // namespace saarcor::units
