// The saarcor binary itself: Embree is a test oracle (host/embree_oracle.h), linked into tests
// and benchmarks only, never into the binary people run.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <memory>
#include <string>

namespace {

// ldd's listing of the binary: every shared library it loads, its dependencies' included.
std::string ldd(const std::string& binary) {
  std::string out;
  std::unique_ptr<FILE, int (*)(FILE*)> p(popen(("ldd " + binary + " 2>&1").c_str(), "r"), pclose);
  if (!p) return out;
  std::array<char, 512> buf{};
  while (std::fgets(buf.data(), static_cast<int>(buf.size()), p.get()) != nullptr)
    out += buf.data();
  return out;
}

TEST(SaarcorBinary, DoesNotLoadEmbree) {
  const std::string libs = ldd(std::string(SAARCOR_BIN_DIR) + "/saarcor");
  // The listing is real: the image library the binary does need is in it.
  ASSERT_NE(libs.find("libOpenImageIO"), std::string::npos) << libs;
  EXPECT_EQ(libs.find("embree"), std::string::npos) << libs;
}

}  // namespace
