// The process's memory: glibc allocator settings for frame-after-frame work and the resident
// memory read from /proc and getrusage (memory.hpp). Process plumbing, so io and not core, which
// reads no files.
#include <proxseg/io/memory.hpp>

#include <sys/resource.h>
#include <unistd.h>
#include <algorithm>
#include <cstddef>  // defines __GLIBC__ with glibc
#include <cstdint>
#include <cstdlib>
#include <fstream>
#if defined(__GLIBC__)
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace proxseg {

namespace {

// Bytes of address space this process may still map under RLIMIT_AS (SIZE_MAX without a limit).
std::size_t address_space_left() {
  rlimit limit{};
  if (::getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return SIZE_MAX;
  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0;
  statm >> pages;
  const std::size_t used = pages * static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  return limit.rlim_cur > used ? static_cast<std::size_t>(limit.rlim_cur) - used : 0;
}

}  // namespace

void keep_freed_memory() {
#if defined(__GLIBC__)
  constexpr std::size_t kMiB = std::size_t{1} << 20;
  // Blocks up to 32 MiB (glibc's upper limit for this setting) from the heap, not fresh mappings.
  mallopt(M_MMAP_THRESHOLD, 32 * kMiB);
  mallopt(M_TRIM_THRESHOLD, 512 * kMiB);  // freed heap memory stays mapped
  // One arena for all threads: a worker thread's own arena starts empty and faults in every page
  // it touches (4.8k extra page faults, +70 ms CPU per 640 x 480 frame at 2 threads), while the
  // main heap below is reserved once with huge pages. Two threads hardly contend for its lock.
  mallopt(M_ARENA_MAX, 1);
  // Reserve the heap's address space in one step and ask for transparent huge pages on it: a
  // 640 x 480 frame touches ~70 MB of fresh heap, 17k page faults of 4 KiB (~15 us each on a
  // virtual machine, more than the segmentation itself) or ~40 of 2 MiB. Only the address space
  // is reserved; memory is committed page by page as it is touched. Kernels with THP off or
  // "never" ignore the advice.
  std::size_t reserve = 384 * kMiB, pad = 64 * kMiB;
  // Under an address-space limit (ulimit -v) the reservation, and growth in steps of `pad`
  // (glibc asks for the padding even when it falls back from sbrk to mmap), would be what makes a
  // later allocation fail: both shrink to a part of what the limit leaves.
  if (const std::size_t left = address_space_left(); left < 16 * reserve) {
    reserve = left / 16 >= 32 * kMiB ? left / 16 : 0;
    pad = std::min(pad, left / 64);
  }
  const auto brk_before = reinterpret_cast<std::uintptr_t>(sbrk(0));
  void* probe = nullptr;
  if (reserve > 0) {
    mallopt(M_TOP_PAD, static_cast<int>(reserve));
    probe = std::malloc(16 * kMiB);  // more than the top chunk holds: the heap grows now
  }
  const auto brk_after = reinterpret_cast<std::uintptr_t>(sbrk(0));
  const auto at = reinterpret_cast<std::uintptr_t>(probe);
  // Only when the block came from the heap that just grew (not from another allocator's memory,
  // as under a sanitizer).
  if (probe != nullptr && brk_after >= brk_before + reserve && at < brk_after) {
    const auto page = static_cast<std::uintptr_t>(sysconf(_SC_PAGESIZE));
    const std::uintptr_t begin = (at + page - 1) & ~(page - 1), end = brk_after & ~(page - 1);
#if defined(MADV_HUGEPAGE)
    madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#endif
  }
  std::free(probe);
  mallopt(M_TOP_PAD, static_cast<int>(pad));  // later growth in large steps
#endif
}

double resident_mib() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  if (!(statm >> pages >> resident)) return 0;
  return static_cast<double>(resident) * static_cast<double>(::sysconf(_SC_PAGESIZE)) / (1 << 20);
}

double peak_resident_mib() {
  rusage u{};
  if (::getrusage(RUSAGE_SELF, &u) != 0) return 0;
  return u.ru_maxrss / 1024.0;  // KiB on Linux
}

}  // namespace proxseg
