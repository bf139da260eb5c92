// Test-only: unit vector files for the RTL unit tests, generated with the built saarcor binary
// (`saarcor vectors`, docs/unit-vectors.md), and the check of a file's vectors through the RTL
// against units/datapath.h (expected_outputs) and the file's own outputs, with the latency held
// against the cycle model's unit depth.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "rtl/rtl_units.h"
#include "rtl/vector_file.h"
#include "units/cycle_params.h"

namespace saarcor::rtl::testing {

#if defined(SAARCOR_SANITIZED)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

using units::VectorUnit;

inline int model_depth(VectorUnit u) {
  const units::CycleParams p = units::prototype_params();
  switch (u) {
    case VectorUnit::kTraversal:
      return p.traversal_depth();
    case VectorUnit::kTransformation:
      return p.transformation_depth();
    case VectorUnit::kIntersection:
      return p.intersection_depth();
  }
  return -1;
}

inline std::string temp_path(const std::string& name) {
  return (std::filesystem::path(::testing::TempDir()) /
          ("saarcor_rtl_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

// Writes `count` vectors of `unit` from `scene` with the built saarcor binary.
inline std::string generate(const std::string& scene, VectorUnit unit, std::size_t count,
                            const std::string& extra = "") {
  std::string tag = scene + "_" + units::vector_unit_name(unit);
  for (char& ch : tag)
    if (ch == '/' || ch == ':' || ch == '.') ch = '_';
  const std::string out = temp_path(tag + ".txt");
  const std::string cmd = std::string(SAARCOR_BIN_DIR) + "/saarcor vectors '" + scene +
                          "' --unit " + units::vector_unit_name(unit) + " --count " +
                          std::to_string(count) + (kSanitized ? " --res 64x48" : "") + " " + extra +
                          " --out '" + out + "' > /dev/null";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  return out;
}

inline std::vector<std::vector<std::uint32_t>> inputs_of(const VectorFile& f) {
  std::vector<std::vector<std::uint32_t>> in;
  for (const auto& v : f.vectors)
    in.push_back(v.in);
  return in;
}

inline std::string hex_list(const std::vector<std::uint32_t>& v) {
  std::string s;
  char buf[16];
  for (auto x : v) {
    std::snprintf(buf, sizeof buf, "%s%06x", s.empty() ? "" : " ", static_cast<unsigned>(x));
    s += buf;
  }
  return s;
}

// Runs a vector file through the RTL (with idle cycles between some transactions) and compares
// every output field with the datapath's and the file's. Returns the number of vectors (a scene
// without inner kd-nodes has no traversal transactions: an empty file checks nothing).
inline std::size_t check_file(const std::string& path, const std::string& what) {
  const VectorFile f = read_vector_file(path);
  if (f.vectors.empty()) return 0;
  const RtlRun run = run_unit(f.unit, inputs_of(f), {.bubble_one_in = 11, .seed = 5});
  EXPECT_EQ(run.latency_min, model_depth(f.unit)) << what;
  EXPECT_EQ(run.latency_max, model_depth(f.unit)) << what;
  EXPECT_EQ(run.stray_outputs, 0u) << what;
  std::size_t bad = 0, file_bad = 0;
  for (std::size_t k = 0; k < f.vectors.size(); ++k) {
    const VectorLine& v = f.vectors[k];
    const std::vector<std::uint32_t> want = units::expected_outputs(f.unit, v.in);
    const std::vector<std::uint32_t> got(run.outputs[k].begin(),
                                         run.outputs[k].begin() + static_cast<long>(want.size()));
    if (got != want && ++bad <= 5) {
      ADD_FAILURE() << what << " line " << v.line << ": inputs " << hex_list(v.in)
                    << "\n  datapath " << hex_list(want) << "\n  RTL      " << hex_list(got);
    }
    if (v.out != want) ++file_bad;
  }
  EXPECT_EQ(bad, 0u) << what << ": " << bad << " of " << f.vectors.size() << " vectors differ";
  EXPECT_EQ(file_bad, 0u) << what << ": the file's outputs are not the datapath's";
  return f.vectors.size();
}

inline constexpr VectorUnit kUnits[] = {VectorUnit::kIntersection, VectorUnit::kTransformation,
                                        VectorUnit::kTraversal};

}  // namespace saarcor::rtl::testing
