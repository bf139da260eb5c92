// `saarcor vectors`: the file round trip (written vectors check clean), a changed output is
// found and named, malformed files and bad options are one-line errors with no file written.
#include "testbench/vectors_cmd.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "testbench/testing.h"

namespace saarcor {
namespace {

namespace fs = std::filesystem;
using test_support::error_of;

std::string read(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

TEST(Vectors, WrittenVectorsCheckCleanForEveryUnit) {
  const fs::path d = test_support::scratch_dir("vectors");
  for (const char* unit : {"traversal", "transformation", "intersection"}) {
    VectorsOptions o;
    o.scene = "builtin:dynamic";
    o.unit = unit;
    o.count = 50;
    o.res = "32x24";
    o.out = (d / (std::string(unit) + ".txt")).string();
    testing::internal::CaptureStdout();
    ASSERT_EQ(run_vectors(o), 0);
    testing::internal::GetCapturedStdout();
    const std::string text = read(o.out);
    EXPECT_EQ(text.rfind("# saarcor unit vectors 1\n# unit: " + std::string(unit) + "\n", 0), 0u);
    const VectorCheck r = check_vector_text(text);
    EXPECT_EQ(r.vectors, 50u) << unit;
    EXPECT_EQ(r.differing, 0u) << unit;
    VectorsOptions c;
    c.check = o.out;
    testing::internal::CaptureStdout();
    EXPECT_EQ(run_vectors(c), 0);
    EXPECT_NE(testing::internal::GetCapturedStdout().find("50 vectors, 0 differ"),
              std::string::npos);
  }
  fs::remove_all(d);
}

TEST(Vectors, ADifferentOutputIsFoundAndNamed) {
  // One intersection vector: the ray (0.25, 0.25, 1) + t (0, 0, -1) hits at t = 1.
  const std::string head =
      "# saarcor unit vectors 1\n# unit: intersection\n# inputs: ox oy oz dx dy dz\n";
  const std::string good =
      "3d0000 3d0000 3f0000 000000 000000 bf0000 3f0000 3d0000 3d0000 bf0000 1\n";
  EXPECT_EQ(check_vector_text(head + good).differing, 0u);
  const std::string wrong_u =
      "3d0000 3d0000 3f0000 000000 000000 bf0000 3f0000 3d0001 3d0000 bf0000 1\n";
  const VectorCheck r = check_vector_text(head + good + wrong_u + good);
  EXPECT_EQ(r.vectors, 3u);
  EXPECT_EQ(r.differing, 1u);
  ASSERT_EQ(r.first_differences.size(), 1u);
  EXPECT_EQ(r.first_differences[0], "line 5: u is 3d0001, the datapath gives 3d0000");
  // The command's exit status says so (2: vectors differ; 1 is for errors).
  const fs::path d = test_support::scratch_dir("vectors");
  const std::string path = (d / "rtl.txt").string();
  std::ofstream(path) << head << good << wrong_u;
  VectorsOptions c;
  c.check = path;
  testing::internal::CaptureStdout();
  EXPECT_EQ(run_vectors(c), 2);
  EXPECT_NE(testing::internal::GetCapturedStdout().find("line 5: u is 3d0001"), std::string::npos);
  fs::remove_all(d);
}

TEST(Vectors, MalformedFilesNameTheLine) {
  const std::string head = "# saarcor unit vectors 1\n# unit: traversal\n";
  EXPECT_EQ(error_of([] { check_vector_text("split o_axis\n"); }),
            "vector file line 1: expected '# saarcor unit vectors 1'");
  EXPECT_EQ(error_of([] { check_vector_text("# saarcor unit vectors 1\n3f0000\n"); }),
            "vector file line 2: a vector before the '# unit: ' line");
  EXPECT_EQ(error_of([&] { check_vector_text(head + "3f0000 0 3f0000 0\n"); }),
            "vector file line 3: 4 fields, a traversal vector has 9");
  EXPECT_EQ(error_of([&] { check_vector_text(head + "3f0000 0 3f0000 0 xyz 1 1 0 0\n"); }),
            "vector file line 3: field tf 'xyz' is not a hex fp24 encoding");
  EXPECT_EQ(error_of([&] { check_vector_text(head + "3f0000 0 3f0000 0 400000 2 1 0 0\n"); }),
            "vector file line 3: field go_near '2' is not 0 or 1");
  EXPECT_EQ(error_of([&] { check_vector_text(head + "1000000 0 3f0000 0 400000 1 1 0 0\n"); }),
            "vector file line 3: field split '1000000' is not a hex fp24 encoding");
  EXPECT_EQ(error_of([] { check_vector_text("# saarcor unit vectors 1\n# unit: shading\n"); }),
            "vector file line 2: unknown unit 'shading' (known: traversal, transformation, "
            "intersection)");
  EXPECT_EQ(error_of([] { check_vector_text("# saarcor unit vectors 1\n"); }),
            "vector file line 1: no '# unit: ' line");
}

TEST(SaarcorBinary, VectorsBadInput) {
  const fs::path d = test_support::scratch_dir("vectors_cli");
  fs::remove_all(d);
  const std::string out = (d / "v.txt").string();
  test_support::expect_one_line_error(
      test_support::run_saarcor("vectors builtin:cube --unit shading --out " + out),
      "unknown unit 'shading'");
  test_support::expect_one_line_error(
      test_support::run_saarcor("vectors builtin:cube --unit traversal --count 0 --out " + out),
      "bad --count 0");
  test_support::expect_one_line_error(
      test_support::run_saarcor("vectors builtin:cube --unit traversal"), "--out");
  test_support::expect_one_line_error(
      test_support::run_saarcor("vectors /nonexistent/s.glb --unit traversal --out " + out),
      "/nonexistent/s.glb");
  test_support::expect_one_line_error(
      test_support::run_saarcor("vectors --check " + (d / "none.txt").string()),
      "cannot read vector file");
  test_support::expect_one_line_error(
      test_support::run_saarcor("vectors builtin:cube --check " + out), "--check reads");
  EXPECT_FALSE(fs::exists(out));
  const test_support::CliRun ok = test_support::run_saarcor(
      "vectors builtin:cube --unit transformation --count 20 --res 16x12 --out " + out);
  ASSERT_EQ(ok.status, 0) << ok.err;
  EXPECT_TRUE(ok.err.empty()) << ok.err;
  const test_support::CliRun checked = test_support::run_saarcor("vectors --check " + out);
  EXPECT_EQ(checked.status, 0) << checked.out;
  EXPECT_NE(checked.out.find("20 vectors, 0 differ"), std::string::npos) << checked.out;
  fs::remove_all(d);
}

}  // namespace
}  // namespace saarcor
