// VCD tracer (docs/hw.md): the output is checked against the VCD grammar of
// IEEE 1364-2005 section 18.2 by a small independent parser, and the values it carries are
// checked against what the design did.
#include "hw/vcd.h"

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <sstream>

#include "hw/kernel.h"
#include "hw/test_designs.h"

namespace saarcor::hw {
namespace {

// Parses a VCD file per IEEE 1364-2005 18.2 (declaration commands, then simulation commands) and
// returns the value history of every variable, keyed by its full dotted reference. Any grammar
// violation fails the test with a message.
struct VcdFile {
  struct Var {
    int size = 0;
    std::string ref;
  };
  std::map<std::string, Var> vars;  // by identifier code
  std::map<std::string, std::vector<std::pair<std::uint64_t, std::string>>> history;  // by ref
  std::string error;

  std::string value_at(const std::string& ref, std::uint64_t t) const {
    std::string v = "x";
    for (const auto& [time, val] : history.at(ref)) {
      if (time > t) break;
      v = val;
    }
    return v;
  }
};

VcdFile parse_vcd(const std::string& text) {
  VcdFile f;
  std::istringstream in(text);
  std::vector<std::string> tok;
  for (std::string t; in >> t;)
    tok.push_back(t);
  std::size_t i = 0;
  auto fail = [&](const std::string& m) {
    if (f.error.empty()) f.error = m + " (token " + std::to_string(i) + ")";
  };
  auto skip_to_end = [&] {
    while (i < tok.size() && tok[i] != "$end")
      ++i;
    if (i == tok.size()) fail("missing $end");
    ++i;
  };
  std::vector<std::string> scope;
  bool defs_done = false;
  const std::set<std::string> var_types = {
      "event", "integer", "parameter", "real",   "realtime", "reg",  "supply0", "supply1", "time",
      "tri",   "triand",  "trior",     "trireg", "tri0",     "tri1", "wand",    "wire",    "wor"};
  const std::set<std::string> scope_types = {"begin", "fork", "function", "module", "task"};
  // Declarations.
  while (i < tok.size() && !defs_done && f.error.empty()) {
    const std::string& t = tok[i];
    if (t == "$comment" || t == "$date" || t == "$version") {
      ++i;
      skip_to_end();
    } else if (t == "$timescale") {
      ++i;
      std::string ts;
      while (i < tok.size() && tok[i] != "$end")
        ts += tok[i++];
      ++i;
      const std::set<std::string> ok = {"1s",  "10s",  "100s",  "1ms", "10ms", "100ms",
                                        "1us", "10us", "100us", "1ns", "10ns", "100ns",
                                        "1ps", "10ps", "100ps", "1fs", "10fs", "100fs"};
      if (!ok.count(ts)) fail("bad timescale " + ts);
    } else if (t == "$scope") {
      if (i + 3 >= tok.size() || !scope_types.count(tok[i + 1]) || tok[i + 3] != "$end") {
        fail("bad $scope");
        break;
      }
      scope.push_back(tok[i + 2]);
      i += 4;
    } else if (t == "$upscope") {
      if (scope.empty() || i + 1 >= tok.size() || tok[i + 1] != "$end") fail("bad $upscope");
      if (!scope.empty()) scope.pop_back();
      i += 2;
    } else if (t == "$var") {
      if (i + 5 >= tok.size() || !var_types.count(tok[i + 1])) {
        fail("bad $var");
        break;
      }
      const int size = std::stoi(tok[i + 2]);
      const std::string id = tok[i + 3];
      std::string ref;
      for (const auto& s : scope)
        ref += s + ".";
      ref += tok[i + 4];
      i += 5;
      if (tok[i] != "$end") {  // optional bit select [msb:lsb]
        if (tok[i] != "[" + std::to_string(size - 1) + ":0]") fail("bad bit select " + tok[i]);
        ++i;
      }
      if (tok[i] != "$end") fail("$var without $end");
      ++i;
      if (size < 1) fail("var size < 1");
      for (char c : id) {
        if (c < 33 || c > 126) fail("bad identifier code");
      }
      if (f.vars.count(id)) fail("identifier code declared twice: " + id);
      if (f.history.count(ref)) fail("reference declared twice: " + ref);
      f.vars[id] = {size, ref};
      f.history[ref];
    } else if (t == "$enddefinitions") {
      if (!scope.empty()) fail("unbalanced $scope");
      ++i;
      if (i >= tok.size() || tok[i] != "$end") fail("$enddefinitions without $end");
      ++i;
      defs_done = true;
    } else {
      fail("unexpected token in declarations: " + t);
    }
  }
  if (!defs_done) fail("no $enddefinitions");
  // Simulation commands.
  bool have_time = false;
  std::uint64_t now = 0;
  bool in_dump = false;
  while (i < tok.size() && f.error.empty()) {
    const std::string& t = tok[i];
    auto change = [&](const std::string& id, const std::string& v, bool scalar) {
      auto it = f.vars.find(id);
      if (it == f.vars.end()) return fail("value change for undeclared id " + id);
      if (!have_time) return fail("value change before the first #time");
      if (scalar && it->second.size != 1) return fail("scalar change of a vector " + id);
      if (!scalar && static_cast<int>(v.size()) > it->second.size) return fail("too wide");
      f.history[it->second.ref].emplace_back(now, v);
    };
    if (t[0] == '#') {
      const std::uint64_t nt = std::stoull(t.substr(1));
      if (have_time && nt <= now) fail("time does not increase: " + t);
      now = nt;
      have_time = true;
      ++i;
    } else if (t == "$dumpvars" || t == "$dumpall" || t == "$dumpon" || t == "$dumpoff") {
      if (in_dump) fail("nested dump");
      in_dump = true;
      ++i;
    } else if (t == "$end") {
      if (!in_dump) fail("stray $end");
      in_dump = false;
      ++i;
    } else if (t == "$comment") {
      ++i;
      skip_to_end();
    } else if (t[0] == 'b' || t[0] == 'B') {
      const std::string v = t.substr(1);
      if (v.empty() || v.find_first_not_of("01xXzZ") != std::string::npos) fail("bad vector");
      if (i + 1 >= tok.size())
        fail("vector without id");
      else
        change(tok[i + 1], v, false);
      i += 2;
    } else if (std::string("01xXzZ").find(t[0]) != std::string::npos && t.size() >= 2) {
      change(t.substr(1), t.substr(0, 1), true);
      ++i;
    } else {
      fail("unexpected token in simulation: " + t);
    }
  }
  if (in_dump) fail("unterminated dump");
  return f;
}

TEST(VcdTracer, OutputFollowsTheVcdGrammarAndCarriesWhatTheDesignDid) {
  Kernel k({.idle_skip = true});
  testing::DesignA d(k, 40);
  std::ostringstream out;
  k.trace_vcd(out, 5, 60);
  // Record the truth over the window from a probe evaluated every cycle.
  std::map<std::uint64_t, int> occupancy_e;
  std::map<std::uint64_t, bool> sink_busy;
  class Probe : public Module {
   public:
    Probe(Kernel& k, const Channel<std::uint32_t>& c, std::map<std::uint64_t, int>& occ)
        : Module(k, "probe"), c_(c), occ_(occ) {}
    int evaluate() override { return occ_[now()] = c_.occupancy(), 0; }
    const Channel<std::uint32_t>& c_;
    std::map<std::uint64_t, int>& occ_;
  } probe(k, d.e, occupancy_e);
  k.run_to_completion([&] { return d.done(); }, 10000);
  k.finish_trace();
  const VcdFile f = parse_vcd(out.str());
  ASSERT_EQ(f.error, "") << out.str().substr(0, 2000);
  // Scopes nest by dotted name.
  ASSERT_TRUE(f.history.count("top.a.sink.busy"));
  ASSERT_TRUE(f.history.count("top.a.ch_e.occupancy"));
  ASSERT_TRUE(f.history.count("top.a.joiner.pipe.valid"));
  ASSERT_TRUE(f.history.count("top.a.ch_a.ready"));
  EXPECT_EQ(f.history.at("top.a.sink.busy").front().first, 5u);  // $dumpvars at the window start
  for (std::uint64_t t = 5; t <= 60; ++t) {
    EXPECT_EQ(std::stoi(f.value_at("top.a.ch_e.occupancy", t), nullptr, 2), occupancy_e.at(t))
        << "cycle " << t;
  }
  // The sink pops on cycles divisible by 3 when ch_e is valid: busy exactly then.
  for (std::uint64_t t = 5; t <= 60; ++t) {
    const bool busy = f.value_at("top.a.sink.busy", t) == "1";
    const bool valid = f.value_at("top.a.ch_e.valid", t) == "1";
    EXPECT_EQ(busy, t % 3 == 0 && valid) << "cycle " << t;
  }
  // Nothing after the window.
  for (const auto& [ref, h] : f.history) {
    for (const auto& [t, v] : h)
      EXPECT_LE(t, 60u) << ref;
  }
  EXPECT_NE(out.str().find("\n#61\n"), std::string::npos);  // closing timestamp
}

TEST(VcdTracer, TheCheckerRejectsBrokenFiles) {
  const std::string good =
      "$timescale 1 ns $end\n$scope module top $end\n$var wire 1 ! a $end\n$var wire 3 \" b [2:0] "
      "$end\n$upscope $end\n$enddefinitions $end\n#0\n$dumpvars\n0!\nb101 \"\n$end\n#3\n1!\n";
  EXPECT_EQ(parse_vcd(good).error, "");
  auto broken = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    s.replace(s.find(from), from.size(), to);
    return parse_vcd(s).error;
  };
  EXPECT_NE(broken("#3", "#0"), "");             // time going backwards
  EXPECT_NE(broken("1!\n", "1?\n"), "");         // undeclared identifier
  EXPECT_NE(broken("b101 \"", "b1011 \""), "");  // wider than declared
  EXPECT_NE(broken("$upscope $end\n", ""), "");  // unbalanced scope
  EXPECT_NE(broken("1 ns", "3 ns"), "");         // bad timescale
  EXPECT_NE(broken("0!\n", "0\"\n"), "");        // scalar change on a vector
}

TEST(VcdTracer, IdentifierCodesArePrintableAndDistinct) {
  std::set<std::string> seen;
  for (std::size_t k = 0; k < 20000; ++k) {
    const std::string id = vcd_identifier(k);
    for (char c : id)
      ASSERT_TRUE(c >= 33 && c <= 126);
    ASSERT_TRUE(seen.insert(id).second) << k;
  }
}

TEST(VcdTracer, AnEmptyWindowIsRefused) {
  Kernel k;
  std::ostringstream out;
  EXPECT_THROW(k.trace_vcd(out, 10, 5), std::runtime_error);
}

}  // namespace
}  // namespace saarcor::hw
