// A Verilated DynRTP unit as the lockstep harness drives it (rtl/lockstep.h): boundary records
// in, boundary records out (units/boundary.h), one clock cycle per call. Each unit's adapter
// turns the model's input events into its ports and its ports into output events (the list
// unit's: rtl/list_rtl.h make_list_unit_rtl).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "units/boundary.h"

namespace saarcor::rtl {

class UnitRtl {
 public:
  virtual ~UnitRtl() = default;
  virtual units::UnitId unit() const = 0;
  // A unit's cache (its events are BoundaryEvent::cache), named in the lockstep's reports.
  virtual bool cache() const { return false; }
  virtual std::string name() const { return units::unit_name(unit()); }
  // Resets the RTL; the next cycle() is cycle 0.
  virtual void reset() = 0;
  // Clock cycle `cycle`: `inputs` are the model's events of that cycle on the unit's input ports
  // (input paths, side band, cache response, cache back-pressure); the RTL's cache requests and
  // outputs of the cycle are appended to `outputs`, in port order. Throws std::logic_error for
  // inputs the RTL has no port for (two threads on one path in a cycle, a path it lacks).
  virtual void cycle(std::uint64_t cycle, const std::vector<units::BoundaryEvent>& inputs,
                     std::vector<units::BoundaryEvent>& outputs) = 0;
  // VCD of the cycles from now until stop_trace() into `path`.
  virtual void start_trace(const std::string& path) = 0;
  virtual void stop_trace() = 0;
};

// A port event of `unit` appended to an adapter's outputs.
inline units::BoundaryEvent& add_event(std::vector<units::BoundaryEvent>& events,
                                       std::uint64_t cycle, units::UnitId unit,
                                       units::BoundaryPort port, std::uint32_t thread) {
  units::BoundaryEvent& e = events.emplace_back();
  e.cycle = cycle;
  e.unit = unit;
  e.port = port;
  e.thread = thread;
  return e;
}

// A cache request leaving `unit`: the item, and the unit as the request's label.
inline void add_cache_request(std::vector<units::BoundaryEvent>& events, std::uint64_t cycle,
                              units::UnitId unit, std::uint64_t item, std::uint32_t thread) {
  units::BoundaryEvent& e =
      add_event(events, cycle, unit, units::BoundaryPort::kCacheRequest, thread);
  e.fields = 3;
  e.names = units::kCacheRequestFields;
  e.field[0] = item;
  e.field[1] = static_cast<std::uint64_t>(units::unit_index(unit));
  e.field[2] = thread;
}

}  // namespace saarcor::rtl
