// The normal of a point from its neighbours as Open3D's EstimateNormals computes it (without its
// fast solver): the eigenvector of the smallest eigenvalue of their covariance, the covariance
// from the means of the coordinates and of their products, summed in neighbour order. Recognition's
// descriptors need it to the last bit (the database's stored views were described with Open3D);
// the unorganized frames' normals and the evaluation's box frames use it too.
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <utility>
#include <vector>

namespace proxseg::detail {

// neighbours: (index into points, squared distance), nearest first (NearestPoints::nearest()); at
// least 3 of them, or the result is meaningless.
inline Eigen::Vector3d pca_normal(const std::vector<Eigen::Vector3d>& points,
                                  const std::vector<std::pair<int, double>>& neighbours) {
  Eigen::Matrix<double, 9, 1> m = Eigen::Matrix<double, 9, 1>::Zero();
  for (const auto& [q, d2] : neighbours) {
    const Eigen::Vector3d& p = points[q];
    m(0) += p(0), m(1) += p(1), m(2) += p(2);
    m(3) += p(0) * p(0), m(4) += p(0) * p(1), m(5) += p(0) * p(2);
    m(6) += p(1) * p(1), m(7) += p(1) * p(2), m(8) += p(2) * p(2);
  }
  m /= static_cast<double>(neighbours.size());
  Eigen::Matrix3d cov;
  cov(0, 0) = m(3) - m(0) * m(0);
  cov(1, 1) = m(6) - m(1) * m(1);
  cov(2, 2) = m(8) - m(2) * m(2);
  cov(0, 1) = cov(1, 0) = m(4) - m(0) * m(1);
  cov(0, 2) = cov(2, 0) = m(5) - m(0) * m(2);
  cov(1, 2) = cov(2, 1) = m(7) - m(1) * m(2);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.compute(cov, Eigen::ComputeEigenvectors);
  return solver.eigenvectors().col(0);
}

}  // namespace proxseg::detail
