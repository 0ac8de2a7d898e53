// Process-wide allocator settings, and memory readings, for programs that segment frame after
// frame.
#pragma once

namespace proxseg {

// Keeps the memory that segment() frees inside the process for the next frame. With glibc's
// defaults, large per-frame buffers (one value per pixel) are returned to the kernel when freed
// and page-faulted back on the next frame: over the 45 mOSD learn scenes in one process that was
// 441k page faults and three times the time (docs/method.md, Speed). Sets glibc's mmap and trim
// thresholds (mallopt), and reserves the heap's address space in one step with transparent huge
// pages advised on it (madvise), so that the first frame's fresh memory costs ~40 page faults
// instead of ~17k, and keeps every thread on that heap (one arena: a worker thread's own arena
// would start empty). Under an address-space limit (ulimit -v) the reservation and the heap's
// growth steps shrink to a part of what the limit leaves, so that they never make an allocation
// fail. It affects the whole process; call it once at start-up, before other threads allocate.
// Does nothing with other C libraries.
void keep_freed_memory();

// Resident memory of this process now, and its peak so far, in MiB (Linux: /proc/self/statm and
// getrusage; 0 where they are missing). Batches log them per frame to show they do not grow.
double resident_mib();
double peak_resident_mib();

}  // namespace proxseg
