// The first exception of the iterations of an OpenMP loop, rethrown after the loop: an exception
// must not leave an OpenMP region (the runtime would call std::terminate).
#pragma once

#include <atomic>
#include <exception>
#include <mutex>

namespace proxseg::detail {

class FirstError {
 public:
  // Call in a catch (...) block inside the loop's body.
  void capture() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (!error_) error_ = std::current_exception();
    failed_ = true;
  }
  // Whether an iteration has failed: the others may skip their work.
  bool failed() const { return failed_.load(std::memory_order_relaxed); }
  // After the loop: rethrows the first exception captured, if any.
  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::mutex mutex_;
  std::exception_ptr error_;
  std::atomic<bool> failed_{false};
};

}  // namespace proxseg::detail
