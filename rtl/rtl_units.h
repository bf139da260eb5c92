// The Verilated unit datapaths (rtl/intersection_unit.sv, transform_unit.sv, traversal_unit.sv;
// fp24, nearest even, subnormals flushed, the cycle model's default latencies) driven with unit
// vector inputs (docs/unit-vectors.md), one transaction per cycle.
#pragma once

#include <cstdint>
#include <vector>

#include "units/unit_vectors.h"

namespace saarcor::rtl {

// The intersection unit's acceptance inputs (units/datapath.h accepts): the candidate's instance
// and triangle and the ray's closest hit so far. The default is a ray without a hit (t = +inf,
// ids memif::kNone): then accept = inside.
struct AcceptInputs {
  std::uint32_t instance = 0;
  std::uint32_t triangle = 0;
  std::uint32_t best_t = 0x7F0000;  // fp24 +inf
  std::uint32_t best_instance = 0xFFFFFFFFu;
  std::uint32_t best_triangle = 0xFFFFFFFFu;
};

struct RunOptions {
  int bubble_one_in = 0;  // > 0: about one cycle in this many issues nothing (random inputs)
  std::uint64_t seed = 1;
};

struct RtlRun {
  // Per transaction, the vector outputs in the file's order; the intersection unit appends
  // `accept` (a sixth field).
  std::vector<std::vector<std::uint32_t>> outputs;
  int latency_min = 0;  // cycles from a transaction's input to its output, over all of them
  int latency_max = 0;
  std::uint64_t cycles = 0;         // simulated clock cycles
  std::uint64_t stray_outputs = 0;  // valid outputs beyond the transactions issued (must be 0)
};

// Runs the inputs (vector_inputs(unit) fields each) through the unit's RTL. `accept` (intersection
// only) is empty or one per input. Throws std::runtime_error for a wrong field count or when the
// pipeline stops delivering.
RtlRun run_unit(units::VectorUnit unit, const std::vector<std::vector<std::uint32_t>>& inputs,
                const RunOptions& options = {}, const std::vector<AcceptInputs>& accept = {});

}  // namespace saarcor::rtl
