// What a configuration costs (docs/cost.md): FP units and internal memory per unit, from the
// configuration keys; Table 1's designs from their algorithms' operations.
#include "units/cost.h"

#include <algorithm>
#include <stdexcept>

#include "fixedfloat/format.h"
#include "fixedfloat/pack.h"
#include "memif/image_format.h"

namespace saarcor::units {
namespace {

// Bits that tell n values apart (at least 1).
int index_bits(std::int64_t n) {
  int b = 1;
  while ((std::int64_t{1} << b) < n)
    ++b;
  return b;
}
// Bits of a counter 0..n.
int counter_bits(std::int64_t n) {
  return index_bits(n + 1);
}

// Widths of the node format's leaf count (word0 = 3 | count << 2) and of the frame buffer's
// pixel coordinates (its 1M-word bank holds 1024 x 1024 pixels at most).
constexpr int kLeafCountBits = 30;
constexpr int kPixelCoordBits = 10;
// The RGS's colour accumulators: weight (8 bits) x colour (8 bits) per channel, and the weight.
constexpr int kAccumulatorBits = 3 * 16 + 8;
// Ray kind (primary, shadow, secondary) and depth (the frame register max_depth, 2 bits for 3).
constexpr int kRayKindBits = 2, kDepthBits = 2;
// A material index (16 bits, memif::ShadingRecord) and its record (kMaterialWords words).
constexpr int kMaterialIndexBits = 16;
// The sign groups of D27: the current group's sign pattern (3 bits) and the groups left (8).
constexpr int kSignGroupBits = 3 + 8;
// The clip's next face (0..5).
constexpr int kClipFaceBits = 3;

struct Shape {
  CostWidths w;
  int threads, lanes, stack;
};

MemoryItem per_thread(const Shape& s, std::string what, std::string kind, std::int64_t bits,
                      int ports = 1) {
  return {std::move(what), std::move(kind), bits, s.threads, ports};
}

UnitCost traversal_cost(const CycleParams& p, const Shape& s) {
  const int f = s.w.fp, n = s.lanes;
  UnitCost u{"traversal", "Traversal", {}, {}, {}};
  const int faces = p.clip_faces_per_step;
  // Node step: per lane 1 add and 1 div (d = (split - O) / D) and 3 cmp (d < tn, tf < d,
  // t_best < tn; D33); a clip step divides for `faces` box faces per lane (D29).
  u.fp.add = n * faces;
  u.fp.div = n * faces;
  int cmp = 3 * n;
  // Clip steps, as TraversalStep::clip counts them: per lane and face 1 cmp, the last face 1 more,
  // the first step of an exit-only clip 2 more (origins against the box).
  for (int stride : {1, p.clip_exit_only ? 2 : 1}) {
    for (int face = stride - 1; face < 6;) {
      const int left = (6 - face + stride - 1) / stride;
      const int k = std::min(left, faces);
      const bool first = face == stride - 1, last = k == left;
      cmp = std::max(cmp, k * n + (last ? n : 0) + (stride == 2 && first ? 2 * n : 0));
      face += stride * k;
    }
  }
  u.fp.cmp = cmp;
  // Ray data arrive on path b from the transformation unit while the steps read: dual-ported.
  u.memory.push_back(per_thread(s, "world ray per lane (origin, direction)", "ray data",
                                std::int64_t{6} * f * n, 2));
  u.memory.push_back(per_thread(s, "current level's ray per lane (world or object space)",
                                "ray data", std::int64_t{6} * f * n, 2));
  u.memory.push_back(
      per_thread(s, "node segment (tn, tf) per lane", "t-intervals", std::int64_t{2} * f * n));
  u.memory.push_back(per_thread(s, "the level's clipped segment per lane", "t-intervals",
                                std::int64_t{2} * f * n));
  // Written on path f by the intersection unit, read by every node step: dual-ported.
  u.memory.push_back(
      per_thread(s, "closest hit t_best per lane", "t-intervals", std::int64_t{f} * n, 2));
  u.memory.push_back(per_thread(s, "object box of the clip (rows 4-5), from the row cache",
                                "ray data", std::int64_t{6} * f, 2));
  u.memory.push_back(per_thread(
      s, std::to_string(s.stack) + " stack entries: node, lane mask, each lane's (tn, tf)",
      "stacks", std::int64_t{s.stack} * (s.w.node + n + 2 * f * n)));
  u.memory.push_back(per_thread(s, "stack pointer, the top level's stack base", "thread state",
                                2 * counter_bits(s.stack)));
  u.memory.push_back(per_thread(s, "node, lane mask, level, sign group, clip face", "thread state",
                                s.w.node + n + 1 + kSignGroupBits + kClipFaceBits));
  u.memory.push_back(
      {"frame registers: top-level root, scene box", "global state", s.w.node + 6 * f, 1, 1});
  return u;
}

UnitCost list_cost(const CycleParams& p, const Shape& s) {
  UnitCost u{"list", "Mailboxed List", {}, {}, {}};
  // Ids are integers: the mailbox compares no floats.
  const int n = s.lanes;
  u.memory.push_back(per_thread(
      s, std::to_string(p.mailbox) + " object mailbox entries (instance id, lane mask), FIFO",
      "mailboxes", std::int64_t{p.mailbox} * (s.w.instance + n) + 2 * counter_bits(p.mailbox)));
  u.memory.push_back(
      per_thread(s,
                 std::to_string(p.triangle_mailbox) +
                     " triangle mailbox entries (triangle id, lane mask), FIFO (D28)",
                 "mailboxes",
                 std::int64_t{p.triangle_mailbox} * (s.w.triangle + n) +
                     2 * counter_bits(p.triangle_mailbox)));
  u.memory.push_back(per_thread(s, "list cursors: the leaf's and the saved top-level leaf's",
                                "thread state", 2 * (s.w.list + kLeafCountBits)));
  u.memory.push_back(per_thread(
      s, "object entered: instance id, header row (bottom root, triangle rows, shading records)",
      "thread state",
      s.w.instance + s.w.node + s.w.row +
          index_bits(memif::kDefaultBankWords / memif::kShadingRecordWords)));
  u.memory.push_back(per_thread(s, "lanes the current entry goes on with", "thread state", n));
  return u;
}

UnitCost transformation_cost(const Shape& s) {
  const int f = s.w.fp, n = s.lanes;
  // One 3x3 matrix-vector product plus vector add per cycle (paper 2.3, D5).
  UnitCost u{"transformation", "Transformation", transformation_algorithm().units(), {}, {}};
  // Rows arrive from the row cache (or T from the RGS) while the unit reads another thread's.
  u.memory.push_back(
      per_thread(s, "matrix applied (3 rows of 4)", "matrices", std::int64_t{12} * f, 2));
  u.memory.push_back(per_thread(s, "initial rays R' per lane from the RGS (path a)", "ray data",
                                std::int64_t{6} * f * n, 2));
  u.memory.push_back(per_thread(s, "unit-triangle rays per lane for the intersection (path e)",
                                "ray data", std::int64_t{6} * f * n, 2));
  u.memory.push_back(per_thread(s, "shared-origin flag, step of the packet", "thread state",
                                1 + counter_bits(2 * n)));
  return u;
}

UnitCost intersection_cost() {
  // One ray per cycle on the transformation unit's unit-triangle rays; hits go on path f. Its
  // only storage is its pipeline.
  return {"intersection", "Intersection", unit_triangle_algorithm().units(), {}, {}};
}

void add_cache(UnitCost& u, const CycleParams& p, const Shape& s, CacheUnit c, int index,
               int item_bits) {
  const auto& cc = p.cache[static_cast<int>(c)];
  const std::string name = cache_unit_name(c);
  const int sets_bits = index_bits(cc.items / cc.ways);
  const int tag = std::max(0, index - sets_bits);
  const int label = index_bits(s.threads);
  u.memory.push_back({name + " cache data (" + std::to_string(item_bits) + "-bit items)",
                      "cache data", item_bits, cc.items, 1});
  u.memory.push_back({name + " cache tags and valid bits", "cache tags", tag + 1, cc.items, 1});
  if (cc.ways > 1)
    u.memory.push_back({name + " cache LRU ages", "cache tags", index_bits(cc.ways), cc.items, 1});
  // MSHRs: item, line, state, the fill's words, and the merged requests' labels (D20).
  u.memory.push_back({name + " cache outstanding misses (item, line, fill, merged labels)",
                      "cache misses",
                      index + index_bits(cc.items) + 2 + item_bits + p.cache_merge_targets * label,
                      p.cache_misses, 1});
  u.memory.push_back({name + " cache request queue (item, label)", "cache misses", index + label,
                      p.cache_request_queue, 1});
}

UnitCost caches_cost(const CycleParams& p, const Shape& s) {
  // The cache serves one lookup or one fill per cycle (fills first, memif/cache.h): one port.
  UnitCost u{"caches", "DynRTC-Cache", {}, {}, {}};
  const int row_bits = 32 * ff::row_words(ff::kFp24);
  add_cache(u, p, s, CacheUnit::kTraversal, s.w.node, 64);
  add_cache(u, p, s, CacheUnit::kList, s.w.list, 32);
  add_cache(u, p, s, CacheUnit::kTransformation, s.w.row, row_bits);
  return u;
}

UnitCost shader_cost(const CostParams& cp, const Shape& s) {
  const int f = s.w.fp, n = s.lanes;
  UnitCost u{"shader", "Shader", {}, {}, {}};
  // The RGS FP helper (D10): the cosines' mul, sqrt, div and k + k; one operator of each kind,
  // sequenced by the RGS's phases.
  u.fp = {1, 1, 1, 0, 1};
  // Written on path f/g by the intersection and traversal units, read by the RGS: dual-ported.
  u.memory.push_back(per_thread(s, "hit record per lane: u, v, D'z, instance, triangle",
                                "hit records",
                                std::int64_t{n} * (3 * f + s.w.instance + s.w.triangle), 2));
  u.memory.push_back(per_thread(s, "colour accumulator and ray weight per lane", "shader state",
                                std::int64_t{n} * kAccumulatorBits));
  u.memory.push_back(per_thread(s, "material register (index, record; D35)", "shader state",
                                kMaterialIndexBits + 32 * memif::kMaterialWords));
  u.memory.push_back(per_thread(s, "packet: pixel x, y, ray kind, depth", "thread state",
                                2 * kPixelCoordBits + kRayKindBits + kDepthBits));
  u.memory.push_back({"light table: position, RGB8 (" + std::to_string(cp.lights) + " lights)",
                      "lights", 3 * f + 24, cp.lights, 1});
  // FrameRegisters: camera, epsilon, image size, region bases and counts, colours, depth, bank.
  const CostWidths& w = s.w;
  const int bank = index_bits(memif::kDefaultBankWords);
  u.memory.push_back({"frame registers: camera, epsilon, sizes, bases, colours", "global state",
                      13 * f + 2 * 16 + w.row + w.instance + 3 * bank + 16 + 2 * 24 + 8 + 1, 1, 1});
  return u;
}

}  // namespace

FpUnits& FpUnits::operator+=(const FpUnits& o) {
  add += o.add;
  mul += o.mul;
  div += o.div;
  cmp += o.cmp;
  sqrt += o.sqrt;
  return *this;
}
FpUnits operator+(FpUnits a, const FpUnits& b) {
  return a += b;
}
FpUnits operator*(FpUnits a, int k) {
  return {a.add * k, a.mul * k, a.div * k, a.cmp * k, a.sqrt * k};
}

// Virtex-II figures of one fp24 operator (rtl/fp_*.sv at their defaults: nearest even, flush, the
// cycle model's latencies), measured with yosys 0.23 by
//   RTL_SYNTH=xc2v rtl/synth.sh fp_add fp_mul fp_div fp_cmp
// (synth_xilinx -family xc2v -flatten; LUT1-LUT4 counted, carry and MUXF cells not; docs/rtl.md
// "Synthesis"). rtl/ has no square root: the RGS helper's one is counted at the divider's figure,
// the digit recurrence of a square root having the divider's shape (one root bit per step).
const std::vector<OperatorArea>& operator_areas() {
  static const std::vector<OperatorArea> table = {
      {"add", 728, 0, "rtl/fp_add.sv, 3 stages"},
      {"mul", 759, 1, "rtl/fp_mul.sv, 3 stages"},
      {"div", 1504, 0, "rtl/fp_div.sv, 8 stages"},
      {"cmp", 96, 0, "rtl/fp_cmp.sv (lt, le, eq), 1 stage"},
      {"sqrt", 1504, 0, "no RTL: the divider's figure"},
  };
  return table;
}

AreaEstimate& AreaEstimate::operator+=(const AreaEstimate& o) {
  luts += o.luts;
  mult18x18 += o.mult18x18;
  block_rams += o.block_rams;
  return *this;
}
AreaEstimate operator*(AreaEstimate a, int k) {
  return {a.luts * k, a.mult18x18 * k, a.block_rams * k};
}

AreaEstimate fp_area(const FpUnits& f) {
  const int counts[] = {f.add, f.mul, f.div, f.cmp, f.sqrt};
  AreaEstimate a;
  for (std::size_t i = 0; i < std::size(counts); ++i) {
    a.luts += std::int64_t{counts[i]} * operator_areas()[i].luts;
    a.mult18x18 += counts[i] * operator_areas()[i].mult18x18;
  }
  return a;
}

std::int64_t UnitCost::block_ram_bits() const {
  std::int64_t b = 0;
  for (const MemoryItem& m : memory)
    if (m.kind != "global state" && m.kind != "cache misses") b += m.bits_each * m.count;
  return b;
}

int block_rams(const UnitCost& u) {
  return static_cast<int>((u.block_ram_bits() + kBlockRamBits - 1) / kBlockRamBits);
}

std::int64_t UnitCost::memory_bits() const {
  std::int64_t b = 0;
  for (const MemoryItem& m : memory)
    b += m.bits();
  return b;
}

CostWidths cost_widths() {
  // Scene data: three banks of kDefaultBankWords words; item sizes of memif/image_format.h.
  const std::int64_t scene = std::int64_t{memif::kSceneBanks} * memif::kDefaultBankWords;
  const std::int64_t rows = scene / ff::row_words(ff::kFp24);
  CostWidths w;
  w.fp = ff::kFp24.bits();
  w.node = index_bits(scene / 2);
  w.list = index_bits(scene);
  w.row = index_bits(rows);
  w.instance = index_bits(rows / memif::kInstanceRows);
  w.triangle = index_bits(rows / memif::kTriangleRows);
  return w;
}

CostParams cost_preset(const std::string& name) {
  CostParams p;
  p.cycle = cycle_preset(name);
  // Table 2: "parameters for 8 light-sources"; the prototype: "support of 256 light sources".
  p.lights = name == "table2" ? 8 : 256;
  return p;
}

void apply_cost_setting(CostParams& params, const std::string& key_value) {
  const auto eq = key_value.find('=');
  if (eq != std::string::npos && key_value.substr(0, eq) == "lights") {
    const std::string text = key_value.substr(eq + 1);
    std::size_t used = 0;
    long v = -1;
    try {
      v = std::stol(text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (text.empty() || used != text.size() || v < 0 || v > kMaxCostLights)
      throw std::runtime_error("bad --set lights=" + text + ": expected 0.." +
                               std::to_string(kMaxCostLights) + " lights");
    params.lights = static_cast<int>(v);
    return;
  }
  apply_cycle_setting(params.cycle, key_value);
}

void check_cost_params(const CostParams& params) {
  check_cycle_params(params.cycle);
  if (params.lights < 0 || params.lights > kMaxCostLights)
    throw std::runtime_error("bad lights=" + std::to_string(params.lights) + ": expected 0.." +
                             std::to_string(kMaxCostLights));
}

ConfigurationCost configuration_cost(const CostParams& params) {
  check_cost_params(params);
  const CycleParams& p = params.cycle;
  const Shape s{cost_widths(), p.threads, p.packet, p.stack};
  ConfigurationCost c;
  c.pipelines = p.pipelines;
  c.clock_mhz = p.clock_mhz;
  c.units = {traversal_cost(p, s), list_cost(p, s),   transformation_cost(s),
             intersection_cost(),  caches_cost(p, s), shader_cost(params, s)};
  for (UnitCost& u : c.units) {
    u.area = fp_area(u.fp);
    u.area.block_rams = block_rams(u);
    c.fp_per_pipeline += u.fp;
    c.memory_bits_per_pipeline += u.memory_bits();
    c.area_per_pipeline += u.area;
  }
  c.fp_total = c.fp_per_pipeline * p.pipelines;
  c.area_total = c.area_per_pipeline * p.pipelines;
  c.memory_bits_total = c.memory_bits_per_pipeline * p.pipelines;
  c.flops = static_cast<double>(c.fp_total.total()) * p.clock_mhz * 1e6;
  return c;
}

// ---- Table 1 ------------------------------------------------------------------------------

FpUnits Algorithm::units() const {
  FpUnits u;
  for (const OpLine& l : ops) {
    int* slot = l.op == FpOp::kAdd   ? &u.add
                : l.op == FpOp::kMul ? &u.mul
                : l.op == FpOp::kDiv ? &u.div
                                     : &u.cmp;
    *slot += l.count;
  }
  return u;
}

const Algorithm& transformation_algorithm() {
  static const Algorithm a{"T",
                           "transformation unit: (m_r0 x + m_r1 y) + (m_r2 z + t_r), r = 0..2 (D5)",
                           {{"m_r0 x, m_r1 y, m_r2 z for the three rows", FpOp::kMul, 9},
                            {"m_r0 x + m_r1 y and m_r2 z + t_r for the three rows", FpOp::kAdd, 6},
                            {"the two sums added, three rows", FpOp::kAdd, 3}}};
  return a;
}

const Algorithm& unit_triangle_algorithm() {
  static const Algorithm a{
      "I",
      "unit-triangle test (paper 2.1.2) on the transformed ray; compares are bit tests (D13)",
      {{"t = -O'z / D'z (the negation is a sign flip)", FpOp::kDiv, 1},
       {"t D'x, t D'y", FpOp::kMul, 2},
       {"u = O'x + t D'x, v = O'y + t D'y", FpOp::kAdd, 2},
       {"u + v (against 1 as an encoding compare)", FpOp::kAdd, 1}}};
  return a;
}

const Algorithm& wald_algorithm() {
  static const Algorithm a{
      "I_w",
      "Wald's projection test [Wal04]: triangle data n_u, n_v, n_d, b_nu, b_nv, b_d, c_nu, c_nv, "
      "c_d, axis k; compares as bit and encoding tests (D13's rule)",
      {{"n_u D_u, n_v D_v", FpOp::kMul, 2},
       {"D_k + n_u D_u + n_v D_v", FpOp::kAdd, 2},
       {"nd = 1 / (D_k + n_u D_u + n_v D_v)", FpOp::kDiv, 1},
       {"n_u O_u, n_v O_v", FpOp::kMul, 2},
       {"n_d - O_k - n_u O_u - n_v O_v", FpOp::kAdd, 3},
       {"f = (n_d - ...) nd", FpOp::kMul, 1},
       {"f D_u, f D_v", FpOp::kMul, 2},
       {"h_u = O_u + f D_u, h_v = O_v + f D_v", FpOp::kAdd, 2},
       {"h_u b_nu, h_v b_nv", FpOp::kMul, 2},
       {"lambda = h_u b_nu + h_v b_nv + b_d", FpOp::kAdd, 2},
       {"h_u c_nu, h_v c_nv", FpOp::kMul, 2},
       {"mu = h_u c_nu + h_v c_nv + c_d", FpOp::kAdd, 2},
       {"lambda + mu (against 1)", FpOp::kAdd, 1}}};
  return a;
}

const Algorithm& plucker_algorithm() {
  static const Algorithm a{
      "I_p",
      "Plucker test [Eri97]: triangle data the three edges' Plucker coordinates, the normal N "
      "and d = N.A; side signs and the t range as bit and encoding tests (D13's rule)",
      {{"the ray's moment D x O", FpOp::kMul, 6},
       {"the ray's moment D x O", FpOp::kAdd, 3},
       {"three permuted inner products ray . edge (6 mul each)", FpOp::kMul, 18},
       {"three permuted inner products ray . edge (5 add each)", FpOp::kAdd, 15},
       {"N.O and N.D", FpOp::kMul, 6},
       {"N.O and N.D", FpOp::kAdd, 4},
       {"d - N.O", FpOp::kAdd, 1},
       {"t = (d - N.O) / (N.D)", FpOp::kDiv, 1},
       {"s0 + s1 + s2 (the barycentrics' denominator)", FpOp::kAdd, 2},
       {"1 / (s0 + s1 + s2)", FpOp::kDiv, 1},
       {"u = s1 / (...), v = s2 / (...)", FpOp::kMul, 2}}};
  return a;
}

const Algorithm& shading_algorithm() {
  static const Algorithm a{
      "S",
      "shading unit computing rays in floating point: a primary ray's direction x Cr + y Cu + Cd "
      "(paper 2.2.2); a shadow ray's O + t D - L (3 mul, 6 add) runs on the same operators",
      {{"x Cr, y Cu (three components each)", FpOp::kMul, 6},
       {"x Cr + y Cu, + Cd (three components)", FpOp::kAdd, 6}}};
  return a;
}

Table1 table1(const CostParams& params) {
  const ConfigurationCost c = configuration_cost(params);
  Table1 t;
  t.traversal = c.units[0].fp;
  const FpUnits tr = transformation_algorithm().units(), in = unit_triangle_algorithm().units(),
                iw = wald_algorithm().units(), ip = plucker_algorithm().units(),
                sh = shading_algorithm().units();
  auto design = [&](const char* key, const char* name, const char* parts, const FpUnits& u) {
    t.designs.push_back({key, name, parts, u, u + t.traversal});
  };
  design("dyn1", "RT_Dyn1", "T + I + K", tr + in);
  design("static", "RT_static", "S + I_w + K", sh + iw);
  design("dyn2", "RT_Dyn2", "T + S + I_w + K", tr + sh + iw);
  design("dyn3", "RT_Dyn3", "T + S + I_p + K", tr + sh + ip);
  const Table1Design& d1 = t.designs[0];
  auto ratio = [&](const char* key, const char* name, const Table1Design& d, double pw, double pf) {
    t.ratios.push_back(
        {key, name, static_cast<double>(d1.without_traversal.total()) / d.without_traversal.total(),
         static_cast<double>(d1.full.total()) / d.full.total(), pw, pf});
  };
  ratio("dyn1_over_static", "RT_Dyn1 / RT_static", t.designs[1], 0.66, 0.75);
  ratio("dyn1_over_dyn2", "RT_Dyn1 / RT_Dyn2", t.designs[2], 0.46, 0.57);
  ratio("dyn1_over_dyn3", "RT_Dyn1 / RT_Dyn3", t.designs[3], 0.23, 0.32);
  return t;
}

const std::vector<PaperTable2Row>& paper_table2() {
  static const std::vector<PaperTable2Row> rows = {
      {"traversal", "Traversal", 4, 0, 4, 13, 44.5},
      {"list", "Mailboxed List", 0, 0, 0, 0, 0.8},
      {"transformation", "Transformation", 9, 9, 0, 0, 9.3},
      {"intersection", "Intersection", 3, 2, 1, 0, 0.0},
      {"caches", "DynRTC-Cache", 0, 0, 0, 0, 15.6},
      {"shader", "Shader", 0, 0, 0, 0, 4.8},
      {"total", "Total", 16, 11, 5, 13, 75.0},
  };
  return rows;
}

const PaperTable2Row& paper_table2_row(const std::string& key) {
  for (const PaperTable2Row& r : paper_table2())
    if (key == r.key) return r;
  throw std::logic_error("no Table 2 row " + key);
}

}  // namespace saarcor::units
