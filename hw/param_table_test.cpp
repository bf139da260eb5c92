// ParamTable (hw/param_table.h): declared types, defaults from the struct, one-line errors.
#include "hw/param_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace saarcor::hw {
namespace {

struct Inner {
  float cost = 2.5f;
};
struct Config {
  int depth = 8;
  std::uint64_t limit = 1000;
  int lines = 512;
  double clock = 90.0;
  bool reorder = true;
  int paths = 3;
  Inner inner;
};

const ParamTable<Config>& table() {
  static const ParamTable<Config> t = [] {
    ParamTable<Config> p("--set", "known");
    p.integer("depth", &Config::depth, "cycles", -1, 64, "pipeline depth")
        .integer("limit", &Config::limit, "cycles", 1, 1e12, "cycles without progress")
        .power_of_two("cache.lines", &Config::lines, "items", 1, 1 << 20, "cache lines")
        .real("clock_mhz", &Config::clock, "MHz", 0.001, 1e5, "modelled clock")
        .boolean("reorder", &Config::reorder, "prefer the open bank")
        .choice("paths", &Config::paths, "paths", {1, 3}, "issue paths")
        .real(
            "inner.cost", [](auto& c) -> auto& { return c.inner.cost; }, "cost", 0, 10, "cost");
    return p;
  }();
  return t;
}

std::string error_of(Config& c, const std::string& kv) {
  try {
    table().apply(c, kv);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(ParamTable, DefaultsAreTheStructsInitialisers) {
  const auto d = table().defaults();
  ASSERT_EQ(d.size(), 7u);
  EXPECT_EQ(d[0].name, "depth");
  EXPECT_EQ(d[0].value, 8.0);
  EXPECT_EQ(d[1].value, 1000.0);
  EXPECT_EQ(d[2].value, 512.0);
  EXPECT_TRUE(d[2].pow2);
  EXPECT_EQ(d[3].value, 90.0);
  EXPECT_EQ(d[3].type, ParamType::kReal);
  EXPECT_EQ(d[4].value, 1.0);
  EXPECT_EQ(d[4].type, ParamType::kBoolean);
  EXPECT_EQ(d[4].unit, "bool");
  EXPECT_EQ(d[5].type, ParamType::kChoice);
  EXPECT_EQ(d[5].min, 1.0);
  EXPECT_EQ(d[5].max, 3.0);
  EXPECT_EQ(d[6].value, 2.5);
  EXPECT_STREQ(param_type_name(d[6].type), "real");
  EXPECT_STREQ(param_type_name(d[0].type), "integer");
}

TEST(ParamTable, ApplyThenDescribeGivesTheValuesBack) {
  Config c;
  for (const char* kv : {"depth=-1", "limit=1e12", "cache.lines=64", "clock_mhz=120.5", "reorder=0",
                         "paths=1", "inner.cost=0.25"})
    table().apply(c, kv);
  EXPECT_EQ(c.depth, -1);
  EXPECT_EQ(c.limit, 1000000000000ull);
  EXPECT_EQ(c.lines, 64);
  EXPECT_EQ(c.clock, 120.5);
  EXPECT_FALSE(c.reorder);
  EXPECT_EQ(c.paths, 1);
  EXPECT_EQ(c.inner.cost, 0.25f);
  const auto d = table().describe(c);
  EXPECT_EQ(d[0].value, -1.0);
  EXPECT_EQ(d[3].value, 120.5);
  EXPECT_EQ(d[4].value, 0.0);
  EXPECT_EQ(d[6].value, 0.25);
  EXPECT_NO_THROW(table().check(c));
}

TEST(ParamTable, BadValuesAreOneLineErrorsNamingTheKey) {
  Config c;
  EXPECT_EQ(error_of(c, "depth=x"), "bad --set depth=x: not a number");
  EXPECT_EQ(error_of(c, "depth="), "bad --set depth=: not a number");
  EXPECT_EQ(error_of(c, "depth=4x"), "bad --set depth=4x: not a number");
  EXPECT_EQ(error_of(c, "clock_mhz=inf"), "bad --set clock_mhz=inf: not a number");
  EXPECT_EQ(error_of(c, "depth=2.5"), "bad --set depth=2.5: expected an integer");
  EXPECT_EQ(error_of(c, "depth=65"), "bad --set depth=65: expected -1..64 cycles");
  EXPECT_EQ(error_of(c, "limit=0"), "bad --set limit=0: expected 1..1000000000000 cycles");
  EXPECT_EQ(error_of(c, "cache.lines=100"), "bad --set cache.lines=100: expected a power of two");
  EXPECT_EQ(error_of(c, "clock_mhz=0"), "bad --set clock_mhz=0: expected 0.001..100000 MHz");
  EXPECT_EQ(error_of(c, "reorder=2"), "bad --set reorder=2: expected 0 or 1");
  EXPECT_EQ(error_of(c, "reorder=0.5"), "bad --set reorder=0.5: expected an integer");
  EXPECT_EQ(error_of(c, "paths=2"), "bad --set paths=2: expected 1 or 3 paths");
  EXPECT_EQ(error_of(c, "depth"), "bad --set 'depth': expected KEY=VALUE");
  EXPECT_EQ(error_of(c, "=4"), "bad --set '=4': expected KEY=VALUE");
  EXPECT_EQ(error_of(c, "bogus=1"),
            "unknown --set key 'bogus' (known: depth, limit, cache.lines, clock_mhz, reorder, "
            "paths, inner.cost)");
  // Nothing half-applied.
  const Config d;
  EXPECT_EQ(c.depth, d.depth);
  EXPECT_EQ(c.lines, d.lines);
  EXPECT_EQ(c.reorder, d.reorder);
  EXPECT_EQ(c.paths, d.paths);
}

TEST(ParamTable, CheckRefusesValuesSetInCode) {
  const auto refused = [](const Config& c) {
    try {
      table().check(c);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  Config c;
  EXPECT_EQ(refused(c), "");
  c.lines = 12;
  EXPECT_EQ(refused(c), "bad cache.lines=12: expected a power of two");
  c = Config{};
  c.paths = 2;
  EXPECT_EQ(refused(c), "bad paths=2: expected 1 or 3 paths");
  c = Config{};
  c.clock = std::nan("");
  EXPECT_EQ(refused(c), "bad clock_mhz=nan: expected 0.001..100000 MHz");
  c = Config{};
  c.inner.cost = 11;
  EXPECT_EQ(refused(c), "bad inner.cost=11: expected 0..10 cost");
}

TEST(ParamTable, DeclarationMistakesAreRefused) {
  ParamTable<Config> t;
  t.integer("depth", &Config::depth, "cycles", 0, 1, "x");
  EXPECT_THROW(t.integer("depth", &Config::depth, "cycles", 0, 1, "x"), std::logic_error);
  EXPECT_THROW(t.choice("paths", &Config::paths, "paths", {3, 1}, "x"), std::logic_error);
  EXPECT_THROW(t.choice("paths", &Config::paths, "paths", {}, "x"), std::logic_error);
  EXPECT_EQ(t.size(), 1u);
  EXPECT_TRUE(t.has("depth"));
  EXPECT_FALSE(t.has("paths"));
}

}  // namespace
}  // namespace saarcor::hw
