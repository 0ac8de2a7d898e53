// A parallel loop on threads that block when they are done.
#pragma once

#include <sched.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <type_traits>
#include <vector>

namespace proxseg::detail {

// The threads "0 = all cores" stands for: the cores this process may run on.
inline int all_threads() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0) return std::max(1, CPU_COUNT(&set));
  return std::max(1u, std::thread::hardware_concurrency());
}

// threads as the parameters give it: 0 = all_threads().
inline int thread_count(int threads) {
  return threads > 0 ? threads : all_threads();
}

// Runs f(i) for every i in [0, n) on up to `threads` threads, the calling one among them: each
// thread a block of consecutive indices, or, with chunk > 0, chunks of that many indices handed
// out in turn (for uneven work). Every index runs once; when f(i) writes only what index i owns,
// the result does not depend on the thread count. The threads are started for the loop and
// joined at its end, so nothing spins between loops: libgomp's team threads spin-wait after
// every parallel region, which cost a one-frame `proxseg segment` process about 20 ms of CPU on
// the image-grid path (docs/method.md, "Speed"). A thread that cannot be started leaves its
// share to the calling thread. The first exception thrown by f reaches the caller after every
// thread has finished. f may take the thread's number too, f(i, t) with t in [0, threads), for
// buffers kept per thread (an index that runs inline for a thread that could not start keeps that
// thread's number; its calls come one after another).
template <class F>
void parallel_for(int n, int threads, F&& f, int chunk = 0) {
  const auto call = [&f](int i, int t) {
    if constexpr (std::is_invocable_v<F&, int, int>)
      f(i, t);
    else
      f(i);
  };
  threads = std::max(1, std::min(threads, n));
  if (threads == 1) {
    for (int i = 0; i < n; ++i) call(i, 0);
    return;
  }
  std::atomic<int> next{0};
  std::mutex guard;
  std::exception_ptr error;
  auto work = [&](int t) {
    try {
      if (chunk > 0) {
        for (int start; (start = next.fetch_add(chunk)) < n;)
          for (int i = start, end = std::min(n, start + chunk); i < end; ++i) call(i, t);
      } else {
        const int lo = static_cast<int>(static_cast<long long>(n) * t / threads);
        const int hi = static_cast<int>(static_cast<long long>(n) * (t + 1) / threads);
        for (int i = lo; i < hi; ++i) call(i, t);
      }
    } catch (...) {
      const std::lock_guard<std::mutex> lock(guard);
      if (!error) error = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  std::vector<int> inline_shares;
  for (int t = 1; t < threads; ++t) {
    try {
      pool.emplace_back(work, t);
    } catch (const std::system_error&) {
      inline_shares.push_back(t);
    }
  }
  work(0);
  if (chunk == 0)
    for (int t : inline_shares) work(t);
  for (std::thread& th : pool) th.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace proxseg::detail
