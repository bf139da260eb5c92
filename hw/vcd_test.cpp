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

// The parser behind parse_vcd: the tokens, a cursor and the first error (later ones are not
// recorded, so the message names where the file first broke the grammar).
class VcdParser {
 public:
  explicit VcdParser(const std::string& text) {
    std::istringstream in(text);
    for (std::string t; in >> t;)
      tok_.push_back(t);
  }

  VcdFile parse() {
    declarations();
    if (!defs_done_) fail("no $enddefinitions");
    simulation();
    if (in_dump_) fail("unterminated dump");
    return std::move(f_);
  }

 private:
  void fail(const std::string& m) {
    if (f_.error.empty()) f_.error = m + " (token " + std::to_string(i_) + ")";
  }
  void skip_to_end() {
    while (i_ < tok_.size() && tok_[i_] != "$end")
      ++i_;
    if (i_ == tok_.size()) fail("missing $end");
    ++i_;
  }

  // Declaration commands, up to $enddefinitions.
  void declarations() {
    while (i_ < tok_.size() && !defs_done_ && f_.error.empty()) {
      const std::string& t = tok_[i_];
      if (t == "$comment" || t == "$date" || t == "$version") {
        ++i_;
        skip_to_end();
      } else if (t == "$timescale") {
        timescale();
      } else if (t == "$scope") {
        if (!open_scope()) break;
      } else if (t == "$upscope") {
        if (scope_.empty() || i_ + 1 >= tok_.size() || tok_[i_ + 1] != "$end") fail("bad $upscope");
        if (!scope_.empty()) scope_.pop_back();
        i_ += 2;
      } else if (t == "$var") {
        if (!var()) break;
      } else if (t == "$enddefinitions") {
        if (!scope_.empty()) fail("unbalanced $scope");
        ++i_;
        if (i_ >= tok_.size() || tok_[i_] != "$end") fail("$enddefinitions without $end");
        ++i_;
        defs_done_ = true;
      } else {
        fail("unexpected token in declarations: " + t);
      }
    }
  }

  void timescale() {
    ++i_;
    std::string ts;
    while (i_ < tok_.size() && tok_[i_] != "$end")
      ts += tok_[i_++];
    ++i_;
    const std::set<std::string> ok = {"1s",  "10s",  "100s",  "1ms", "10ms", "100ms",
                                      "1us", "10us", "100us", "1ns", "10ns", "100ns",
                                      "1ps", "10ps", "100ps", "1fs", "10fs", "100fs"};
    if (!ok.count(ts)) fail("bad timescale " + ts);
  }

  bool open_scope() {
    const std::set<std::string> scope_types = {"begin", "fork", "function", "module", "task"};
    if (i_ + 3 >= tok_.size() || !scope_types.count(tok_[i_ + 1]) || tok_[i_ + 3] != "$end") {
      fail("bad $scope");
      return false;
    }
    scope_.push_back(tok_[i_ + 2]);
    i_ += 4;
    return true;
  }

  // $var type size id reference [msb:lsb] $end
  bool var() {
    const std::set<std::string> var_types = {
        "event", "integer", "parameter", "real",   "realtime", "reg",  "supply0", "supply1", "time",
        "tri",   "triand",  "trior",     "trireg", "tri0",     "tri1", "wand",    "wire",    "wor"};
    if (i_ + 5 >= tok_.size() || !var_types.count(tok_[i_ + 1])) {
      fail("bad $var");
      return false;
    }
    const int size = std::stoi(tok_[i_ + 2]);
    const std::string id = tok_[i_ + 3];
    std::string ref;
    for (const auto& s : scope_)
      ref += s + ".";
    ref += tok_[i_ + 4];
    i_ += 5;
    if (tok_[i_] != "$end") {  // optional bit select [msb:lsb]
      if (tok_[i_] != "[" + std::to_string(size - 1) + ":0]") fail("bad bit select " + tok_[i_]);
      ++i_;
    }
    if (tok_[i_] != "$end") fail("$var without $end");
    ++i_;
    if (size < 1) fail("var size < 1");
    for (char c : id) {
      if (c < 33 || c > 126) fail("bad identifier code");
    }
    if (f_.vars.count(id)) fail("identifier code declared twice: " + id);
    if (f_.history.count(ref)) fail("reference declared twice: " + ref);
    f_.vars[id] = {size, ref};
    f_.history[ref];
    return true;
  }

  void change(const std::string& id, const std::string& v, bool scalar) {
    auto it = f_.vars.find(id);
    if (it == f_.vars.end()) return fail("value change for undeclared id " + id);
    if (!have_time_) return fail("value change before the first #time");
    if (scalar && it->second.size != 1) return fail("scalar change of a vector " + id);
    if (!scalar && static_cast<int>(v.size()) > it->second.size) return fail("too wide");
    f_.history[it->second.ref].emplace_back(now_, v);
  }

  // Simulation commands: times, dump blocks, comments and value changes.
  void simulation() {
    while (i_ < tok_.size() && f_.error.empty()) {
      const std::string& t = tok_[i_];
      if (t[0] == '#') {
        const std::uint64_t nt = std::stoull(t.substr(1));
        if (have_time_ && nt <= now_) fail("time does not increase: " + t);
        now_ = nt;
        have_time_ = true;
        ++i_;
      } else if (t == "$dumpvars" || t == "$dumpall" || t == "$dumpon" || t == "$dumpoff") {
        if (in_dump_) fail("nested dump");
        in_dump_ = true;
        ++i_;
      } else if (t == "$end") {
        if (!in_dump_) fail("stray $end");
        in_dump_ = false;
        ++i_;
      } else if (t == "$comment") {
        ++i_;
        skip_to_end();
      } else {
        value_change(t);
      }
    }
  }

  // A vector change "bVALUE id" or a scalar change "Vid".
  void value_change(const std::string& t) {
    if (t[0] == 'b' || t[0] == 'B') {
      const std::string v = t.substr(1);
      if (v.empty() || v.find_first_not_of("01xXzZ") != std::string::npos) fail("bad vector");
      if (i_ + 1 >= tok_.size())
        fail("vector without id");
      else
        change(tok_[i_ + 1], v, false);
      i_ += 2;
    } else if (std::string("01xXzZ").find(t[0]) != std::string::npos && t.size() >= 2) {
      change(t.substr(1), t.substr(0, 1), true);
      ++i_;
    } else {
      fail("unexpected token in simulation: " + t);
    }
  }

  std::vector<std::string> tok_;
  std::size_t i_ = 0;
  VcdFile f_;
  std::vector<std::string> scope_;
  bool defs_done_ = false;
  bool have_time_ = false;
  std::uint64_t now_ = 0;
  bool in_dump_ = false;
};

VcdFile parse_vcd(const std::string& text) {
  return VcdParser(text).parse();
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
