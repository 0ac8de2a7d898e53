// Wall-clock milliseconds for stage times (steady clock).
#pragma once

#include <chrono>

namespace proxseg::detail {

class Stopwatch {
 public:
  // Milliseconds since the start or the previous lap; starts the next lap.
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - last_).count();
    last_ = now;
    return ms;
  }
  // Milliseconds since the start or the previous lap.
  double ms() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - last_)
        .count();
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace proxseg::detail
