// The cost model's per-operator table (units/cost.cpp operator_areas) against yosys run afresh on
// the fp24 operators of rtl/ (label deep: the Virtex-II synthesis of the four operators takes
// minutes): each LUT and MULT18X18 figure the LUT estimate multiplies is the one synthesis gives
// today. Skipped where yosys is not installed.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>

#include "units/cost.h"

namespace saarcor::units {
namespace {

// rtl/synth.sh's markdown rows "| top | LUTs | flip-flops | MULT18X18 | yosys s |" by top.
std::map<std::string, std::pair<int, int>> synthesise(const std::string& tops) {
  const std::string cmd =
      "RTL_SYNTH=xc2v " + std::string(SAARCOR_SOURCE_DIR) + "/rtl/synth.sh " + tops + " 2>&1";
  std::FILE* pipe = popen(cmd.c_str(), "r");
  EXPECT_NE(pipe, nullptr);
  std::string out;
  char buf[512];
  while (pipe != nullptr && std::fgets(buf, sizeof buf, pipe) != nullptr)
    out += buf;
  const int rc = pipe != nullptr ? pclose(pipe) : -1;
  EXPECT_EQ(rc, 0) << out;
  std::map<std::string, std::pair<int, int>> rows;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) {
    std::string top, luts, ffs, mults;
    std::istringstream cells(line);
    char bar = 0;
    if (!(cells >> bar >> top >> bar >> luts >> bar >> ffs >> bar >> mults)) continue;
    if (top.rfind("fp_", 0) != 0) continue;
    rows[top] = {std::stoi(luts), std::stoi(mults)};
  }
  return rows;
}

TEST(CostDeep, OperatorTableIsWhatYosysMeasures) {
  if (std::system("command -v yosys >/dev/null 2>&1") != 0) GTEST_SKIP() << "yosys not installed";
  const auto rows = synthesise("fp_add fp_mul fp_div fp_cmp");
  for (const OperatorArea& o : operator_areas()) {
    if (std::string(o.op) == "sqrt") continue;  // no RTL: the divider's figure
    const auto it = rows.find("fp_" + std::string(o.op));
    ASSERT_NE(it, rows.end()) << o.op;
    EXPECT_EQ(it->second.first, o.luts) << o.op << " LUTs";
    EXPECT_EQ(it->second.second, o.mult18x18) << o.op << " MULT18X18";
  }
}

}  // namespace
}  // namespace saarcor::units
