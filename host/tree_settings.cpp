// The kd-tree keys (host/tree_settings.h; docs/kdtree.md "Configuration keys").
#include "host/tree_settings.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace saarcor::host {
namespace {

struct Binding {
  TreeSettingInfo info;  // value: filled from ImageParams{} by tree_setting_table()
  bool integral;
  double (*get)(const ImageParams&);
  void (*set)(ImageParams&, double);
};

#define SAARCOR_TREE_FIELD(expr, type)                              \
  [](const ImageParams& p) { return static_cast<double>(p.expr); }, \
      [](ImageParams& p, double v) { p.expr = static_cast<type>(v); }

const std::vector<Binding>& bindings() {
  static const std::vector<Binding> table = {
      {{"kd.traversal_cost", 0, "cost", "SAH cost of one traversal step (K_T)", 0, 1e6},
       false,
       SAARCOR_TREE_FIELD(kd.traversal_cost, float)},
      {{"kd.intersection_cost", 0, "cost", "SAH cost of one triangle test (K_I)", 1e-6, 1e6},
       false,
       SAARCOR_TREE_FIELD(kd.intersection_cost, float)},
      {{"kd.top_item_cost", 0, "x K_I",
        "top level: an object visit's cost in triangle tests (transformation, clip, descent)", 1e-6,
        1e6},
       false,
       SAARCOR_TREE_FIELD(top_item_cost_factor, float)},
      {{"kd.empty_bonus", 0, "factor", "SAH cost factor of a plane that cuts off empty space", 1e-6,
        1},
       false,
       SAARCOR_TREE_FIELD(kd.empty_bonus, float)},
      {{"kd.max_depth", 0, "levels",
        "depth limit per level, -1 = automatic (8 + 1.3 log2 N); top + bottom fit kd.stack", -1,
        1000},
       true,
       SAARCOR_TREE_FIELD(kd.max_depth, int)},
      {{"kd.leaf_size", 0, "items", "never split a node with this many items or fewer", 0, 1e6},
       true,
       SAARCOR_TREE_FIELD(kd.leaf_size, int)},
      {{"kd.leaf_step", 0, "bool",
        "SAH charges K_T for every non-empty child (the traversal unit steps into leaves too; "
        "empty children are skipped)",
        0, 1},
       true,
       SAARCOR_TREE_FIELD(kd.leaf_step, bool)},
      {{"kd.nodes_per_item", 0, "nodes",
        "node bound: at most this many nodes per triangle in a bottom tree (or kd.node_floor), "
        "0 = no bound",
        0, 1e6},
       false,
       SAARCOR_TREE_FIELD(kd.max_nodes_per_item, float)},
      {{"kd.node_floor", 0, "nodes",
        "node bound: a tree of this many nodes or fewer is never bound", 0, 1e9},
       true,
       SAARCOR_TREE_FIELD(kd.node_floor, int)},
      {{"kd.empty_chains", 0, "rule",
        "chains of empty cuts: 0 = allowed, 1 = same-axis links merged into one cut, 2 = the "
        "non-empty child of an empty cut is not cut off empty again",
        0, 2},
       true,
       SAARCOR_TREE_FIELD(kd.empty_chains, int)},
      {{"kd.face_slabs", 0, "bool",
        "thin slabs peeling items that lie in a node face (for hardware without a triangle "
        "mailbox)",
        0, 1},
       true,
       SAARCOR_TREE_FIELD(kd.face_slabs, bool)},
      {{"kd.objective", 0, "enum",
        "bottom trees: 0 = plain SAH sum at kd.traversal_cost, 1 = the K_T (x 2^(i/2), i = -4..4) "
        "whose tree has the lowest SAH-expected load in its busiest unit",
        0, 1},
       true,
       SAARCOR_TREE_FIELD(tree_objective, int)},
      {{"kd.objective_ratio", 0, "factor",
        "kd.objective=1 walks only the trees whose SAH-expected traversal and transformation "
        "loads differ by at least this factor (1 = every tree); the others keep the plain tree",
        1, 1e6},
       false,
       SAARCOR_TREE_FIELD(tree_objective_ratio, float)},
      {{"kd.stack", 0, "entries",
        "traversal stack entries the trees are built for (both levels share them)", 2, 4096},
       true,
       SAARCOR_TREE_FIELD(stack_entries, int)},
      {{"image.bilinear", 0, "bool",
        "texture filter of every material record: 1 = bilinear (4 texels per hit), 0 = nearest "
        "(1 texel; the paper's Scene6 and Office runs)",
        0, 1},
       true,
       SAARCOR_TREE_FIELD(bilinear, bool)},
      {{"image.camera", 0, "index",
        "the scene's camera the frame is rendered from: -1 = its first (a default view if it has "
        "none), k = camera k of the scene's list (saarcor scene counts them)",
        -1, 1e6},
       true,
       SAARCOR_TREE_FIELD(camera, int)},
  };
  return table;
}
#undef SAARCOR_TREE_FIELD

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.15g", v);
  return buf;
}

}  // namespace

std::vector<TreeSettingInfo> tree_setting_table() {
  return describe_tree_settings(ImageParams{});
}

bool is_tree_setting(const std::string& key_value) {
  return key_value.rfind("kd.", 0) == 0 || key_value.rfind("image.", 0) == 0;
}

void apply_tree_setting(ImageParams& params, const std::string& key_value) {
  const auto eq = key_value.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::runtime_error("bad --set '" + key_value + "': expected KEY=VALUE");
  const std::string key = key_value.substr(0, eq);
  const std::string text = key_value.substr(eq + 1);
  std::string known;
  for (const auto& b : bindings()) {
    known += (known.empty() ? "" : ", ") + b.info.name;
    if (b.info.name != key) continue;
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size() || errno != 0 || !std::isfinite(v))
      throw std::runtime_error("bad --set " + key + "=" + text + ": not a number");
    if (b.integral && v != std::floor(v))
      throw std::runtime_error("bad --set " + key + "=" + text + ": expected an integer");
    if (v < b.info.min || v > b.info.max)
      throw std::runtime_error("bad --set " + key + "=" + text + ": expected " + fmt(b.info.min) +
                               ".." + fmt(b.info.max) + " " + b.info.unit);
    b.set(params, v);
    return;
  }
  throw std::runtime_error("unknown --set key '" + key + "' (known kd-tree keys: " + known + ")");
}

std::vector<TreeSettingInfo> describe_tree_settings(const ImageParams& params) {
  std::vector<TreeSettingInfo> v;
  for (const auto& b : bindings()) {
    TreeSettingInfo i = b.info;
    i.value = b.get(params);
    v.push_back(i);
  }
  return v;
}

}  // namespace saarcor::host
