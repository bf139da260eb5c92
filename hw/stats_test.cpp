// Statistics registry (docs/hw.md): declaration rules, values, JSON dump, time series.
#include "hw/stats.h"

#include <gtest/gtest.h>

#include "hw/kernel.h"

namespace saarcor::hw {
namespace {

TEST(Stats, CountersAveragesHistogramsAndFormulasReportTheirValues) {
  Stats s;
  Counter& hits = s.counter("dynrtp0.node_cache.hits", "requests", "requests that hit");
  Counter& reqs = s.counter("dynrtp0.node_cache.requests", "requests", "requests accepted");
  Average& lat = s.average("dynrtp0.node_cache.latency", "cycles", "cycles per request");
  Histogram& h = s.histogram("dynrtp0.node_cache.latency_hist", "cycles", "latency", 0, 10, 3);
  s.formula("dynrtp0.node_cache.hit_rate", "ratio", "hits / requests", [&] {
    return reqs.value ? static_cast<double>(hits.value) / static_cast<double>(reqs.value) : 0.0;
  });
  reqs += 4;
  ++hits;
  hits += 2;
  for (double v : {2.0, 4.0, 12.0, 45.0}) {
    lat.sample(v);
    h.sample(v);
  }
  h.sample(-1.0);
  EXPECT_EQ(s.value("dynrtp0.node_cache.hits"), 3.0);
  EXPECT_EQ(s.value("dynrtp0.node_cache.latency"), 63.0 / 4.0);
  EXPECT_EQ(s.value("dynrtp0.node_cache.hit_rate"), 0.75);
  EXPECT_EQ(h.buckets, (std::vector<std::uint64_t>{2, 1, 0}));
  EXPECT_EQ(h.overflow, 1u);
  EXPECT_EQ(h.underflow, 1u);
  EXPECT_EQ(s.json(),
            "{\n"
            "  \"dynrtp0.node_cache.hit_rate\": {\"kind\": \"formula\", \"unit\": \"ratio\", "
            "\"desc\": \"hits / requests\", \"value\": 0.75},\n"
            "  \"dynrtp0.node_cache.hits\": {\"kind\": \"counter\", \"unit\": \"requests\", "
            "\"desc\": \"requests that hit\", \"value\": 3},\n"
            "  \"dynrtp0.node_cache.latency\": {\"kind\": \"average\", \"unit\": \"cycles\", "
            "\"desc\": \"cycles per request\", \"value\": 15.75, \"count\": 4},\n"
            "  \"dynrtp0.node_cache.latency_hist\": {\"kind\": \"histogram\", \"unit\": "
            "\"cycles\", \"desc\": \"latency\", \"value\": 5, \"lo\": 0, \"width\": 10, \"mean\": "
            "12.4, \"underflow\": 1, \"overflow\": 1, \"buckets\": [2, 1, 0]},\n"
            "  \"dynrtp0.node_cache.requests\": {\"kind\": \"counter\", \"unit\": \"requests\", "
            "\"desc\": \"requests accepted\", \"value\": 4}\n"
            "}\n");
}

TEST(Stats, FormulaOperatorsComputeRatiosPercentagesAndBandwidth) {
  EXPECT_EQ(ratio(3, 4), 0.75);
  EXPECT_EQ(ratio(5, 0), 0.0);  // no requests: no rate
  EXPECT_EQ(percent(3, 4), 75.0);
  EXPECT_EQ(percent(1, 3), 100.0 / 3.0);  // 100 * 1 = 100, then / 3
  EXPECT_EQ(percent(7, 0), 0.0);
  // 2 MiB in 45 cycles at 90 MHz: 2 MiB per 0.5 us = 4,000,000 MiB/s.
  EXPECT_EQ(mb_per_s(2 * 1048576, 45, 90e6), 4e6);
  EXPECT_EQ(mb_per_s(1000, 0, 90e6), 0.0);
}

TEST(Stats, BadDeclarationsAndUnknownNamesThrow) {
  Stats s;
  s.counter("a.b", "x", "y");
  EXPECT_THROW(s.counter("a.b", "x", "y"), std::logic_error);
  EXPECT_THROW(s.average("a.b", "x", "y"), std::logic_error);
  EXPECT_THROW(s.counter("", "x", "y"), std::logic_error);
  EXPECT_THROW(s.counter("a..b", "x", "y"), std::logic_error);
  EXPECT_THROW(s.counter(".a", "x", "y"), std::logic_error);
  EXPECT_THROW(s.histogram("h", "x", "y", 0, 0, 4), std::logic_error);
  EXPECT_THROW(s.value("nope"), std::logic_error);
  EXPECT_THROW(s.get_counter("nope"), std::logic_error);
}

TEST(Stats, JsonEscapesAndNumbers) {
  EXPECT_EQ(json_escape("a\"b\\c\nd\x01"), "a\\\"b\\\\c\\nd\\u0001");
  EXPECT_EQ(json_number(3.0), "3");
  EXPECT_EQ(json_number(0.1), "0.1");
  EXPECT_EQ(json_number(1.0 / 0.0), "null");
}

TEST(Stats, KernelSamplesTheTimeSeriesEveryPeriod) {
  Kernel k({.idle_skip = true, .time_series_period = 4});
  Channel<int> ch(k, "ch", 4, 1);
  class Pusher : public Module {
   public:
    Pusher(Kernel& k, Channel<int>& c) : Module(k, "pusher"), c_(c) {}
    int evaluate() override {
      if (now() >= 6 || !c_.can_push()) return 0;
      c_.push(1);
      return 1;
    }
    std::uint64_t next_wakeup(std::uint64_t) const override { return kNever; }
    Channel<int>& c_;
  } p(k, ch);
  const RunResult r = k.run([] { return false; }, 13);
  EXPECT_EQ(r.cycles, 13u);
  const std::string ts = k.stats().time_series_json();
  // Names are sorted; samples at cycles 4, 8, 12; pushes stop at 4 (capacity, nobody pops).
  EXPECT_EQ(ts,
            "{\"period\": 4, \"names\": [\"ch.avg_occupancy\", \"ch.max_occupancy\", "
            "\"ch.pushes\", \"pusher.busy_cycles\", \"pusher.stall_cycles\"], \"samples\": [\n"
            "  [4, 1.5, 4, 4, 4, 0],\n"
            "  [8, 2.75, 4, 4, 4, 0],\n"
            "  [12, 3.1666666666666665, 4, 4, 4, 0]]}\n");
  EXPECT_THROW(k.stats().counter("late", "x", "y"), std::logic_error);
  // A counter's column found by reference: pusher.busy_cycles is the fourth name, column 4 (the
  // cycle is column 0); 4 busy cycles in every sample. Formulas and histograms have none.
  const Counter& busy = p.busy_counter();
  EXPECT_EQ(k.stats().time_series_column(busy), 4u);
  EXPECT_EQ(k.stats().time_series()[2][k.stats().time_series_column(busy)], 4.0);
  EXPECT_EQ(k.stats().time_series_column(p.stall_counter()), 5u);
  const Counter elsewhere;
  EXPECT_THROW(k.stats().time_series_column(elsewhere), std::logic_error);
}

}  // namespace
}  // namespace saarcor::hw
