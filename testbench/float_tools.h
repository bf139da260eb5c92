// The float tools a verification engineer uses against an RTL FPU (docs/fixedfloat.md):
//   saarcor float-info  the parameters of a format, and the encoding of a value rounded into it;
//   saarcor float-calc  "OP A [B]" lines in, one result per line out (TestFloat's testfloat_ver
//                       shape), for diffing against an RTL simulation;
//   saarcor float-gen   TestFloat-style vectors "A B RESULT": edge patterns mixed with seeded
//                       random operands.
// All encodings are hexadecimal, results without a prefix, inputs with or without "0x".
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

namespace saarcor {

struct FloatInfoOptions {
  std::string format = "e7m16";
  std::string value;  // empty: no --value
};

struct FloatCalcOptions {
  std::string format = "e7m16";
  std::string round = "rne";         // rne | rtz
  std::string subnormals = "flush";  // flush | keep
};

struct FloatGenOptions {
  std::string op;  // add sub mul div sqrt lt le eq min max
  std::uint64_t count = 1000;
  std::uint64_t seed = 1;
  std::string format = "e7m16";
  std::string round = "rne";
  std::string subnormals = "flush";
};

// Stream versions (tests use these); they throw std::runtime_error with one line on bad input.
void float_info(const FloatInfoOptions& opts, std::ostream& out);
// Returns the number of lines answered.
std::uint64_t float_calc(const FloatCalcOptions& opts, std::istream& in, std::ostream& out);
void float_gen(const FloatGenOptions& opts, std::ostream& out);

// Command entry points on stdin/stdout; return the exit status.
int run_float_info(const FloatInfoOptions& opts);
int run_float_calc(const FloatCalcOptions& opts);
int run_float_gen(const FloatGenOptions& opts);

}  // namespace saarcor
