// Allocators for large buffers that are touched afresh on every use: the kd-tree builder's item
// and event stacks (host/kd_builder.h, HugePageAllocator) and a frame's per-pixel buffers
// (units::FrameSink, ZeroPageAllocator below). A 512x384 frame's hit records are about 17 MB: in
// 4 KiB pages that is ~4,300 first-touch page faults per frame, which on the virtual machines this
// model runs on cost ~8% of a cycle-model frame and ~25% of a functional one (perf:
// exc_page_fault under FrameSink::reset). HugePageAllocator's buffers of
// at least MinBytes (2 MiB unless the user says otherwise) are therefore allocated 2 MiB-aligned
// and advised to transparent huge pages (Linux "madvise" mode: one fault per 2 MiB). Advice
// only: results never depend on it, and where the kernel refuses it nothing changes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace saarcor::hw {

inline constexpr std::size_t kHugePage = std::size_t{2} << 20;

template <class T, std::size_t MinBytes = kHugePage>
struct HugePageAllocator {
  using value_type = T;
  static constexpr std::size_t kHugePage = hw::kHugePage;
  static_assert(MinBytes >= kHugePage, "smaller buffers gain nothing from a huge page");
  static constexpr std::size_t kMinBytes = MinBytes;
  static constexpr std::size_t kMaxBytes = std::size_t{1} << 48;  // no machine holds more
  // The threshold is a template argument, so the standard's automatic rebind does not apply.
  template <class U>
  struct rebind {
    using other = HugePageAllocator<U, MinBytes>;
  };

  HugePageAllocator() = default;
  template <class U>
  explicit HugePageAllocator(const HugePageAllocator<U, MinBytes>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > kMaxBytes / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
    if (bytes < MinBytes) return std::allocator<T>{}.allocate(n);
    const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, rounded);
    if (p == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    (void)madvise(p, rounded, MADV_HUGEPAGE);
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < MinBytes) {
      std::allocator<T>{}.deallocate(p, n);
    } else {
      std::free(p);
    }
  }
  friend bool operator==(const HugePageAllocator&, const HugePageAllocator&) {
    return true;
  }
};

// An allocator for a frame's per-pixel buffers (units::FrameSink) that writes nothing until the
// run does. Its buffers start as zero bytes, and a value-initialised element (vector::resize) is
// left so instead of being written: a run then touches only the pages of the pixels it hands
// out. A sampled run (testbench/sampling.h) hands out a twelfth of a frame's packets; writing
// every pixel's empty record first took as long as simulating them (a 1024x768 frame's records
// are 90 MB). Large buffers are fresh anonymous mappings (zero pages from the kernel), 2 MiB-
// aligned so that advise_pages() can ask for huge pages; small ones come from calloc. Only a
// fresh buffer is zero: a vector that shrinks and grows again within its capacity keeps the old
// elements' bytes, so FrameSink::reset swaps in a new vector every frame.
template <class T>
struct ZeroPageAllocator {
  using value_type = T;
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>,
                "an element left as zero bytes must be an object without construction");
  static constexpr std::size_t kMaxBytes = std::size_t{1} << 48;

  ZeroPageAllocator() = default;
  template <class U>
  explicit ZeroPageAllocator(const ZeroPageAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > kMaxBytes / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
#if defined(__linux__)
    if (bytes >= kHugePage) {
      const std::size_t rounded = round_up(bytes);
      void* m = mmap(nullptr, rounded + kHugePage, PROT_READ | PROT_WRITE,
                     MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      if (m == MAP_FAILED) throw std::bad_alloc();
      // Keep the 2 MiB-aligned part of the mapping; give back the rest.
      const auto base = reinterpret_cast<std::uintptr_t>(m);
      const std::uintptr_t aligned = (base + kHugePage - 1) / kHugePage * kHugePage;
      if (aligned > base) munmap(m, aligned - base);
      const std::size_t tail = base + kHugePage - aligned;
      if (tail > 0) munmap(reinterpret_cast<void*>(aligned + rounded), tail);
      return reinterpret_cast<T*>(aligned);
    }
#endif
    void* p = std::calloc(n == 0 ? 1 : n, sizeof(T));
    if (p == nullptr) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) noexcept {
#if defined(__linux__)
    if (n * sizeof(T) >= kHugePage) {
      munmap(p, round_up(n * sizeof(T)));
      return;
    }
#endif
    std::free(p);
  }
  // Value-initialisation in place is elided: the element stays zero bytes (not T{}).
  template <class U>
  void construct(U*) noexcept {}
  template <class U, class... A>
  void construct(U* p, A&&... a) {
    ::new (static_cast<void*>(p)) U(std::forward<A>(a)...);
  }
  friend bool operator==(const ZeroPageAllocator&, const ZeroPageAllocator&) {
    return true;
  }

 private:
  static std::size_t round_up(std::size_t bytes) {
    return (bytes + kHugePage - 1) / kHugePage * kHugePage;
  }
};

// Page-size advice for a ZeroPageAllocator buffer, given before it is touched: huge pages where a
// run writes all of it (one fault per 2 MiB), small ones where it writes a few scattered parts (a
// 2 MiB page is ~20 rows of a 1024-pixel frame: a sampled run's windows, two rows each, would
// fault in nearly every one). Advice only; results never depend on it.
inline void advise_pages(void* p, std::size_t bytes, bool huge) {
#if defined(__linux__) && defined(MADV_HUGEPAGE) && defined(MADV_NOHUGEPAGE)
  const auto base = reinterpret_cast<std::uintptr_t>(p);
  if (bytes < kHugePage || base % kHugePage != 0) return;  // not a mapping of its own
  (void)madvise(p, (bytes + kHugePage - 1) / kHugePage * kHugePage,
                huge ? MADV_HUGEPAGE : MADV_NOHUGEPAGE);
#else
  (void)p;
  (void)bytes;
  (void)huge;
#endif
}

}  // namespace saarcor::hw
