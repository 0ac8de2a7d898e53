// Seeded 3D value noise: smooth random fields for generated textures (wood grain, blotches,
// fruit skins) that depend only on the point and the salt, with every standard library.
#pragma once
#include <Eigen/Core>
#include <cmath>
#include <cstdint>

#include "util/splitmix.hpp"

namespace proxseg {

// A uniform value in [0, 1) per lattice point and salt.
inline double noise_lattice(std::int64_t x, std::int64_t y, std::int64_t z, std::uint64_t salt) {
  const std::uint64_t h = mix64(salt ^ (static_cast<std::uint64_t>(x) * 0x9e3779b97f4a7c15ull) ^
                                (static_cast<std::uint64_t>(y) * 0xc2b2ae3d27d4eb4full) ^
                                (static_cast<std::uint64_t>(z) * 0x165667b19e3779f9ull));
  return static_cast<double>(h >> 11) * 0x1.0p-53;
}

// In [0, 1], lattice spacing 1: the lattice values blended with smoothstep weights.
inline double vnoise(const Eigen::Vector3d& p, std::uint64_t salt) {
  const auto smooth = [](double t) { return t * t * (3 - 2 * t); };
  const Eigen::Vector3d f(std::floor(p.x()), std::floor(p.y()), std::floor(p.z()));
  const auto x = static_cast<std::int64_t>(f.x()), y = static_cast<std::int64_t>(f.y()),
             z = static_cast<std::int64_t>(f.z());
  const double tx = smooth(p.x() - f.x()), ty = smooth(p.y() - f.y()), tz = smooth(p.z() - f.z());
  double out = 0;
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
    const double w = (dx ? tx : 1 - tx) * (dy ? ty : 1 - ty) * (dz ? tz : 1 - tz);
    if (w == 0) continue;  // e.g. the plane z = 0: 2D noise at half the cost
    out += w * noise_lattice(x + dx, y + dy, z + dz, salt);
  }
  return out;
}

}  // namespace proxseg
