// The kd-tree builder's configuration keys (host/tree_settings.h): defaults, round trip, errors.
#include "host/tree_settings.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace saarcor::host {
namespace {

std::string error_of(ImageParams& p, const std::string& kv) {
  try {
    apply_tree_setting(p, kv);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(TreeSettings, TableHoldsTheBuildersDefaults) {
  const ImageParams d;
  bool saw_depth = false, saw_stack = false;
  for (const TreeSettingInfo& t : tree_setting_table()) {
    EXPECT_TRUE(is_tree_setting(t.name + "=1")) << t.name;
    EXPECT_FALSE(t.help.empty()) << t.name;
    EXPECT_LE(t.min, t.value) << t.name;
    EXPECT_GE(t.max, t.value) << t.name;
    if (t.name == "kd.max_depth") {
      saw_depth = true;
      EXPECT_EQ(t.value, KdBuildParams::kAutoDepth);
    }
    if (t.name == "kd.stack") {
      saw_stack = true;
      EXPECT_EQ(t.value, d.stack_entries);
    }
    if (t.name == "kd.traversal_cost") {
      EXPECT_EQ(t.value, d.kd.traversal_cost);
    }
  }
  EXPECT_TRUE(saw_depth);
  EXPECT_TRUE(saw_stack);
}

TEST(TreeSettings, SetThenDescribeGivesTheValueBack) {
  ImageParams p;
  apply_tree_setting(p, "kd.traversal_cost=12.5");
  apply_tree_setting(p, "kd.max_depth=17");
  apply_tree_setting(p, "kd.face_slabs=0");
  apply_tree_setting(p, "kd.stack=32");
  apply_tree_setting(p, "kd.top_item_cost=4");
  apply_tree_setting(p, "kd.leaf_step=1");
  apply_tree_setting(p, "kd.nodes_per_item=3.5");
  apply_tree_setting(p, "kd.node_floor=1000");
  apply_tree_setting(p, "kd.empty_chains=2");
  apply_tree_setting(p, "image.camera=2");
  EXPECT_EQ(p.camera, 2);
  EXPECT_EQ(p.kd.empty_chains, KdBuildParams::kChainsForbidden);
  EXPECT_TRUE(p.kd.leaf_step);
  EXPECT_EQ(p.kd.max_nodes_per_item, 3.5f);
  EXPECT_EQ(p.kd.node_floor, 1000);
  EXPECT_EQ(p.kd.traversal_cost, 12.5f);
  EXPECT_EQ(p.kd.max_depth, 17);
  EXPECT_FALSE(p.kd.face_slabs);
  EXPECT_EQ(p.stack_entries, 32);
  EXPECT_EQ(p.top_item_cost_factor, 4.0f);
  for (const TreeSettingInfo& t : describe_tree_settings(p)) {
    if (t.name == "kd.max_depth") {
      EXPECT_EQ(t.value, 17.0);
    }
  }
  EXPECT_FALSE(is_tree_setting("threads=4"));
  EXPECT_FALSE(is_tree_setting("kdx=4"));
}

TEST(TreeSettings, BadValuesAreOneLineErrors) {
  ImageParams p;
  EXPECT_EQ(error_of(p, "kd.max_depth=x"), "bad --set kd.max_depth=x: not a number");
  EXPECT_EQ(error_of(p, "kd.max_depth=2.5"), "bad --set kd.max_depth=2.5: expected an integer");
  EXPECT_EQ(error_of(p, "kd.max_depth=-2"), "bad --set kd.max_depth=-2: expected -1..1000 levels");
  EXPECT_EQ(error_of(p, "kd.stack=1"), "bad --set kd.stack=1: expected 2..4096 entries");
  EXPECT_EQ(error_of(p, "kd.empty_chains=3"),
            "bad --set kd.empty_chains=3: expected 0, 1 or 2 rule");
  EXPECT_EQ(error_of(p, "image.camera=-2"),
            "bad --set image.camera=-2: expected -1..1000000 index");
  EXPECT_EQ(error_of(p, "kd.traversal_cost=nan"), "bad --set kd.traversal_cost=nan: not a number");
  EXPECT_EQ(error_of(p, "kd.face_slabs"), "bad --set 'kd.face_slabs': expected KEY=VALUE");
  EXPECT_EQ(
      error_of(p, "kd.leaves=3").rfind("unknown --set key 'kd.leaves' (known kd-tree keys: ", 0),
      0u);
  EXPECT_EQ(p.kd.max_depth, KdBuildParams::kAutoDepth);  // nothing half-applied
}

// Each key's declared type: the costs and factors are real, the rules choices, the switches bool.
TEST(TreeSettings, EachKeyHasItsDeclaredType) {
  for (const TreeSettingInfo& t : tree_setting_table()) {
    const bool real = t.name.find("cost") != std::string::npos || t.name == "kd.empty_bonus" ||
                      t.name == "kd.nodes_per_item" || t.name == "kd.objective_ratio";
    EXPECT_EQ(t.type == hw::ParamType::kReal, real) << t.name;
    EXPECT_EQ(t.type == hw::ParamType::kBoolean, t.unit == "bool") << t.name;
  }
  ImageParams p;
  EXPECT_EQ(error_of(p, "kd.objective=2"), "bad --set kd.objective=2: expected 0 or 1 enum");
  EXPECT_EQ(error_of(p, "kd.face_slabs=2"), "bad --set kd.face_slabs=2: expected 0 or 1");
  EXPECT_EQ(error_of(p, "kd.nodes_per_item=2.5"), "");
  EXPECT_EQ(p.kd.max_nodes_per_item, 2.5f);
}

// README names every key with its default: "`kd.KEY` (DEFAULT".
TEST(TreeSettings, ReadmeGivesEveryKeysDefault) {
  std::ifstream f(std::string(SAARCOR_SOURCE_DIR) + "/README.md");
  std::stringstream s;
  s << f.rdbuf();
  const std::string readme = s.str();
  for (const TreeSettingInfo& t : tree_setting_table()) {
    const std::string at = "`" + t.name + "` (";
    const auto pos = readme.find(at);
    ASSERT_NE(pos, std::string::npos) << t.name << " missing from README";
    char* end = nullptr;
    const double v = std::strtod(readme.c_str() + pos + at.size(), &end);
    EXPECT_EQ(v, t.value) << t.name;
  }
}

}  // namespace
}  // namespace saarcor::host
