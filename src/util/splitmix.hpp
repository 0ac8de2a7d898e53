// splitmix64 draws: the same numbers with every standard library (std:: distributions are not),
// for the evaluation's seeded random choices (the occlusion generator, the test viewpoints).
#pragma once
#include <cmath>
#include <cstdint>
#include "util/angles.hpp"

namespace proxseg {

// splitmix64's output function: a bijective mix of all 64 bits (also a hash of one value).
inline std::uint64_t mix64(std::uint64_t x) {
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

struct SplitMix {
  static constexpr std::uint64_t kGamma = 0x9e3779b97f4a7c15ull;  // the state's increment
  std::uint64_t state;
  std::uint64_t next() { return mix64(state += kGamma); }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  double normal() {  // Box-Muller
    const double u = 1.0 - uniform(), v = uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * detail::kPi * v);
  }
};

}  // namespace proxseg
