// Transparent huge pages for the rasterizer's large per-frame arrays.
//
// A frame writes its triangle setups (hundreds of MB at 10^7 triangles)
// into memory freshly mapped for it, and on a virtual machine each 4 KiB
// page's first-touch fault is costly: measured on the 10^6-triangle
// terrain, faults in the setup stage took as long as setting up. Asking
// for 2 MiB pages (where the kernel allows them: `madvise` mode) makes
// that one fault per 2 MiB. Only a hint: contents and results are
// unchanged, and where it is refused nothing happens.
#pragma once

#include <cstddef>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace rastray {

// Advises huge pages for the whole 2 MiB pages inside [data, data + bytes).
inline void adviseHugePages(void* data, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr uintptr_t kHuge = uintptr_t(2) << 20;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHuge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

}  // namespace rastray
