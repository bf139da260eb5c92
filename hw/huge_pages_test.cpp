// HugePageAllocator: large buffers 2 MiB-aligned, small ones from the default allocator, contents
// kept when a vector grows across the threshold.
#include "hw/huge_pages.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <type_traits>
#include <vector>

namespace saarcor::hw {
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

// The kd-tree builder's stacks ask for huge pages only from 8 MiB on: below the threshold the
// default allocator serves (no alignment promised), from it on 2 MiB-aligned.
TEST(HugePages, AThresholdAboveOnePageKeepsSmallerBuffersOnTheDefaultAllocator) {
  using Big = HugePageAllocator<std::uint64_t, 4 * kHugePage>;
  static_assert(Big::kMinBytes == 4 * kHugePage);
  static_assert(std::is_same_v<std::allocator_traits<Big>::rebind_alloc<char>,
                               HugePageAllocator<char, 4 * kHugePage>>);
  Big alloc;
  const std::size_t words = 4 * kHuge / sizeof(std::uint64_t);
  std::uint64_t* large = alloc.allocate(words);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(large) % kHuge, 0u);
  large[words - 1] = 5u;
  EXPECT_EQ(large[words - 1], 5u);
  alloc.deallocate(large, words);
  std::uint64_t* small = alloc.allocate(words - 1);  // one word below: not rounded up
  small[0] = 3u;
  EXPECT_EQ(small[0], 3u);
  alloc.deallocate(small, words - 1);
}

// A frame's buffers (units::FrameSink): zero bytes, nothing written by the container, a fresh
// buffer zero again after a used one is freed, large ones 2 MiB-aligned.
TEST(ZeroPages, BuffersStartAsZeroBytesAndResizeWritesNothing) {
  struct Record {
    std::uint32_t a = 7, b = 9;  // a value-initialised Record is not zero bytes
  };
  using Buffer = std::vector<Record, ZeroPageAllocator<Record>>;
  const std::size_t n = 3 * kHuge / sizeof(Record) + 5;
  for (int round = 0; round < 2; ++round) {
    Buffer v(n);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % kHuge, 0u);
    for (std::size_t i = 0; i < n; i += 4097)
      ASSERT_EQ(v[i].a + v[i].b, 0u) << i;
    EXPECT_EQ(v.back().a, 0u);
    v[0] = Record{};  // dirty it: the next round's buffer must still start as zero bytes
    v[n - 1] = Record{};
    advise_pages(v.data(), n * sizeof(Record), round == 0);
    EXPECT_EQ(v[n - 1].b, 9u);
  }
  Buffer small(3);  // below a huge page: calloc
  EXPECT_EQ(small[2].a, 0u);
  small.push_back(Record{});  // an explicit value is still constructed
  EXPECT_EQ(small[3].b, 9u);
}

}  // namespace
}  // namespace saarcor::hw
