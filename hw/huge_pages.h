// An allocator for large buffers that are touched afresh on every use: a frame's per-pixel
// buffers (units::FrameSink) and the kd-tree builder's item and event stacks (host/kd_builder.h).
// A 512x384 frame's hit records are about 17 MB: in 4 KiB pages that is ~4,300 first-touch page
// faults per frame, which on the virtual machines this model runs on cost ~8% of a cycle-model
// frame and ~25% of a functional one (perf: exc_page_fault under FrameSink::reset). Buffers of
// at least MinBytes (2 MiB unless the user says otherwise) are therefore allocated 2 MiB-aligned
// and advised to transparent huge pages (Linux "madvise" mode: one fault per 2 MiB). Advice
// only: results never depend on it, and where the kernel refuses it nothing changes.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>

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

}  // namespace saarcor::hw
