// The image grid of an organized frame, shared by the parts of the image-grid selection
// (image_selection.cpp, occluded_pieces.cpp).
#pragma once
#include <proxseg/core/frame.hpp>

#include "util/parallel_for.hpp"

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <vector>

namespace proxseg::detail {

constexpr int kNone = -1;
constexpr int kPlane = -2;  // component id of the support plane's pixels

struct Plane {
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
  float offset = 0;  // normal . x + offset = 0 on the plane
  float distance(const Eigen::Vector3f& x) const { return normal.dot(x) + offset; }
};

// The image grid: pixel neighbours, the range of every pixel (distance from the sensor, whatever
// way its axes point: PCL's sample scenes look down -z) and the depth-step test between pixels.
struct ImageGrid {
  ImageGrid(const Frame& f, float ratio, int nthreads)
      : frame(f), step_ratio(ratio), threads(nthreads), range(f.size(), 0.f) {
    parallel_for(static_cast<int>(f.size()), threads, [&](int p) {
      if (f.valid(p)) range[p] = f.xyz[p].norm();
    });
  }
  const Frame& frame;
  float step_ratio;
  int threads;  // for the per-pixel loops (parallel_for); every pixel is written by one iteration
  std::vector<float> range;
  int w() const { return frame.width; }
  int h() const { return frame.height; }
  bool valid(int i) const { return range[i] > 0; }
  float z(int i) const { return range[i]; }
  // Neighbouring pixels i and j (both valid) lie on one surface unless their depths differ by
  // more than step_ratio of the nearer one, times their distance in pixels.
  bool continuous(int i, int j, int pixels = 1) const {
    return std::abs(z(i) - z(j)) <= step_ratio * pixels * std::min(z(i), z(j));
  }
  // The 4-neighbours of pixel i, -1 outside the image.
  std::array<int, 4> neighbours(int i) const {
    const int u = i % w(), v = i / w();
    return {u > 0 ? i - 1 : -1, u + 1 < w() ? i + 1 : -1, v > 0 ? i - w() : -1,
            v + 1 < h() ? i + w() : -1};
  }
};

inline bool has_normal(const Eigen::Vector3f& n) {
  return std::isfinite(n.x());
}

}  // namespace proxseg::detail
