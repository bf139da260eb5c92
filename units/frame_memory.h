// Host memory for a frame's per-pixel results (FrameSink). A 512x384 frame's hit records are
// about 17 MB: in 4 KiB pages that is ~4,300 first-touch page faults per frame, which on the
// virtual machines this model runs on cost ~8% of a cycle-model frame and ~25% of a functional
// one (perf: exc_page_fault under FrameSink::reset). Transparent huge pages take 2 MiB per fault.
// Advice only: results never depend on it, and where the kernel refuses it nothing changes.
#pragma once

#include <cstddef>
#include <cstdint>

#include "units/thread_program.h"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace saarcor::units {

// Asks for huge pages on the 2 MiB-aligned part of [p, p + bytes), before it is first touched.
inline void advise_huge_pages(const void* p, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
  const auto first = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t begin = (first + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t end = (first + bytes) & ~(kHuge - 1);
  if (end > begin) (void)madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

// FrameSink::reset for a w x h frame, with the buffers allocated (and advised) before reset()
// fills them (assign() within the capacity does not allocate again).
inline void reset_frame_sink(FrameSink& sink, int w, int h) {
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  sink.pixels.clear();
  sink.colour_sum.clear();
  sink.pixels.reserve(n);
  sink.colour_sum.reserve(n);
  advise_huge_pages(sink.pixels.data(), n * sizeof(FrameSink::Pixel));
  advise_huge_pages(sink.colour_sum.data(), n * sizeof(sink.colour_sum[0]));
  sink.reset(w, h);
}

}  // namespace saarcor::units
