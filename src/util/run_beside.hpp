// Two independent pieces of work at the same time on the two threads of an OpenMP team.
#pragma once

#include <exception>

namespace proxseg::detail {

// Runs a and b at the same time on two threads of an OpenMP team, or one after the other when
// `together` is false (a one-thread budget) or when called inside a parallel region. The team's
// second thread is the one OpenMP keeps for the library's parallel loops: a thread of our own would
// compete for the core with it while it spin-waits for the next parallel region (libgomp's
// default). An exception from either reaches the caller once both have finished (the first of the
// two if both throw).
template <class A, class B>
void run_beside(bool together, A&& a, B&& b) {
  if (!together) {
    a();
    b();
    return;
  }
  std::exception_ptr error[2];
#pragma omp parallel sections num_threads(2)
  {
#pragma omp section
    try {
      a();
    } catch (...) {
      error[0] = std::current_exception();
    }
#pragma omp section
    try {
      b();
    } catch (...) {
      error[1] = std::current_exception();
    }
  }
  for (const std::exception_ptr& e : error)
    if (e) std::rethrow_exception(e);
}

}  // namespace proxseg::detail
