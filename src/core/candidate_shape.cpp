// A candidate's shape [paper 3.3]: its oriented box and centroid, and the background test of
// both selection geometries (selection_detail.hpp).
#include <proxseg/core/selection.hpp>

#include "selection_detail.hpp"
#include "util/moments.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace proxseg {

bool is_background(const Frame& frame, const Candidate& c, const SelectionParams& params) {
  const Eigen::Vector3d& e = c.box.extent;
  if (e[0] * e[1] < params.background_min_area) return false;
  const Eigen::Vector3d normal = c.box.axes.col(2);
  std::size_t inliers = 0;
  for (int p : c.points)
    inliers += std::abs(normal.dot(frame.xyz[p].cast<double>() - c.centroid)) <=
               params.background_plane_distance;
  return inliers >= params.background_inlier_ratio * c.points.size();
}

namespace {

// The box about the points' principal axes (m: their moments).
OrientedBox box_from_moments(const Frame& frame, const std::vector<int>& points,
                             const detail::Moments3& m) {
  OrientedBox box;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m.scatter);
  // Largest variance first; each axis signed so its largest component is positive, the third
  // completing a right-handed frame, so the box does not flip between runs.
  Eigen::Matrix3d axes;
  for (int i = 0; i < 2; ++i) {
    Eigen::Vector3d a = eig.eigenvectors().col(2 - i);
    Eigen::Index k;
    a.cwiseAbs().maxCoeff(&k);
    axes.col(i) = a[k] < 0 ? Eigen::Vector3d(-a) : a;
  }
  axes.col(2) = axes.col(0).cross(axes.col(1)).normalized();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (int p : points) {
    const Eigen::Vector3d q = axes.transpose() * (frame.xyz[p].cast<double>() - m.mean);
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  box.axes = axes;
  box.extent = hi - lo;
  box.centre = m.mean + axes * ((lo + hi) / 2);
  return box;
}

detail::Moments3 point_moments(const Frame& frame, const std::vector<int>& points) {
  return detail::moments(points.size(), [&](std::size_t j) { return frame.xyz[points[j]]; });
}

}  // namespace

OrientedBox oriented_box(const Frame& frame, const std::vector<int>& points) {
  if (points.empty()) return {};
  return box_from_moments(frame, points, point_moments(frame, points));
}

void describe_shape(const Frame& frame, Candidate& c) {
  if (c.points.empty()) {
    c.box = {};
    c.centroid = Eigen::Vector3d::Zero();
    return;
  }
  const detail::Moments3 m = point_moments(frame, c.points);
  c.box = box_from_moments(frame, c.points, m);
  c.centroid = m.mean;
}

}  // namespace proxseg
