// Stopping a long computation from outside: segment() and recognition check the StopToken of the
// thread that called them at their stop points (between segmentation stages and describing
// steps, per candidate, per batch of views, per view aligned, every 256 RANSAC attempts) and
// throw Stopped there. A computation never stopped
// answers as if there were no token: the checks read a flag and change nothing. The Python
// module stops its calls this way when the interpreter exits or a signal handler raises
// (KeyboardInterrupt).
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <stdexcept>

namespace proxseg {

// Thrown at a stop point of a computation whose token was asked to stop. Not an InputError: the
// input was fine; the caller asked for the stop and knows why.
struct Stopped : std::runtime_error {
  Stopped() : std::runtime_error("stopped") {}
};

// The flag a computation checks; request_stop() from any thread (it is one atomic store, safe
// in a signal handler too).
class StopToken {
 public:
  StopToken() = default;
  StopToken(const StopToken&) = delete;
  StopToken& operator=(const StopToken&) = delete;

  void request_stop() noexcept { stop_.store(true, std::memory_order_relaxed); }
  bool stop_requested() const noexcept { return stop_.load(std::memory_order_relaxed); }

  // `poll` is called at the stop points that the thread holding the StopScope reaches (not its
  // helper threads), at most once per `every`; true asks to stop. For what only that thread may
  // look at (Python checks for signals on the main thread only).
  void poll_with(std::function<bool()> poll, std::chrono::milliseconds every) {
    poll_ = std::move(poll);
    every_ = every;
  }

 private:
  friend void stop_point();
  std::atomic<bool> stop_{false};
  std::function<bool()> poll_;
  std::chrono::steady_clock::duration every_{};
  std::chrono::steady_clock::time_point polled_{};
};

// While it lives, the computations the calling thread runs check `token` at their stop points
// (and so do the threads the library starts for them). Scopes nest; the inner one rules.
class StopScope {
 public:
  explicit StopScope(StopToken& token) : StopScope(&token, true) {}
  // For a thread that works for another (a thread of an OpenMP team): the other's token
  // (current_stop_token() read on it), without its polling. Null: no token.
  StopScope(StopToken* token, bool polls);
  ~StopScope();
  StopScope(const StopScope&) = delete;
  StopScope& operator=(const StopScope&) = delete;

 private:
  StopToken* previous_;
  bool previous_polls_;
};

// The token of the calling thread's innermost StopScope, or null.
StopToken* current_stop_token() noexcept;

// A stop point: throws Stopped when the calling thread's token asks to stop (after polling it,
// on the thread that polls, when due). Without a token: nothing.
void stop_point();

}  // namespace proxseg
