// Process-wide allocator settings for programs that segment frame after frame.
#pragma once

namespace proxseg {

// Keeps the memory that segment() frees inside the process for the next frame. With glibc's
// defaults, large per-frame buffers (one value per pixel) are returned to the kernel when freed
// and page-faulted back on the next frame: over the 45 mOSD learn scenes in one process that was
// 441k page faults and three times the time (docs/method.md, Speed). Sets glibc's mmap and trim
// thresholds (mallopt), and reserves the heap's address space in one step with transparent huge
// pages advised on it (madvise), so that the first frame's fresh memory costs ~40 page faults
// instead of ~17k. It affects the whole process; call it once at start-up, before other threads
// allocate. Does nothing with other C libraries.
void keep_freed_memory();

}  // namespace proxseg
