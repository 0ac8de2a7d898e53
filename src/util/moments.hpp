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
  // The upper triangle only (the same products and sums as d d^T, so the same bits), mirrored.
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
  for (std::size_t j = 0; j < count; ++j) {
    const Eigen::Vector3d d = point(j).template cast<double>() - m.mean;
    xx += d.x() * d.x(), xy += d.x() * d.y(), xz += d.x() * d.z();
    yy += d.y() * d.y(), yz += d.y() * d.z(), zz += d.z() * d.z();
  }
  m.scatter << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  return m;
}

}  // namespace proxseg::detail
