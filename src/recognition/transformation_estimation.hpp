// Transformation estimation [paper 3.4, Algorithm 2]: the rigid transforms that RANSAC fits to
// its samples' inliers and ICP steps by. Private to src/recognition.
#pragma once
#include <Eigen/Core>
#include <vector>

namespace proxseg::detail {

// Rigid transform (no scale) taking src onto dst in the least-squares sense (Kabsch/Umeyama).
Eigen::Matrix4d kabsch(const std::vector<Eigen::Vector3d>& src,
                       const std::vector<Eigen::Vector3d>& dst);

// The point put in place by t.
inline Eigen::Vector3d apply(const Eigen::Matrix4d& t, const Eigen::Vector3d& p) {
  return t.topLeftCorner<3, 3>() * p + t.topRightCorner<3, 1>();
}

// Point-to-plane step (linearised, small angles): the increment that moves src towards the
// planes (dst, normal) in the least-squares sense.
Eigen::Matrix4d point_to_plane(const std::vector<Eigen::Vector3d>& src,
                               const std::vector<Eigen::Vector3d>& dst,
                               const std::vector<Eigen::Vector3d>& normal);

}  // namespace proxseg::detail
