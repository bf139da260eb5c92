// The cycle model's keys (units/cycle_params.h): declared types, defaults, the memory interface
// they configure, one-line errors, and the README's key table.
#include "units/cycle_params.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>

namespace saarcor::units {
namespace {

std::string error_of(const std::string& kv) {
  CycleParams p;
  try {
    apply_cycle_setting(p, kv);
    check_cycle_params(p);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

const CycleParamInfo& info(const std::string& key) {
  for (const CycleParamInfo& i : cycle_param_table())
    if (i.name == key) return i;
  throw std::logic_error("no key " + key);
}

// The type is declared with the key: real numbers only where a fraction means something.
TEST(CycleParams, EachKeyHasItsDeclaredType) {
  int reals = 0, booleans = 0, choices = 0;
  for (const CycleParamInfo& i : cycle_param_table()) {
    reals += i.type == hw::ParamType::kReal;
    booleans += i.type == hw::ParamType::kBoolean;
    choices += i.type == hw::ParamType::kChoice;
    EXPECT_FALSE(i.help.empty()) << i.name;
    EXPECT_FALSE(i.unit.empty()) << i.name;
    EXPECT_TRUE(i.value >= i.min && i.value <= i.max) << i.name;
  }
  EXPECT_EQ(reals, 2);
  EXPECT_EQ(info("clock_mhz").type, hw::ParamType::kReal);
  EXPECT_EQ(info("hostbus.mb_s").type, hw::ParamType::kReal);
  EXPECT_EQ(booleans, 4);
  EXPECT_EQ(info("mem.reorder").type, hw::ParamType::kBoolean);
  EXPECT_EQ(choices, 1);
  EXPECT_EQ(info("mem.scene_paths").choices, (std::vector<int>{1, 3}));
  EXPECT_TRUE(info("packet").pow2);
  EXPECT_TRUE(info("cache.list.items").pow2);
  EXPECT_EQ(error_of("clock_mhz=120.5"), "");
  EXPECT_EQ(error_of("hostbus.mb_s=266.5"), "");
  EXPECT_EQ(error_of("lat.add=2.5"), "bad --set lat.add=2.5: expected an integer");
  EXPECT_EQ(error_of("watchdog=1.5"), "bad --set watchdog=1.5: expected an integer");
  EXPECT_EQ(error_of("mem.reorder=2"), "bad --set mem.reorder=2: expected 0 or 1");
  EXPECT_EQ(error_of("mem.scene_paths=2"), "bad --set mem.scene_paths=2: expected 1 or 3 paths");
  EXPECT_EQ(error_of("packet=3"), "bad --set packet=3: expected a power of two");
  EXPECT_EQ(error_of("threads=0"), "bad --set threads=0: expected 1..4096 threads");
  EXPECT_EQ(error_of("cache.bogus.items=8")
                .rfind("unknown --set key 'cache.bogus.items' (known: "
                       "pipelines, threads, ",
                       0),
            0u);
}

// The prototype is CycleParams{}; the table's defaults are its values.
TEST(CycleParams, DefaultsAreThePrototype) {
  const CycleParams p = prototype_params();
  const std::vector<CycleParamInfo> now = describe(p);
  ASSERT_EQ(now.size(), cycle_param_table().size());
  for (std::size_t i = 0; i < now.size(); ++i) {
    EXPECT_EQ(now[i].name, cycle_param_table()[i].name);
    EXPECT_EQ(now[i].value, cycle_param_table()[i].value) << now[i].name;
  }
  EXPECT_EQ(p.threads, 64);
  EXPECT_EQ(p.packet, 4);
  EXPECT_EQ(p.clock_mhz, 90.0);
  EXPECT_EQ(p.mem_scene_paths, 3);
  EXPECT_EQ(p.watchdog, 100000u);
  EXPECT_EQ(cycle_preset("table2").threads, 32);
  EXPECT_EQ(cycle_preset("standard").pipelines, 4);
  EXPECT_NO_THROW(check_cycle_params(p));
}

// Every memory-interface key reaches its own field of the memory system the chip builds, and no
// other: each set to a value none has by default.
TEST(CycleParams, EveryMemoryKeyReachesItsMemifField) {
  using memif::MemorySystemConfig;
  const MemorySystemConfig base = memory_system_config(prototype_params());
  EXPECT_EQ(base.controller.bank_path, (std::vector<int>{0, 1, 2, 3, 4, 5}));  // scene_paths=3
  struct Case {
    const char* kv;
    double want;
    double (*got)(const MemorySystemConfig&);
  };
  const Case cases[] = {
      {"pipelines=5", 5, [](const MemorySystemConfig& m) { return double(m.pipelines); }},
      {"cache.traversal.items=32", 32,
       [](const MemorySystemConfig& m) { return double(m.node_cache.items); }},
      {"cache.list.ways=2", 2,
       [](const MemorySystemConfig& m) { return double(m.list_cache.ways); }},
      {"cache.transformation.items=64", 64,
       [](const MemorySystemConfig& m) { return double(m.row_cache.items); }},
      {"cache.hit_latency=5", 5,
       [](const MemorySystemConfig& m) { return double(m.row_cache.hit_latency); }},
      {"cache.misses=3", 3,
       [](const MemorySystemConfig& m) { return double(m.list_cache.max_misses); }},
      {"cache.merge_targets=7", 7,
       [](const MemorySystemConfig& m) { return double(m.node_cache.max_targets); }},
      {"cache.request_queue=9", 9,
       [](const MemorySystemConfig& m) { return double(m.node_cache.request_capacity); }},
      {"cache.memory_queue=11", 11,
       [](const MemorySystemConfig& m) { return double(m.row_cache.memory_capacity); }},
      {"mem.latency=13", 13,
       [](const MemorySystemConfig& m) { return double(m.controller.latency); }},
      {"mem.switch_penalty=6", 6,
       [](const MemorySystemConfig& m) { return double(m.controller.switch_penalty); }},
      {"mem.queue_depth=17", 17,
       [](const MemorySystemConfig& m) { return double(m.controller.queue_depth); }},
      {"mem.reorder=0", 0,
       [](const MemorySystemConfig& m) { return double(m.controller.reorder); }},
      {"mem.max_burst=19", 19,
       [](const MemorySystemConfig& m) { return double(m.controller.max_burst); }},
      {"mem.port_capacity=21", 21,
       [](const MemorySystemConfig& m) { return double(m.controller.port_capacity); }},
      {"mem.scene_paths=1", 3,
       [](const MemorySystemConfig& m) { return double(m.controller.bank_path[5]); }},
      {"routing.responses=23", 23,
       [](const MemorySystemConfig& m) { return double(m.responses_per_cycle); }},
      {"hostbus.mb_s=266.5", 266.5, [](const MemorySystemConfig& m) { return m.host.mb_per_s; }},
      {"hostbus.burst_words=2", 2,
       [](const MemorySystemConfig& m) { return double(m.host.burst_words); }},
      {"clock_mhz=120", 120e6, [](const MemorySystemConfig& m) { return m.host.clock_hz; }},
      {"clock_mhz=121", 121e6, [](const MemorySystemConfig& m) { return m.controller.clock_hz; }},
  };
  for (const Case& c : cases) {
    CycleParams p = prototype_params();
    apply_cycle_setting(p, c.kv);
    const MemorySystemConfig m = memory_system_config(p);
    EXPECT_EQ(c.got(m), c.want) << c.kv;
    EXPECT_NE(c.got(base), c.want) << c.kv;
  }
}

// A configuration built in code is checked like one given by keys, naming the key.
TEST(CycleParams, CheckRefusesValuesSetInCode) {
  const auto refused = [](const CycleParams& p) {
    try {
      check_cycle_params(p);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CycleParams p;
  p.threads = 0;
  EXPECT_EQ(refused(p), "bad threads=0: expected 1..4096 threads");
  p = CycleParams{};
  p.cache[2].items = 100;
  EXPECT_EQ(refused(p), "bad cache.transformation.items=100: expected a power of two");
  p = CycleParams{};
  p.mem_scene_paths = 2;
  EXPECT_EQ(refused(p), "bad mem.scene_paths=2: expected 1 or 3 paths");
  p = CycleParams{};
  p.cache[1].items = 8;
  p.cache[1].ways = 16;
  EXPECT_EQ(refused(p), "bad cache.list.ways=16: must divide cache.list.items=8");
  p = CycleParams{};
  p.pipelines = 16;
  p.threads = 512;
  EXPECT_EQ(refused(p), "bad pipelines=16 with threads=512: 8192 threads in all, at most 4096");
}

// README's "Configuration keys" table: each key (`a.{b,c}.d` expanded, several per row split at
// " / ") with its default in the next cell.
std::map<std::string, std::string> readme_key_defaults() {
  std::ifstream f(std::string(SAARCOR_SOURCE_DIR) + "/README.md");
  std::string line;
  while (std::getline(f, line) && line.rfind("### Configuration keys", 0) != 0) {
  }
  std::map<std::string, std::string> out;
  while (std::getline(f, line) && (line.empty() || line[0] == '|' || out.empty())) {
    if (line.rfind("| `", 0) != 0) continue;
    const auto bar = line.find('|', 2);
    const std::string keys = line.substr(2, bar - 2);
    const std::string cell = line.substr(bar + 1, line.find('|', bar + 1) - bar - 1);
    std::vector<std::string> values;
    std::istringstream vs(cell);
    for (std::string v; vs >> v;)
      if (v != "/") values.push_back(v);
    std::vector<std::string> names;
    for (std::size_t a = keys.find('`'); a != std::string::npos; a = keys.find('`', a + 1)) {
      const auto b = keys.find('`', a + 1);
      const std::string key = keys.substr(a + 1, b - a - 1);
      a = b;
      const auto open = key.find('{'), close = key.find('}');
      if (open == std::string::npos) {
        names.push_back(key);
        continue;
      }
      std::istringstream alts(key.substr(open + 1, close - open - 1));
      for (std::string alt; std::getline(alts, alt, ',');)
        names.push_back(key.substr(0, open) + alt + key.substr(close + 1));
    }
    for (std::size_t i = 0; i < names.size(); ++i)
      out[names[i]] = values.size() == names.size() ? values[i] : values.at(0);
  }
  return out;
}

TEST(CycleParams, ReadmeListsEveryKeyWithItsDefault) {
  const std::map<std::string, std::string> readme = readme_key_defaults();
  for (const CycleParamInfo& i : cycle_param_table()) {
    const auto at = readme.find(i.name);
    ASSERT_NE(at, readme.end()) << i.name << " missing from README's configuration keys";
    EXPECT_EQ(at->second, hw::format_param_value(i.value)) << i.name;
  }
  EXPECT_EQ(readme.size(), cycle_param_table().size());
}

}  // namespace
}  // namespace saarcor::units
