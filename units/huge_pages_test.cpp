// HugePageAllocator: large buffers 2 MiB-aligned, small ones from the default allocator, contents
// kept when a vector grows across the threshold.
#include "units/huge_pages.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace saarcor::units {
namespace {

using Alloc = HugePageAllocator<std::uint64_t>;
constexpr std::size_t kHuge = Alloc::kHugePage;

TEST(HugePages, LargeBuffersAreHugePageAligned) {
  std::vector<std::uint64_t, Alloc> v(3 * kHuge / sizeof(std::uint64_t) + 5, 7u);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % kHuge, 0u);
  EXPECT_EQ(v.front(), 7u);
  EXPECT_EQ(v.back(), 7u);
}

TEST(HugePages, GrowingAcrossTheThresholdKeepsTheContents) {
  std::vector<std::uint64_t, Alloc> v;
  const std::size_t n = kHuge / sizeof(std::uint64_t) * 2;
  for (std::size_t i = 0; i < n; ++i)
    v.push_back(i * 3);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % kHuge, 0u);
  for (std::size_t i = 0; i < n; i += 4099)
    ASSERT_EQ(v[i], i * 3);
  v.resize(10);
  v.shrink_to_fit();  // back below the threshold: the default allocator again
  EXPECT_EQ(v[9], 27u);
}

}  // namespace
}  // namespace saarcor::units
