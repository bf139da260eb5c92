// The units added to the DynRTP beyond Figure 2's five (units/program_types.h add_unit; README
// "adding a unit"): their names and the phases they serve, for unit_name, phase_name and
// phase_unit. Only added units are looked up here; Figure 2's own stay in the inline lists.
#include <deque>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "units/program_types.h"

namespace saarcor::units {
namespace {

constexpr int kFirstAddedUnit = static_cast<int>(UnitId::kNone) + 1;
constexpr int kFirstAddedPhase = static_cast<int>(Phase::kDone) + 1;

struct Registry {
  std::mutex mutex;
  std::deque<std::string> units;  // by id - kFirstAddedUnit (a deque: names stay put)
  struct PhaseEntry {
    std::string name;
    UnitId unit;
  };
  std::deque<PhaseEntry> phases;  // by phase - kFirstAddedPhase
};

Registry& registry() {
  static Registry r;
  return r;
}

}  // namespace

AddedUnit add_unit(const std::string& name, const std::vector<std::string>& phases) {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  for (int u = 0; u <= static_cast<int>(UnitId::kNone); ++u)
    if (name == unit_name(static_cast<UnitId>(u)))
      throw std::logic_error("add_unit: '" + name + "' is a unit of Figure 2");
  for (const std::string& n : r.units)
    if (n == name) throw std::logic_error("add_unit: a unit '" + name + "' was added before");
  if (kFirstAddedUnit + static_cast<int>(r.units.size()) >= kMaxUnits)
    throw std::logic_error("add_unit: no unit id left for '" + name + "' (kMaxUnits)");
  if (kFirstAddedPhase + static_cast<int>(r.phases.size() + phases.size()) > kMaxPhases)
    throw std::logic_error("add_unit: no phase left for '" + name + "' (kMaxPhases)");
  AddedUnit a;
  a.id = static_cast<UnitId>(kFirstAddedUnit + static_cast<int>(r.units.size()));
  a.first_phase = static_cast<Phase>(kFirstAddedPhase + static_cast<int>(r.phases.size()));
  r.units.push_back(name);
  for (const std::string& p : phases)
    r.phases.push_back({p, a.id});
  return a;
}

const char* added_unit_name(UnitId u) {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  const auto i = static_cast<std::size_t>(static_cast<int>(u) - kFirstAddedUnit);
  return static_cast<int>(u) >= kFirstAddedUnit && i < r.units.size() ? r.units[i].c_str() : "?";
}

const char* added_phase_name(Phase p) {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  const auto i = static_cast<std::size_t>(static_cast<int>(p) - kFirstAddedPhase);
  return static_cast<int>(p) >= kFirstAddedPhase && i < r.phases.size() ? r.phases[i].name.c_str()
                                                                        : "?";
}

UnitId added_phase_unit(Phase p) {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  const auto i = static_cast<std::size_t>(static_cast<int>(p) - kFirstAddedPhase);
  return static_cast<int>(p) >= kFirstAddedPhase && i < r.phases.size() ? r.phases[i].unit
                                                                        : UnitId::kNone;
}

}  // namespace saarcor::units
