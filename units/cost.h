// What a configuration costs (paper section 4.3, Tables 1 and 2; docs/cost.md): per unit of one
// DynRTP the floating-point units (adders, multipliers, dividers, comparators) and the internal
// memory broken into what it holds, derived from the configuration keys (units/cycle_params.h),
// never typed in; the chip's total and its FLOPs at the clock; and Table 1's four ray tracer
// designs, each counted from its algorithm's operations written out below.
//
// Counting rules (docs/cost.md gives every rule's source):
//  - FP units: one operator per operation of a fully pipelined datapath issuing one step per cycle;
//    a unit whose steps differ (a node step, a clip step) needs the most any one step issues.
//  - Sign and zero tests and compares of encodings known non-negative are bit and integer tests,
//    not FP comparators (D13).
//  - Memory: storage the hardware must keep between cycles (per-thread state, stacks, mailboxes,
//    caches, tables, registers); the datapaths' pipeline registers are logic, not memory. A memory
//    one unit writes while another reads it in the same cycle is dual-ported and counted twice,
//    as the paper counts ("dual port memory bits are counted as 2 bits").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "units/cycle_params.h"

namespace saarcor::units {

// A configuration for the cost model: the cycle model's keys and the light table's capacity (the
// RGS's on-chip light table: Table 2 counts "parameters for 8 light-sources", the prototype
// supports 256).
struct CostParams {
  CycleParams cycle;
  int lights = 256;
};
inline constexpr int kMaxCostLights = 65536;

// The cycle model's preset with its light table: `table2` 8 lights (Table 2's), the others 256
// (the prototype's). Throws as cycle_preset for an unknown name.
CostParams cost_preset(const std::string& name);
// Applies "KEY=VALUE": `lights` or any cycle model key; throws std::runtime_error naming the key.
void apply_cost_setting(CostParams& params, const std::string& key_value);
// check_cycle_params and the light table; throws naming the key.
void check_cost_params(const CostParams& params);

struct FpUnits {
  int add = 0, mul = 0, div = 0, cmp = 0;
  int sqrt = 0;  // only the RGS FP helper has one (D10); Table 2 has no column for it
  int total() const { return add + mul + div + cmp + sqrt; }
  FpUnits& operator+=(const FpUnits& o);
  friend bool operator==(const FpUnits&, const FpUnits&) = default;
};
FpUnits operator+(FpUnits a, const FpUnits& b);
FpUnits operator*(FpUnits a, int k);

// One memory of a unit: `count` copies (threads, cache lines, lights) of `bits_each` bits, read
// and written through `ports` ports (2 = dual-ported, counted twice).
struct MemoryItem {
  std::string what;  // what it holds
  std::string kind;  // the category: "ray data", "t-intervals", "stack", ...
  std::int64_t bits_each = 0;
  std::int64_t count = 0;
  int ports = 1;
  std::int64_t bits() const { return bits_each * count * ports; }
};

// ---- area on the prototype's FPGA (a Virtex-II XC2V6000, paper 4.1) ---------------------------
inline constexpr int kXc2v6000Luts = 67584;
inline constexpr int kXc2v6000Mult18x18 = 144;
inline constexpr int kXc2v6000BlockRams = 144;
// A Virtex-II block RAM holds 18 Kbit in every shape that carries the parity bits as data (512 x
// 36, 1K x 18, 2K x 9; Xilinx UG002); it has two ports of its own, so a memory the paper counts
// twice (dual-ported) needs its bits once.
inline constexpr std::int64_t kBlockRamBits = 18 * 1024;

// What one fp24 operator of the FP unit count takes on the Virtex-II: LUTs (LUT1-LUT4) and
// MULT18X18 blocks, the synthesis figures of rtl/ (docs/rtl.md "Synthesis").
struct OperatorArea {
  const char* op;  // add, mul, div, cmp, sqrt
  int luts = 0;
  int mult18x18 = 0;
  const char* source;  // where the figure comes from
};
const std::vector<OperatorArea>& operator_areas();

// A unit's (or the chip's) area estimate: the LUTs and multipliers of its FP operators (the
// per-operator table times the FP unit counts) and the block RAMs its memories need at least.
struct AreaEstimate {
  std::int64_t luts = 0;
  int mult18x18 = 0;
  int block_rams = 0;
  AreaEstimate& operator+=(const AreaEstimate& o);
  friend bool operator==(const AreaEstimate&, const AreaEstimate&) = default;
};
AreaEstimate operator*(AreaEstimate a, int k);
// The operators' LUTs and multipliers for these FP unit counts.
AreaEstimate fp_area(const FpUnits& f);

struct UnitCost {
  std::string key;   // JSON key: traversal, list, transformation, intersection, caches, shader
  std::string name;  // the paper's row name
  FpUnits fp;
  std::vector<MemoryItem> memory;
  AreaEstimate area;  // set by configuration_cost
  std::int64_t memory_bits() const;
  double memory_kb() const { return static_cast<double>(memory_bits()) / 8192.0; }  // KB = 2^10 B
  // The bits that go into block RAM, each once: every memory but the registers (kinds "global
  // state", the frame registers, and "cache misses", the outstanding misses every lookup
  // searches at once and the short request FIFO).
  std::int64_t block_ram_bits() const;
};
// At least this many block RAMs hold the unit's RAM bits: ceil(block_ram_bits / 18 Kbit), the
// unit's memories packed densely (a lower bound; a memory's shape can waste part of a block).
int block_rams(const UnitCost& u);

struct ConfigurationCost {
  int pipelines = 1;
  double clock_mhz = 0.0;
  std::vector<UnitCost> units;  // one DynRTP, in Table 2's order
  FpUnits fp_per_pipeline;
  FpUnits fp_total;  // all DynRTPs
  std::int64_t memory_bits_per_pipeline = 0;
  std::int64_t memory_bits_total = 0;  // all DynRTPs
  double flops = 0.0;                  // every FP unit of the chip once per cycle at the clock
  AreaEstimate area_per_pipeline;      // the units' areas added
  AreaEstimate area_total;             // all DynRTPs
  double memory_kb_total() const { return static_cast<double>(memory_bits_total) / 8192.0; }
};

// The cost of a configuration (checked first: throws naming the key).
ConfigurationCost configuration_cost(const CostParams& params);

// Widths the memories are counted with, from the memory image (memif/image_format.h) at the
// prototype's 4 MB banks and the fp24 format.
struct CostWidths {
  int fp = 0;        // one float
  int node = 0;      // kd-node index
  int list = 0;      // list-entry index
  int row = 0;       // matrix-row index
  int instance = 0;  // instance id
  int triangle = 0;  // triangle id
};
CostWidths cost_widths();

// ---- Table 1 ------------------------------------------------------------------------------
enum class FpOp { kAdd, kMul, kDiv, kCmp };
// One line of an algorithm: `count` operations of one kind, what they compute.
struct OpLine {
  const char* what;
  FpOp op;
  int count;
};
struct Algorithm {
  const char* key;   // "T", "I", "I_w", "I_p", "S", "K"
  const char* name;  // what it is
  std::vector<OpLine> ops;
  FpUnits units() const;  // one unit per operation
};
// The per-ray datapaths Table 1 compares (docs/cost.md writes each out):
const Algorithm& transformation_algorithm();  // T: 3x3 matrix-vector product plus vector add
const Algorithm& unit_triangle_algorithm();   // I: the paper's unit-triangle test (2.1.2)
const Algorithm& wald_algorithm();            // I_w: Wald's projection test [Wal04]
const Algorithm& plucker_algorithm();         // I_p: the Plucker test [Eri97]
const Algorithm& shading_algorithm();         // S: primary and shadow rays in floating point

struct Table1Design {
  std::string key;   // dyn1, static, dyn2, dyn3
  std::string name;  // RT_Dyn1 ...
  std::string parts;
  FpUnits without_traversal;
  FpUnits full;  // with the traversal unit K
};
struct Table1Ratio {
  std::string key;  // dyn1_over_static, dyn1_over_dyn2, dyn1_over_dyn3
  std::string name;
  double without_traversal = 0.0, full = 0.0;              // fractions
  double paper_without_traversal = 0.0, paper_full = 0.0;  // Table 1's
};
struct Table1 {
  FpUnits traversal;  // K of the configuration
  std::vector<Table1Design> designs;
  std::vector<Table1Ratio> ratios;
};
Table1 table1(const CostParams& params);

// ---- Table 2 as printed -----------------------------------------------------------------------
struct PaperTable2Row {
  const char* key;  // as UnitCost::key; "total"
  const char* name;
  int add, mul, div, cmp;
  double memory_kb;
};
const std::vector<PaperTable2Row>& paper_table2();
// The row with `key` (a UnitCost::key or "total"); throws std::logic_error for another key.
const PaperTable2Row& paper_table2_row(const std::string& key);
inline constexpr double kPaperFlops = 4e9;  // section 4.3: "a total of 4 billion FLOPs"

}  // namespace saarcor::units
