// The fuzz harnesses' inputs kept in step with the code they fuzz (docs/fuzzing.md): the
// configuration dictionary names every cycle and kd.* key and every preset, and each seed the
// repository keeps is accepted (or, for the one bad seed, refused in one line).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "host/tree_settings.h"
#include "testbench/cycle_render.h"
#include "testbench/testing.h"
#include "testbench/vector_file.h"
#include "units/cycle_params.h"

namespace saarcor {
namespace {

namespace fs = std::filesystem;

const fs::path kFuzz = fs::path(SAARCOR_SOURCE_DIR) / "testbench" / "fuzz";

std::string read(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

TEST(FuzzInputs, ConfigDictionaryNamesEveryKeyAndPreset) {
  const std::string dict = read(kFuzz / "config.dict");
  ASSERT_FALSE(dict.empty());
  for (const units::CycleParamInfo& i : units::cycle_param_table())
    EXPECT_NE(dict.find("\"" + i.name + "=\""), std::string::npos) << i.name;
  for (const host::TreeSettingInfo& i : host::tree_setting_table())
    EXPECT_NE(dict.find("\"" + i.name + "=\""), std::string::npos) << i.name;
  for (const std::string& p : units::cycle_preset_names())
    EXPECT_NE(dict.find("\"" + p + "\""), std::string::npos) << p;
}

// A config seed: the preset on its first line, one KEY=VALUE per further line.
CycleRenderOptions options_of(const std::string& text) {
  std::istringstream in(text);
  CycleRenderOptions o;
  std::getline(in, o.preset);
  for (std::string line; std::getline(in, line);)
    o.set.push_back(line);
  return o;
}

TEST(FuzzInputs, ConfigSeedsResolve) {
  int seeds = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(kFuzz / "config")) {
    ++seeds;
    const CycleRenderOptions o = options_of(read(e.path()));
    if (e.path().filename() == "bad.txt") {
      // The first bad line ends it: a cache size that is not a power of two.
      EXPECT_EQ(test_support::error_of([&] { resolve_cycle_params(o); }),
                "bad --set cache.list.items=12: expected a power of two");
      continue;
    }
    EXPECT_NO_THROW(resolve_cycle_params(o)) << e.path();
  }
  EXPECT_GE(seeds, 8);
}

TEST(FuzzInputs, VectorSeedsCheck) {
  for (const char* unit : {"traversal", "transformation", "intersection"}) {
    const VectorCheck r = check_vector_text(read(kFuzz / "vectors" / (std::string(unit) + ".txt")));
    EXPECT_EQ(units::vector_unit_name(r.unit), std::string(unit));
    EXPECT_EQ(r.vectors, 4u) << unit;
    EXPECT_EQ(r.differing, 0u) << unit;
  }
  const VectorCheck d = check_vector_text(read(kFuzz / "vectors" / "traversal_differs.txt"));
  EXPECT_EQ(d.vectors, 4u);
  EXPECT_EQ(d.differing, 1u);
  ASSERT_EQ(d.first_differences.size(), 1u);
  EXPECT_EQ(d.first_differences[0], "line 10: far_tn is 415a3d, the datapath gives 415a3c");
}

}  // namespace
}  // namespace saarcor
