// `saarcor cost [--preset P] [--set KEY=VALUE ...] [--json FILE]`: what a configuration costs
// (units/cost.h, docs/cost.md): per unit and in total the FP units and the internal memory broken
// into what it holds, and the FLOPs at the clock; with `--preset table2` each figure beside the
// paper's Table 2 with the ratio. `saarcor paper --table 1|2` prints Tables 1 and 2 through here.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "units/cost.h"

namespace saarcor {

struct CostOptions {
  std::string preset = "prototype";
  std::vector<std::string> set;  // cycle model keys and `lights`
  std::string json;              // write the figures as JSON
};

// The configuration: the preset's, then every --set in order; throws naming the key.
units::CostParams cost_params(const std::string& preset, const std::vector<std::string>& set);

// The per-unit listing with every memory item; with `table2` each unit's paper and ratio lines.
std::string cost_text(const units::CostParams& params, bool table2);
// Tables 1 and 2 printed as `saarcor paper` prints Tables 3 and 4: paper, model, ratio lines.
std::string table1_text(const units::CostParams& params);
std::string table2_text(const units::CostParams& params);

// `saarcor cost`: prints the listing, writes --json; returns 0. Bad input throws one line.
int run_cost(const CostOptions& opts);
// `saarcor paper --table 1|2` with the user's --set keys (Table 2 on preset table2); `json` as
// `saarcor cost --json`; a `csv` is refused (the CSV has Tables 3 and 4's columns).
int run_paper_cost_table(int table, const std::vector<std::string>& set, const std::string& json,
                         const std::string& csv);

}  // namespace saarcor
