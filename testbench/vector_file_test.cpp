// The vector file's reader (testbench/vector_file.h) on the inputs fuzzing found
// (testbench/vector_file_fuzz.cpp, docs/fuzzing.md): text from the file is quoted in the one-line
// error with its control characters escaped, and a file with CRLF line ends reads as with LF.
#include "testbench/vector_file.h"

#include <gtest/gtest.h>

#include <string>

#include "testbench/testing.h"

namespace saarcor {
namespace {

using test_support::error_of;

// The crash input, shortened: a carriage return inside the unit name reached the message of
// units::parse_vector_unit unescaped (a two-line error on a terminal) and without the line number.
TEST(VectorFile, AnUnknownUnitIsOneLineNamingTheLine) {
  const std::string text =
      "# saarcor unit vectors 1\n"
      "# unit: transfor00000 round \rto nearest even\n";
  const std::string e = error_of([&] { check_vector_text(text); });
  EXPECT_EQ(e,
            "vector file line 2: unknown unit 'transfor00000 round \\x0dto nearest even' (known: "
            "traversal, transformation, intersection)");
}

TEST(VectorFile, ControlCharactersInAFieldAreEscaped) {
  const std::string text =
      "# saarcor unit vectors 1\n"
      "# unit: traversal\n"
      "bce000 40\x1b[2J6666 bf005f 000000 4172a9 1 1 4083d6 4083d6\n";
  EXPECT_EQ(error_of([&] { check_vector_text(text); }),
            "vector file line 3: field o_axis '40\\x1b[2J6666' is not a hex fp24 encoding");
}

TEST(VectorFile, CrlfLineEndsReadAsLf) {
  const std::string lf =
      "# saarcor unit vectors 1\n"
      "# unit: traversal\n"
      "bce000 406666 bf005f 000000 4172a9 1 1 4083d6 4083d6\n"
      "bfff9d 406666 bec622 415590 4159e8 1 0 4159e8 415a3d\n";
  std::string crlf;
  for (const char c : lf)
    crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  const VectorCheck a = check_vector_text(lf);
  const VectorCheck b = check_vector_text(crlf);
  EXPECT_EQ(a.unit, units::VectorUnit::kTraversal);
  EXPECT_EQ(b.unit, units::VectorUnit::kTraversal);
  EXPECT_EQ(a.vectors, 2u);
  EXPECT_EQ(b.vectors, 2u);
  EXPECT_EQ(a.differing, 1u);
  EXPECT_EQ(b.differing, 1u);
  EXPECT_EQ(a.first_differences, b.first_differences);
}

}  // namespace
}  // namespace saarcor
