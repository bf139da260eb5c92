// The kd-tree builder's parameters as configuration keys (`--set kd.KEY=VALUE`): the trees are the
// hardware's input, so an architect sweeps tree construction against the units like any other
// parameter (docs/kdtree.md "Configuration keys"). One parameter table (hw/param_table.h), as the
// cycle model's: every key declared once with its type, unit, range and help, bound to a field of
// ImageParams, whose default member initialiser is the key's default.
#pragma once

#include <string>
#include <vector>

#include "host/image_builder.h"
#include "hw/param_table.h"

namespace saarcor::host {

// A key as declared (hw::ParamInfo: name, value, unit, help, range, type).
using TreeSettingInfo = hw::ParamInfo;

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
