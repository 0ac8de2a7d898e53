// The paper's occlusion generator [4]: a random point of the view and a random radius (uniform
// in [0, max_radius]); every point within the radius of that point is removed. The share of
// removed points is what the paper's Table 3 bins by. Same view and seed, same occlusion.
#pragma once
#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace proxseg {

struct Occlusion {
  std::vector<Eigen::Vector3d> points;  // what is left, in the view's order
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0;
  double removed_share = 0;  // removed / view points
};
Occlusion occlude(const std::vector<Eigen::Vector3d>& view, double max_radius, std::uint64_t seed);

}  // namespace proxseg
