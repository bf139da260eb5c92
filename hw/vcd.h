// VCD tracer (docs/hw.md; IEEE 1364-2005 section 18, the four-state VCD format that
// GTKWave reads). Traces per module `busy` and `stall` and per channel `valid`, `ready` and
// `occupancy` over a window of cycles; one VCD time unit is one clock cycle. Dotted names become
// nested $scope modules, so `dynrtp0.traversal` appears as dynrtp0 > traversal in GTKWave.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

namespace saarcor::hw {

class Module;
class ChannelBase;

class VcdTracer {
 public:
  VcdTracer(std::ostream& out, std::uint64_t from, std::uint64_t to);
  // Called by the kernel after evaluate, before commit, for every evaluated cycle.
  void sample(std::uint64_t cycle, const std::vector<Module*>& modules,
              const std::vector<ChannelBase*>& channels);
  // Writes the final timestamp (the cycle after the window or after the last sample).
  void finish(std::uint64_t cycle);

 private:
  struct Signal {
    std::string scope;  // dotted
    std::string name;
    int width;
    std::string id;
    std::uint64_t last;
  };
  void header(const std::vector<Module*>& modules, const std::vector<ChannelBase*>& channels);
  void value_change(Signal& s, std::uint64_t v, bool force);

  std::ostream& out_;
  std::uint64_t from_, to_;
  bool started_ = false, finished_ = false;
  std::uint64_t last_time_ = 0;
  std::vector<Signal> signals_;
};

// Identifier code of signal k: printable ASCII 33..126, base 94 (VCD identifier_code).
std::string vcd_identifier(std::size_t k);

}  // namespace saarcor::hw
