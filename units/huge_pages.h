// An allocator for a frame's per-pixel buffers (FrameSink). A 512x384 frame's hit records are
// about 17 MB: in 4 KiB pages that is ~4,300 first-touch page faults per frame, which on the
// virtual machines this model runs on cost ~8% of a cycle-model frame and ~25% of a functional
// one (perf: exc_page_fault under FrameSink::reset). Buffers of 2 MiB and more are therefore
// allocated 2 MiB-aligned and advised to transparent huge pages (one fault per 2 MiB). Advice
// only: results never depend on it, and where the kernel refuses it nothing changes.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace saarcor::units {

template <class T>
struct HugePageAllocator {
  using value_type = T;
  static constexpr std::size_t kHugePage = std::size_t{2} << 20;
  static constexpr std::size_t kMaxBytes = std::size_t{1} << 48;  // no machine holds more

  HugePageAllocator() = default;
  template <class U>
  explicit HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > kMaxBytes / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kHugePage) return std::allocator<T>{}.allocate(n);
    const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, rounded);
    if (p == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    (void)madvise(p, rounded, MADV_HUGEPAGE);
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < kHugePage) {
      std::allocator<T>{}.deallocate(p, n);
    } else {
      std::free(p);
    }
  }
  friend bool operator==(const HugePageAllocator&, const HugePageAllocator&) {
    return true;
  }
};

}  // namespace saarcor::units
