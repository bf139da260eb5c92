// The kd-tree builder's parameters as configuration keys (`--set kd.KEY=VALUE`): the trees are the
// hardware's input, so an architect sweeps tree construction against the units like any other
// parameter (docs/kdtree.md "Configuration keys"). Same shape as the cycle model's table: every
// key declared once with its default, unit, help and range.
#pragma once

#include <string>
#include <vector>

#include "host/image_builder.h"

namespace saarcor::host {

struct TreeSettingInfo {
  std::string name;  // "kd.max_depth"
  double value;      // the default (tree_setting_table) or the current value (describe)
  std::string unit;
  std::string help;
  double min, max;
};

// Every tree key with its default (ImageParams{}'s values).
std::vector<TreeSettingInfo> tree_setting_table();
// True when "KEY=VALUE" names a tree or image key (its key starts with "kd." or "image.").
bool is_tree_setting(const std::string& key_value);
// Applies "kd.KEY=VALUE" to params; throws std::runtime_error naming the key for an unknown key,
// a value that is not a number, or one out of range.
void apply_tree_setting(ImageParams& params, const std::string& key_value);
// Every tree key with its current value in params.
std::vector<TreeSettingInfo> describe_tree_settings(const ImageParams& params);

}  // namespace saarcor::host
