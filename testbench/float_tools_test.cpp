// Tests of saarcor float-info / float-calc / float-gen: known encodings, the
// float-gen -> float-calc round trip in every mode, and one clear error per class of bad input,
// in process and through the `saarcor` executable.
#include "testbench/float_tools.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>

namespace saarcor {
namespace {

std::string calc(const std::string& input, const FloatCalcOptions& opts = {}) {
  std::istringstream in(input);
  std::ostringstream out;
  float_calc(opts, in, out);
  return out.str();
}

std::string calc_error(const std::string& input, const FloatCalcOptions& opts = {}) {
  try {
    calc(input, opts);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(FloatCalc, KnownFp24Results) {
  EXPECT_EQ(calc("add 3f0000 3f0000\n"), "400000\n");      // 1 + 1 = 2
  EXPECT_EQ(calc("mul 0x3f8000 0x3f8000\n"), "402000\n");  // 1.5 * 1.5 = 2.25
  EXPECT_EQ(calc("div 3f0000 000000\n"), "7f0000\n");      // 1 / +0 = +inf
  EXPECT_EQ(calc("div bf0000 000000\n"), "ff0000\n");      // -1 / +0 = -inf
  EXPECT_EQ(calc("div 000000 000000\n"), "7f8000\n");      // 0 / 0 = NaN
  EXPECT_EQ(calc("sqrt 400000\n"), "3f6a0a\n");            // sqrt(2) = 1.41421 (rne)
  EXPECT_EQ(calc("sub 3f0000 3f0000\n"), "000000\n");      // exact cancellation is +0
  EXPECT_EQ(calc("add 7effff 7effff\n"), "7f0000\n");      // overflow to inf (rne)
  EXPECT_EQ(calc("lt 3f0000 400000\nle 400000 3f0000\neq 800000 000000\n"), "1\n0\n1\n");
  EXPECT_EQ(calc("lt 7f8000 3f0000\n"), "0\n");  // NaN compares false
  EXPECT_EQ(calc("min 3f0000 7f8000\nmin 7f8000 3f0000\n"), "3f0000\n7f8000\n");
  EXPECT_EQ(calc("max 000000 800000\n"), "000000\n");  // comparator + mux keeps a
  // Comments and blank lines are skipped; CRLF line ends are accepted.
  EXPECT_EQ(calc("# header\n\nadd 3f0000 3f0000\r\n"), "400000\n");
}

TEST(FloatCalc, ModesChangeResults) {
  FloatCalcOptions rtz;
  rtz.round = "rtz";
  EXPECT_EQ(calc("add 7effff 7effff\n", rtz), "7effff\n");  // truncation saturates
  EXPECT_EQ(calc("sqrt 400000\n", rtz), "3f6a09\n");
  // 1/5 = 1.6 * 2^-3: rne rounds the last bit up, rtz does not.
  EXPECT_EQ(calc("div 3f0000 400000\n"), "3e0000\n");
  EXPECT_EQ(calc("div 3f0000 414000\n"), "3c999a\n");
  EXPECT_EQ(calc("div 3f0000 414000\n", rtz), "3c9999\n");
  EXPECT_EQ(calc("div 3f0000 408000\n"), "3d5555\n");  // 1/3 rounds down in both
  // Smallest normal / 2: flushed (default) or kept as a subnormal.
  FloatCalcOptions keep;
  keep.subnormals = "keep";
  EXPECT_EQ(calc("mul 010000 3e0000\n"), "000000\n");
  EXPECT_EQ(calc("mul 010000 3e0000\n", keep), "008000\n");
  // Other formats: binary32 through e8m23.
  FloatCalcOptions f32;
  f32.format = "e8m23";
  f32.subnormals = "keep";
  EXPECT_EQ(calc("add 3f800000 3f800000\n", f32), "40000000\n");
  EXPECT_EQ(calc("div 3f800000 40400000\n", f32), "3eaaaaab\n");  // 1/3 in binary32
}

TEST(FloatCalc, BadInputNamesTheLine) {
  EXPECT_EQ(
      calc_error("add 3f0000 3f0000\nfoo 1 2\n"),
      "float-calc: line 2: unknown op 'foo' (expected add sub mul div sqrt lt le eq min max)");
  EXPECT_EQ(calc_error("add 3f0000\n"), "float-calc: line 1: add takes 2 operand(s), got 1");
  EXPECT_EQ(calc_error("sqrt 3f0000 3f0000\n"),
            "float-calc: line 1: sqrt takes 1 operand(s), got 2");
  EXPECT_EQ(calc_error("\nadd 3f0000 xyz\n"),
            "float-calc: line 2: operand 'xyz' is not a hex encoding of e7m16 (24 bits)");
  EXPECT_EQ(calc_error("add 1000000 0\n"),
            "float-calc: line 1: operand '1000000' is not a hex encoding of e7m16 (24 bits)");
  EXPECT_EQ(calc_error("add 0x 0\n"),
            "float-calc: line 1: operand '0x' is not a hex encoding of e7m16 (24 bits)");
  FloatCalcOptions bad;
  bad.format = "e9m30";
  EXPECT_NE(calc_error("add 0 0\n", bad).find("unknown float format 'e9m30'"), std::string::npos);
  bad = {};
  bad.round = "up";
  EXPECT_EQ(calc_error("add 0 0\n", bad), "unknown rounding mode 'up' (expected rne or rtz)");
  bad = {};
  bad.subnormals = "daz";
  EXPECT_EQ(calc_error("add 0 0\n", bad), "unknown subnormal mode 'daz' (expected flush or keep)");
  // The lines before the bad one are answered.
  std::istringstream in("add 3f0000 3f0000\nbad\n");
  std::ostringstream out;
  EXPECT_THROW(float_calc({}, in, out), std::runtime_error);
  EXPECT_EQ(out.str(), "400000\n");
}

// float-gen's vectors, fed back through float-calc, give the same results, in every mode.
TEST(FloatGen, RoundTripThroughFloatCalc) {
  const char* ops[] = {"add", "sub", "mul", "div", "sqrt", "lt", "le", "eq", "min", "max"};
  for (const char* format : {"e7m16", "e4m5", "e8m23"}) {
    for (const char* round : {"rne", "rtz"}) {
      for (const char* sub : {"flush", "keep"}) {
        for (const char* op : ops) {
          FloatGenOptions g;
          g.op = op;
          g.count = 500;
          g.seed = 11;
          g.format = format;
          g.round = round;
          g.subnormals = sub;
          std::ostringstream vectors;
          float_gen(g, vectors);
          // Rebuild "OP A [B]" lines and the expected results.
          std::istringstream lines(vectors.str());
          std::string line, input, expected;
          int n = 0;
          while (std::getline(lines, line)) {
            std::istringstream f(line);
            std::string a, b, r;
            if (std::string(op) == "sqrt") {
              f >> a >> r;
              input += std::string(op) + " " + a + "\n";
            } else {
              f >> a >> b >> r;
              input += std::string(op) + " " + a + " " + b + "\n";
            }
            expected += r + "\n";
            ++n;
          }
          ASSERT_EQ(n, 500);
          FloatCalcOptions c;
          c.format = format;
          c.round = round;
          c.subnormals = sub;
          ASSERT_EQ(calc(input, c), expected) << op << " " << format << " " << round << " " << sub;
        }
      }
    }
  }
}

TEST(FloatGen, SeededAndMixesEdgePatterns) {
  FloatGenOptions g;
  g.op = "add";
  g.count = 2000;
  std::ostringstream a, b, c;
  float_gen(g, a);
  float_gen(g, b);
  g.seed = 2;
  float_gen(g, c);
  EXPECT_EQ(a.str(), b.str());  // same seed, same bytes
  EXPECT_NE(a.str(), c.str());
  // Edge operands appear: infinities, NaN, zeros, the largest finite value.
  for (const char* edge : {"7f0000 ", "7f8000 ", "000000 ", "7effff ", "800000 "}) {
    EXPECT_NE(a.str().find(edge), std::string::npos) << edge;
  }
  g.op = "pow";
  std::ostringstream d;
  EXPECT_THROW(float_gen(g, d), std::runtime_error);
}

TEST(FloatInfo, Fp24Parameters) {
  std::ostringstream out;
  float_info({}, out);
  const std::string s = out.str();
  EXPECT_NE(s.find("bias             63\n"), std::string::npos) << s;
  EXPECT_NE(s.find("one              0x3f0000"), std::string::npos) << s;
  EXPECT_NE(s.find("largest          0x7effff"), std::string::npos) << s;
  EXPECT_NE(s.find("(exact 18446603336221196288)"), std::string::npos) << s;  // (2-2^-16)*2^63
  EXPECT_NE(s.find("smallest normal  0x010000"), std::string::npos) << s;
  EXPECT_NE(s.find("epsilon          0x2f0000"), std::string::npos) << s;
  EXPECT_NE(s.find("(exact 0.0000152587890625)"), std::string::npos) << s;
}

TEST(FloatInfo, ValueRoundsOnceExactly) {
  FloatInfoOptions o;
  o.value = "0.1";
  std::ostringstream out;
  float_info(o, out);
  // 0.1 = 1.6 * 2^-4: mantissa 0.6 * 2^16 = 39321.6 -> rne 39322 (0x999a), rtz 39321 (0x9999).
  EXPECT_NE(out.str().find("value (rne)      0x3b999a"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("value (rtz)      0x3b9999"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("(exact 0.1000003814697265625)"), std::string::npos) << out.str();
  // A decimal just above a tie of fp24 whose nearest binary64 value is the tie itself:
  // 1 + 2^-17 + 10^-30 must round up (rne), which rounding the binary64 value alone would miss.
  o.value = "1.000007629394531250000000000001";
  std::ostringstream tie;
  float_info(o, tie);
  EXPECT_NE(tie.str().find("value (rne)      0x3f0001"), std::string::npos) << tie.str();
  o.value = "1.00000762939453125";  // the tie itself: even (1.0)
  std::ostringstream even;
  float_info(o, even);
  EXPECT_NE(even.str().find("value (rne)      0x3f0000"), std::string::npos) << even.str();
  o.value = "1e400";  // beyond binary64: inf in rne, the largest finite value in rtz
  std::ostringstream huge;
  float_info(o, huge);
  EXPECT_NE(huge.str().find("value (rne)      0x7f0000"), std::string::npos) << huge.str();
  EXPECT_NE(huge.str().find("value (rtz)      0x7effff"), std::string::npos) << huge.str();
  o.value = "twelve";
  std::ostringstream bad;
  EXPECT_THROW(float_info(o, bad), std::runtime_error);
}

// The executable: exit status and the one-line error through main(). `cmd` is a /bin/sh command
// line in which $S names the saarcor executable.
std::string run(const std::string& cmd_line, int* status) {
  const std::string cmd =
      "S='" + std::string(SAARCOR_BIN_DIR) + "/saarcor'; { " + cmd_line + " ; } 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) throw std::runtime_error("popen failed");
  std::string out;
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0)
    out.append(buf.data(), n);
  *status = pclose(p);
  return out;
}

TEST(FloatToolsCli, CalcAndErrorsThroughTheExecutable) {
  int status = 0;
  EXPECT_EQ(run("printf 'add 3f0000 3f0000\\n' | \"$S\" float-calc", &status), "400000\n");
  EXPECT_EQ(status, 0);
  EXPECT_EQ(run("printf 'mul 3f0000\\n' | \"$S\" float-calc", &status),
            "saarcor: error: float-calc: line 1: mul takes 2 operand(s), got 1\n");
  EXPECT_NE(status, 0);
  const std::string info = run("\"$S\" float-info --format e4m5", &status);
  EXPECT_EQ(status, 0);
  EXPECT_NE(info.find("bias             7\n"), std::string::npos) << info;
  EXPECT_EQ(run("\"$S\" float-info --format e10m5", &status),
            "saarcor: error: unknown float format 'e10m5' (expected eEmM with 2 <= E <= 8, "
            "1 <= M <= 23, or fp24/fp32/fp16)\n");
  EXPECT_NE(status, 0);
  const std::string gen = run("\"$S\" float-gen mul --count 3 --seed 5", &status);
  EXPECT_EQ(status, 0);
  EXPECT_EQ(std::count(gen.begin(), gen.end(), '\n'), 3);
}

}  // namespace
}  // namespace saarcor
