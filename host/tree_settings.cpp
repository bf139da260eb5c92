// The kd-tree keys (host/tree_settings.h; docs/kdtree.md "Configuration keys").
#include "host/tree_settings.h"

namespace saarcor::host {
namespace {

using Table = hw::ParamTable<ImageParams>;

// The builder's own parameters (KdBuildParams, both levels).
template <auto field>
constexpr auto kd = [](auto& p) -> auto& {
  return p.kd.*field;
};

// The SAH's costs and the node bound.
void declare_costs(Table& t) {
  t.real("kd.traversal_cost", kd<&KdBuildParams::traversal_cost>, "cost", 0, 1e6,
         "SAH cost of one traversal step (K_T)")
      .real("kd.intersection_cost", kd<&KdBuildParams::intersection_cost>, "cost", 1e-6, 1e6,
            "SAH cost of one triangle test (K_I)")
      .real("kd.top_item_cost", &ImageParams::top_item_cost_factor, "x K_I", 1e-6, 1e6,
            "top level: an object visit's cost in triangle tests (transformation, clip, descent)")
      .real("kd.empty_bonus", kd<&KdBuildParams::empty_bonus>, "factor", 1e-6, 1,
            "SAH cost factor of a plane that cuts off empty space")
      .integer("kd.max_depth", kd<&KdBuildParams::max_depth>, "levels", -1, 1000,
               "depth limit per level, -1 = automatic (8 + 1.3 log2 N); top + bottom fit kd.stack")
      .integer("kd.leaf_size", kd<&KdBuildParams::leaf_size>, "items", 0, 1e6,
               "never split a node with this many items or fewer")
      .boolean("kd.leaf_step", kd<&KdBuildParams::leaf_step>,
               "SAH charges K_T for every non-empty child (the traversal unit steps into leaves "
               "too; empty children are skipped)")
      .real("kd.nodes_per_item", kd<&KdBuildParams::max_nodes_per_item>, "nodes", 0, 1e6,
            "node bound: at most this many nodes per triangle in a bottom tree (or "
            "kd.node_floor), 0 = no bound")
      .integer("kd.node_floor", kd<&KdBuildParams::node_floor>, "nodes", 0, 1e9,
               "node bound: a tree of this many nodes or fewer is never bound");
}

// The shape rules, the objective, the stack, and what the image builder writes besides the trees.
void declare_shapes(Table& t) {
  t.choice("kd.empty_chains", kd<&KdBuildParams::empty_chains>, "rule", {0, 1, 2},
           "chains of empty cuts: 0 = allowed, 1 = same-axis links merged into one cut, 2 = the "
           "non-empty child of an empty cut is not cut off empty again")
      .boolean("kd.face_slabs", kd<&KdBuildParams::face_slabs>,
               "thin slabs peeling items that lie in a node face (for hardware without a "
               "triangle mailbox)")
      .choice("kd.objective", &ImageParams::tree_objective, "enum", {0, 1},
              "bottom trees: 0 = plain SAH sum at kd.traversal_cost, 1 = the K_T (x 2^(i/2), i = "
              "-4..4) whose tree has the lowest SAH-expected load in its busiest unit")
      .real("kd.objective_ratio", &ImageParams::tree_objective_ratio, "factor", 1, 1e6,
            "kd.objective=1 walks only the trees whose SAH-expected traversal and transformation "
            "loads differ by at least this factor (1 = every tree); the others keep the plain "
            "tree")
      .integer("kd.stack", &ImageParams::stack_entries, "entries", 2, 4096,
               "traversal stack entries the trees are built for (both levels share them)")
      .boolean("image.bilinear", &ImageParams::bilinear,
               "texture filter of every material record: 1 = bilinear (4 texels per hit), 0 = "
               "nearest (1 texel; the paper's Scene6 and Office runs)")
      .integer("image.camera", &ImageParams::camera, "index", -1, 1e6,
               "the scene's camera the frame is rendered from: -1 = its first (a default view if "
               "it has none), k = camera k of the scene's list (saarcor scene counts them)");
}

const Table& table() {
  static const Table t = [] {
    Table t("--set", "known kd-tree keys");
    declare_costs(t);
    declare_shapes(t);
    return t;
  }();
  return t;
}

}  // namespace

std::vector<TreeSettingInfo> tree_setting_table() {
  return table().defaults();
}

bool is_tree_setting(const std::string& key_value) {
  return key_value.rfind("kd.", 0) == 0 || key_value.rfind("image.", 0) == 0;
}

void apply_tree_setting(ImageParams& params, const std::string& key_value) {
  table().apply(params, key_value);
}

std::vector<TreeSettingInfo> describe_tree_settings(const ImageParams& params) {
  return table().describe(params);
}

}  // namespace saarcor::host
