#include <proxseg/memory.hpp>

#include <cstddef>  // defines __GLIBC__ with glibc
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace proxseg {

void keep_freed_memory() {
#if defined(__GLIBC__)
  constexpr int kMiB = 1 << 20;
  // Blocks up to 32 MiB (glibc's upper limit for this setting) from the heap, not fresh mappings.
  mallopt(M_MMAP_THRESHOLD, 32 * kMiB);
  mallopt(M_TRIM_THRESHOLD, 256 * kMiB);  // freed heap memory stays mapped
  mallopt(M_TOP_PAD, 64 * kMiB);          // the heap grows in large steps
#endif
}

}  // namespace proxseg
