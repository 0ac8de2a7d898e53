// Two independent pieces of work at the same time.
#pragma once

#include <exception>
#include <system_error>
#include <thread>

namespace proxseg::detail {

// Runs a and b at the same time, b on a thread of its own, or one after the other when
// `together` is false (a one-thread budget) or when the thread cannot be started (no memory or
// threads left: the work is still done). An exception from either reaches the caller once both
// have finished (a's if both throw).
template <class A, class B>
void run_beside(bool together, A&& a, B&& b) {
  std::exception_ptr error[2];
  const auto run = [&error](auto& f, int k) {
    try {
      f();
    } catch (...) {
      error[k] = std::current_exception();
    }
  };
  std::thread beside;
  if (together) {
    try {
      beside = std::thread([&] { run(b, 1); });
    } catch (const std::system_error&) {
      together = false;
    }
  }
  run(a, 0);
  if (together)
    beside.join();
  else
    run(b, 1);
  for (const std::exception_ptr& e : error)
    if (e) std::rethrow_exception(e);
}

}  // namespace proxseg::detail
