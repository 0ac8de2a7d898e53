// Mean and scatter matrix of 3D points: the statistics behind every 3x3 principal-axis fit
// (the shape feature's eigenvalues [paper 3.1], voxel normals, plane fits, oriented boxes).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>

namespace proxseg::detail {

struct Moments3 {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  // sum over the points of (p - mean)(p - mean)^T; divided by the count it is the covariance.
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
};

// point(j), j < count, is the j-th point (any Eigen 3-vector); in double, two passes (mean
// first, then deviations: no cancellation for clouds far from the origin). No points: zeros.
template <class Point>
Moments3 moments(std::size_t count, Point&& point) {
  Moments3 m;
  for (std::size_t j = 0; j < count; ++j) m.mean += point(j).template cast<double>();
  m.mean /= std::max<double>(1.0, static_cast<double>(count));
  for (std::size_t j = 0; j < count; ++j) {
    const Eigen::Vector3d d = point(j).template cast<double>() - m.mean;
    m.scatter += d * d.transpose();
  }
  return m;
}

}  // namespace proxseg::detail
