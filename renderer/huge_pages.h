// Transparent huge pages for large, freshly allocated buffers: one page
// fault per 2 MiB instead of per 4 KiB (Linux madvise(MADV_HUGEPAGE)).
#pragma once
#include <cstddef>
#include <cstdint>

#include <sys/mman.h>

namespace ra {

// Asks for huge pages on the 2 MiB-aligned part of [p, p + bytes); call it
// before the memory is first touched. A hint: refused or unsupported, the
// memory is the same, only slower to fault in.
inline void advise_huge_pages(void* p, std::size_t bytes) {
#ifdef MADV_HUGEPAGE
  constexpr std::uintptr_t kHuge = std::uintptr_t(1) << 21;
  const std::uintptr_t b = (reinterpret_cast<std::uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t e = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kHuge - 1);
  if (e > b) madvise(reinterpret_cast<void*>(b), e - b, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

}  // namespace ra
