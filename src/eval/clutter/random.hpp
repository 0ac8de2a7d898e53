// The random numbers of the cluttered scene generator (docs/clutter.md): seeded sub-streams and
// value noise. splitmix64 only: std:: distributions differ between standard libraries, and a
// seed must give the same scene bit for bit everywhere. Private to the library.
#pragma once
#include <Eigen/Core>
#include <cmath>
#include <cstdint>

#include "util/splitmix.hpp"
#include "util/value_noise.hpp"

namespace proxseg::clutter {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;

struct Rng {
  SplitMix s;
  std::uint64_t next() { return s.next(); }
  double u() { return s.uniform(); }
  double u(double lo, double hi) { return s.uniform(lo, hi); }
  int i(int lo, int hi) {  // inclusive
    return lo + static_cast<int>(s.next() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  bool p(double probability) { return s.uniform() < probability; }
  double normal() { return s.normal(); }
};

// Independent sub-stream k of a seed.
inline Rng stream(std::uint32_t seed, std::uint64_t k) {
  return Rng{SplitMix{mix64(mix64(seed + 0x632be59bd9b4e019ull) ^ (k * 0x9e3779b97f4a7c15ull))}};
}

// Three octaves, in [0, 1]; scale = lattice spacing of the first octave (metres).
inline double fbm(const Vec3& p, double scale, std::uint64_t salt) {
  double sum = 0, amp = 1, norm = 0, f = 1 / scale;
  for (int o = 0; o < 3; ++o, amp *= 0.5, f *= 2) {
    sum += amp * vnoise(p * f, salt + static_cast<std::uint64_t>(o) * 0x51ed27ull);
    norm += amp;
  }
  return sum / norm;
}

inline double frac(double x) {
  return x - std::floor(x);
}

}  // namespace proxseg::clutter
