// A value made on first use, once, whatever the number of threads asking: what a stored model
// database holds of a view until recognition shortlists it (docs/database.md, "Reading only what
// is used").
#pragma once
#include <atomic>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <utility>

namespace proxseg {

template <class T>
class Lazy {
 public:
  // Already made.
  explicit Lazy(T value) : value_(std::move(value)), ready_(true) {}
  // Made by `make` on the first get(). A make() that throws is not retried: every get() throws
  // its error again (a damaged record stays damaged; reading it again would only cost time).
  explicit Lazy(std::function<T()> make) : make_(std::move(make)) {}

  const T& get() const {
    if (!ready_.load(std::memory_order_acquire)) make_once();
    if (error_) std::rethrow_exception(error_);
    return *value_;
  }
  // Whether get() has run make() (or was given the value), for tests and reports.
  bool made() const { return ready_.load(std::memory_order_acquire); }

 private:
  void make_once() const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (ready_.load(std::memory_order_relaxed)) return;
    try {
      value_.emplace(make_());
    } catch (...) {
      error_ = std::current_exception();
    }
    make_ = nullptr;  // frees what it captured (a file handle, a buffer)
    ready_.store(true, std::memory_order_release);
  }

  mutable std::function<T()> make_;
  mutable std::optional<T> value_;
  mutable std::exception_ptr error_;
  mutable std::mutex mutex_;
  mutable std::atomic<bool> ready_{false};
};

}  // namespace proxseg
