// Test-only helpers of the testbench/ tests: a per-process scratch folder, the message of the
// error a call throws, and the saarcor binary run as a user runs it.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>

namespace saarcor::test_support {

// <tmp>/saarcor_<tag>_<pid>, created: tests running in parallel processes never share files.
inline std::filesystem::path scratch_dir(const std::string& tag) {
  std::filesystem::path d =
      std::filesystem::temp_directory_path() / ("saarcor_" + tag + "_" + std::to_string(getpid()));
  std::filesystem::create_directories(d);
  return d;
}

// The one-line message f throws, or "(no error)".
inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

struct CliRun {
  int status = -1;
  std::string out, err;
};

// `saarcor ARGS` with stdin empty and stdout, stderr captured (stderr is not a terminal, so no
// progress lines may appear there).
inline CliRun run_saarcor(const std::string& args) {
  const std::filesystem::path d = scratch_dir("cli");
  const std::string out = (d / "stdout.txt").string(), err = (d / "stderr.txt").string();
  const std::string cmd =
      std::string(SAARCOR_BIN_DIR) + "/saarcor " + args + " >" + out + " 2>" + err + " </dev/null";
  const int rc = std::system(cmd.c_str());
  CliRun r;
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  auto slurp = [](const std::string& p) {
    std::ifstream f(p);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
  };
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

// The shape every bad input must have: exit 1 and one line "saarcor: error: ..." naming it.
inline void expect_one_line_error(const CliRun& r, const std::string& contains) {
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.err.rfind("saarcor: error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(contains), std::string::npos) << r.err;
}

}  // namespace saarcor::test_support
