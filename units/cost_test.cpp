// The cost model (units/cost.h, docs/cost.md): Table 2's configuration and two others, every
// expected figure computed by hand in the comments from the counting rules; Table 1's designs and
// ratios; the light table key and bad input.
#include "units/cost.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace saarcor::units {
namespace {

constexpr double kKb = 8192.0;

CostParams with(const std::string& preset, std::initializer_list<const char*> set) {
  CostParams p = cost_preset(preset);
  for (const char* kv : set)
    apply_cost_setting(p, kv);
  return p;
}

const UnitCost& unit(const ConfigurationCost& c, const std::string& key) {
  for (const UnitCost& u : c.units)
    if (u.key == key) return u;
  throw std::logic_error("no unit " + key);
}

const MemoryItem& item(const UnitCost& u, const std::string& what_prefix) {
  for (const MemoryItem& m : u.memory)
    if (m.what.rfind(what_prefix, 0) == 0) return m;
  throw std::logic_error("no item " + what_prefix + " in " + u.key);
}

double paper_kb(const std::string& key) {
  for (const auto& r : paper_table2())
    if (key == r.key) return r.memory_kb;
  throw std::logic_error("no paper row " + key);
}

TEST(Cost, WidthsFollowTheMemoryImage) {
  // Three banks of 2^20 words: 1.5M 2-word nodes (21 bits), 3M list entries (22), 2^20 3-word
  // rows (20), 2^20 / 6 instance records (18), 2^20 / 3 triangle matrices (19); fp24.
  const CostWidths w = cost_widths();
  EXPECT_EQ(w.fp, 24);
  EXPECT_EQ(w.node, 21);
  EXPECT_EQ(w.list, 22);
  EXPECT_EQ(w.row, 20);
  EXPECT_EQ(w.instance, 18);
  EXPECT_EQ(w.triangle, 19);
}

TEST(Cost, Table2FpUnitsAreThePapersOrADecisions) {
  const ConfigurationCost c = configuration_cost(cost_preset("table2"));
  // Traversal: per lane 1 add, 1 div and 3 cmp (d < tn, tf < d, t_best < tn): 4, 4, 12 for P = 4;
  // Table 2's 13th comparator is not needed (D13, D33).
  EXPECT_EQ(unit(c, "traversal").fp, (FpUnits{4, 0, 4, 12, 0}));
  EXPECT_EQ(unit(c, "list").fp, (FpUnits{}));
  EXPECT_EQ(unit(c, "transformation").fp, (FpUnits{9, 9, 0, 0, 0}));
  EXPECT_EQ(unit(c, "intersection").fp, (FpUnits{3, 2, 1, 0, 0}));
  EXPECT_EQ(unit(c, "caches").fp, (FpUnits{}));
  // The RGS FP helper of D10 (the cosines' mul, sqrt, div; k + k): Table 2's shader has none.
  EXPECT_EQ(unit(c, "shader").fp, (FpUnits{1, 1, 1, 0, 1}));
  // The DynRTC alone: Table 2's 16 / 11 / 5 and 12 of its 13 comparators.
  const FpUnits dynrtc = unit(c, "traversal").fp + unit(c, "list").fp +
                         unit(c, "transformation").fp + unit(c, "intersection").fp;
  EXPECT_EQ(dynrtc, (FpUnits{16, 11, 5, 12, 0}));
  // 48 FP units at 90 MHz: 4.32 billion FLOPs (the paper's 45 give "4 billion").
  EXPECT_EQ(c.fp_total.total(), 48);
  EXPECT_DOUBLE_EQ(c.flops, 48 * 90e6);
}

TEST(Cost, Table2MemoryByHand) {
  const ConfigurationCost c = configuration_cost(cost_preset("table2"));
  // Traversal, 32 threads, P = 4, fp24: world and level rays 2 x 576 x 32 x 2 ports = 73,728;
  // node and clipped segments 2 x 192 x 32 = 12,288; t_best 96 x 32 x 2 = 6,144; object box
  // 144 x 32 x 2 = 9,216; stack 64 x (21 + 4 + 8 x 24) x 32 = 444,416; stack pointers 14 x 32 =
  // 448; control (21 + 4 + 1 + 11 + 3) x 32 = 1,280; frame registers 21 + 6 x 24 = 165.
  EXPECT_EQ(unit(c, "traversal").memory_bits(), 547'685);
  // List: object mailbox (8 x (18 + 4) + 8) x 32 = 5,888; triangle mailbox (8 x 23 + 8) x 32 =
  // 6,144; cursors 2 x (22 + 30) x 32 = 3,328; object entered (18 + 21 + 20 + 18) x 32 = 2,464;
  // entry lanes 4 x 32 = 128.
  EXPECT_EQ(unit(c, "list").memory_bits(), 17'952);
  // Transformation: matrix 288 x 32 x 2 = 18,432; R' and unit-triangle rays 2 x 576 x 32 x 2 =
  // 73,728; flag and step (1 + 4) x 32 = 160.
  EXPECT_EQ(unit(c, "transformation").memory_bits(), 92'320);
  EXPECT_EQ(unit(c, "intersection").memory_bits(), 0);
  // Caches of 512 items: data 512 x (64 + 32 + 96) = 98,304; tags and valid 512 x (13 + 14 + 12)
  // = 19,968; MSHRs 8 x (176 + 145 + 207) = 4,224; request queues 4 x (26 + 27 + 25) = 312.
  EXPECT_EQ(unit(c, "caches").memory_bits(), 122'808);
  // Shader: hit records 4 x (3 x 24 + 18 + 19) x 32 x 2 = 27,904; accumulators 4 x 56 x 32 =
  // 7,168; material register 272 x 32 = 8,704; packet 24 x 32 = 768; 8 lights x 96 = 768; frame
  // registers 515.
  EXPECT_EQ(unit(c, "shader").memory_bits(), 45'827);
  EXPECT_EQ(c.memory_bits_total, 826'592);
}

TEST(Cost, Table2MemoryWithinFifteenPercentOrItsCause) {
  const ConfigurationCost c = configuration_cost(cost_preset("table2"));
  auto near = [](double model_bits, const std::string& key) {
    return std::abs(model_bits / kKb / paper_kb(key) - 1.0) <= 0.15;
  };
  EXPECT_TRUE(near(double(unit(c, "caches").memory_bits()), "caches"));
  // Each larger difference and its measured cause (docs/cost.md "Table 2"):
  const UnitCost& trav = unit(c, "traversal");
  EXPECT_FALSE(near(double(trav.memory_bits()), "traversal"));  // 66.9 KB against 44.5
  // A stack entry keeps both ends of each lane's segment (D26): with one, 42.9 KB.
  const MemoryItem& stack = item(trav, "64 stack entries");
  const double one_t = double(trav.memory_bits()) - double(stack.count) * 64 * 4 * 24;
  EXPECT_TRUE(near(one_t, "traversal")) << one_t / kKb;
  // The list unit: the paper's 0.8 KB is the object mailbox (0.72 KB); the triangle mailbox
  // (D28), the list cursors and the object entered are the rest of 2.19 KB.
  EXPECT_FALSE(near(double(unit(c, "list").memory_bits()), "list"));
  EXPECT_TRUE(near(double(item(unit(c, "list"), "8 object mailbox").bits()), "list"));
  // Transformation: 11.3 KB, of which the RGS's initial rays are dual-ported; single-ported 9.0.
  const UnitCost& tr = unit(c, "transformation");
  EXPECT_FALSE(near(double(tr.memory_bits()), "transformation"));
  EXPECT_TRUE(
      near(double(tr.memory_bits() - item(tr, "initial rays").bits() / 2), "transformation"));
  // Shader: 5.59 KB with a material register per thread (D35); 4.53 KB without.
  const UnitCost& sh = unit(c, "shader");
  EXPECT_FALSE(near(double(sh.memory_bits()), "shader"));
  EXPECT_TRUE(near(double(sh.memory_bits() - item(sh, "material register").bits()), "shader"));
}

TEST(Cost, WidePacketsDeepClipsByHand) {
  // P = 16, 64 threads, 32 stack entries, two clip faces per step, 256 lights (prototype).
  const ConfigurationCost c = configuration_cost(
      with("prototype", {"packet=16", "threads=64", "stack=32", "clip.faces_per_step=2"}));
  const UnitCost& t = unit(c, "traversal");
  // 16 lanes x 2 faces: 32 adders and dividers. Comparators: a node step 3 x 16 = 48; an
  // exit-only clip's first step 2 faces x 16 + 2 x 16 (origins in the box) = 64.
  EXPECT_EQ(t.fp, (FpUnits{32, 0, 32, 64, 0}));
  // Stack: 32 x (21 + 16 + 2 x 16 x 24) = 25,760 bits per thread, x 64 = 1,648,640.
  EXPECT_EQ(item(t, "32 stack entries").bits(), 1'648'640);
  // World ray: 6 x 24 x 16 = 2,304 bits, x 64 threads x 2 ports = 294,912.
  EXPECT_EQ(item(t, "world ray").bits(), 294'912);
  EXPECT_EQ(item(unit(c, "shader"), "light table").bits(), 256 * 96);
  // 128 + 18 + 6 + 4 (the RGS helper) = 156 FP units at 90 MHz.
  EXPECT_EQ(c.fp_total.total(), 156);
  EXPECT_DOUBLE_EQ(c.flops, 156 * 90e6);
}

TEST(Cost, FourPipelinesAssociativeCacheByHand) {
  const ConfigurationCost c = configuration_cost(
      with("prototype", {"pipelines=4", "cache.traversal.items=1024", "cache.traversal.ways=4"}));
  const UnitCost& k = unit(c, "caches");
  // 1024 nodes in 256 sets of 4: tag 21 - 8 = 13 bits + valid = 14 x 1024; LRU ages 2 x 1024;
  // MSHR 21 + 10 + 2 + 64 + 16 labels x 6 bits (64 threads) = 193 x 8.
  EXPECT_EQ(item(k, "traversal cache tags").bits(), 14 * 1024);
  EXPECT_EQ(item(k, "traversal cache LRU").bits(), 2 * 1024);
  EXPECT_EQ(item(k, "traversal cache data").bits(), 64 * 1024);
  EXPECT_EQ(item(k, "traversal cache outstanding").bits(), 193 * 8);
  // Four DynRTPs of 48 FP units each; memory four times one DynRTP's.
  EXPECT_EQ(c.fp_total, (FpUnits{68, 48, 24, 48, 4}));
  EXPECT_DOUBLE_EQ(c.flops, 192 * 90e6);
  EXPECT_EQ(c.memory_bits_total, 4 * c.memory_bits_per_pipeline);
}

TEST(Cost, Table1DesignsFromTheirOperations) {
  // T 9 + 9, I 3 + 2 + 1 (compares are bit tests, D13), I_w 12 add + 11 mul + 1 div, I_p 25 add
  // + 32 mul + 2 div, S 6 + 6; K = 4 + 4 + 12 for P = 4.
  EXPECT_EQ(transformation_algorithm().units(), (FpUnits{9, 9, 0, 0, 0}));
  EXPECT_EQ(unit_triangle_algorithm().units(), (FpUnits{3, 2, 1, 0, 0}));
  EXPECT_EQ(wald_algorithm().units(), (FpUnits{12, 11, 1, 0, 0}));
  EXPECT_EQ(plucker_algorithm().units(), (FpUnits{25, 32, 2, 0, 0}));
  EXPECT_EQ(shading_algorithm().units(), (FpUnits{6, 6, 0, 0, 0}));
  const Table1 t = table1(cost_preset("prototype"));
  EXPECT_EQ(t.traversal.total(), 20);
  // Without traversal: Dyn1 24, static 36, Dyn2 54, Dyn3 89; with K: 44, 56, 74, 109.
  const int without[] = {24, 36, 54, 89}, full[] = {44, 56, 74, 109};
  ASSERT_EQ(t.designs.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(t.designs[i].without_traversal.total(), without[i]) << t.designs[i].name;
    EXPECT_EQ(t.designs[i].full.total(), full[i]) << t.designs[i].name;
  }
  ASSERT_EQ(t.ratios.size(), 3u);
  EXPECT_DOUBLE_EQ(t.ratios[0].without_traversal, 24.0 / 36);  // 66.7 % (paper 66)
  EXPECT_DOUBLE_EQ(t.ratios[0].full, 44.0 / 56);               // 78.6 % (75)
  EXPECT_DOUBLE_EQ(t.ratios[1].without_traversal, 24.0 / 54);  // 44.4 % (46)
  EXPECT_DOUBLE_EQ(t.ratios[1].full, 44.0 / 74);               // 59.5 % (57)
  EXPECT_DOUBLE_EQ(t.ratios[2].without_traversal, 24.0 / 89);  // 27.0 % (23)
  EXPECT_DOUBLE_EQ(t.ratios[2].full, 44.0 / 109);              // 40.4 % (32): docs/cost.md
  // Five of the six within 5 points of the paper's; the sixth's cause is written down.
  for (const Table1Ratio& r : t.ratios) {
    EXPECT_LE(std::abs(r.without_traversal - r.paper_without_traversal), 0.05) << r.name;
    if (r.key != "dyn1_over_dyn3") {
      EXPECT_LE(std::abs(r.full - r.paper_full), 0.05) << r.name;
    }
  }
  EXPECT_GT(std::abs(t.ratios[2].full - t.ratios[2].paper_full), 0.05);
}

TEST(Cost, OperatorAreasAreTheMeasuredSynthesisFigures) {
  // docs/rtl.md "Synthesis", Virtex-II columns: add 728 LUTs, mul 759 + 1 MULT18X18, div 1,504,
  // cmp 96; the square root (no RTL) at the divider's figure.
  const auto& t = operator_areas();
  ASSERT_EQ(t.size(), 5u);
  const char* ops[] = {"add", "mul", "div", "cmp", "sqrt"};
  const int luts[] = {728, 759, 1504, 96, 1504}, mults[] = {0, 1, 0, 0, 0};
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_STREQ(t[i].op, ops[i]);
    EXPECT_EQ(t[i].luts, luts[i]) << ops[i];
    EXPECT_EQ(t[i].mult18x18, mults[i]) << ops[i];
  }
}

TEST(Cost, Table2AreaByHand) {
  const ConfigurationCost c = configuration_cost(cost_preset("table2"));
  // LUTs: traversal 4 x 728 + 4 x 1,504 + 12 x 96 = 10,080; transformation 9 x 728 + 9 x 759 =
  // 13,383 (9 multipliers); intersection 3 x 728 + 2 x 759 + 1,504 = 5,206 (2); shader 728 + 759
  // + 1,504 + 1,504 (the sqrt) = 4,495 (1); list and caches none.
  EXPECT_EQ(unit(c, "traversal").area.luts, 10'080);
  EXPECT_EQ(unit(c, "transformation").area.luts, 13'383);
  EXPECT_EQ(unit(c, "transformation").area.mult18x18, 9);
  EXPECT_EQ(unit(c, "intersection").area.luts, 5'206);
  EXPECT_EQ(unit(c, "intersection").area.mult18x18, 2);
  EXPECT_EQ(unit(c, "shader").area.luts, 4'495);
  EXPECT_EQ(unit(c, "list").area.luts, 0);
  EXPECT_EQ(unit(c, "caches").area.luts, 0);
  // Block RAMs: each unit's RAM bits once (two ports per block RAM) over 18,432, rounded up.
  // Traversal: Table2MemoryByHand's items without the second port and the frame registers:
  // 2 x 18,432 + 2 x 6,144 + 3,072 + 4,608 + 444,416 + 448 + 1,280 = 502,976 -> 27.3 -> 28.
  EXPECT_EQ(unit(c, "traversal").block_ram_bits(), 502'976);
  EXPECT_EQ(unit(c, "traversal").area.block_rams, 28);
  // List: 17,952 bits, all single-ported -> 1.
  EXPECT_EQ(unit(c, "list").area.block_rams, 1);
  // Transformation: 9,216 + 2 x 18,432 + 160 = 46,240 -> 2.5 -> 3.
  EXPECT_EQ(unit(c, "transformation").block_ram_bits(), 46'240);
  EXPECT_EQ(unit(c, "transformation").area.block_rams, 3);
  EXPECT_EQ(unit(c, "intersection").area.block_rams, 0);
  // Caches: data 98,304 + tags 19,968 = 118,272 (the misses' registers excluded) -> 6.4 -> 7.
  EXPECT_EQ(unit(c, "caches").block_ram_bits(), 118'272);
  EXPECT_EQ(unit(c, "caches").area.block_rams, 7);
  // Shader: hit records 13,952 + 7,168 + 8,704 + 768 + lights 768 = 31,360 -> 1.7 -> 2.
  EXPECT_EQ(unit(c, "shader").block_ram_bits(), 31'360);
  EXPECT_EQ(unit(c, "shader").area.block_rams, 2);
  // One DynRTP: 33,164 LUTs (49 % of the XC2V6000's 67,584), 12 multipliers, 41 block RAMs.
  EXPECT_EQ(c.area_per_pipeline, (AreaEstimate{33'164, 12, 41}));
  EXPECT_EQ(c.area_total, c.area_per_pipeline);
}

TEST(Cost, AreaOfWidePacketsAndFourPipelinesByHand) {
  // P = 16, two clip faces: traversal 32 add, 32 div, 64 cmp = 23,296 + 48,128 + 6,144 = 77,568
  // LUTs; with the transformation, intersection and shader of Table2AreaByHand: 100,652, more
  // than one XC2V6000 holds.
  const ConfigurationCost wide = configuration_cost(
      with("prototype", {"packet=16", "threads=64", "stack=32", "clip.faces_per_step=2"}));
  EXPECT_EQ(unit(wide, "traversal").area.luts, 77'568);
  EXPECT_EQ(wide.area_total.luts, 100'652);
  EXPECT_GT(wide.area_total.luts, kXc2v6000Luts);
  // Four prototype DynRTPs: four times one's LUTs, multipliers and block RAMs.
  const ConfigurationCost four = configuration_cost(with("prototype", {"pipelines=4"}));
  EXPECT_EQ(four.area_per_pipeline.luts, 33'164);
  EXPECT_EQ(four.area_total, four.area_per_pipeline * 4);
  EXPECT_EQ(four.area_total.mult18x18, 48);
}

TEST(Cost, LightsAndBadInput) {
  EXPECT_EQ(cost_preset("table2").lights, 8);
  EXPECT_EQ(cost_preset("prototype").lights, 256);
  CostParams p = cost_preset("prototype");
  apply_cost_setting(p, "lights=32");
  EXPECT_EQ(p.lights, 32);
  auto error = [](const char* kv) {
    CostParams q = cost_preset("prototype");
    try {
      apply_cost_setting(q, kv);
      configuration_cost(q);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("lights=-1").find("lights"), std::string::npos);
  EXPECT_NE(error("lights=x").find("lights"), std::string::npos);
  EXPECT_NE(error("packet=3").find("packet"), std::string::npos);
  EXPECT_NE(error("cache.list.ways=3").find("cache.list.ways"), std::string::npos);
  EXPECT_NE(error("nokey=1").find("nokey"), std::string::npos);
  EXPECT_THROW(cost_preset("nopreset"), std::runtime_error);
}

}  // namespace
}  // namespace saarcor::units
