#include "nudge/memory.hpp"

#include <cstdlib>  // defines __GLIBC__ where the C library is glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace nudge {

bool keep_large_buffers_for_reuse() {
#if defined(__GLIBC__)
  // glibc caps the mmap threshold at HEAP_MAX_SIZE / 2 (32 MB on 64-bit); setting it also turns
  // off the dynamic threshold, which would only rise after a first block had been unmapped.
  constexpr int kMmapThreshold = 32 * 1024 * 1024;
  constexpr int kTrimThreshold = 1024 * 1024 * 1024;
  const bool mapped = mallopt(M_MMAP_THRESHOLD, kMmapThreshold) == 1;
  const bool trimmed = mallopt(M_TRIM_THRESHOLD, kTrimThreshold) == 1;
  return mapped && trimmed;
#else
  return false;
#endif
}

}  // namespace nudge
