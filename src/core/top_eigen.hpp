// The leading eigenpairs of a symmetric matrix, for the principal axes of the features
// [paper 3.2]: a QR solver that takes back only the wanted eigenvectors, and block Lanczos for
// large matrices (top_eigen.cpp says how and why). tests/core/test_top_eigen.cpp checks both
// against Eigen::SelfAdjointEigenSolver.
#pragma once
#include <Eigen/Core>

namespace proxseg::detail {

struct TopEigen {
  Eigen::VectorXd values;   // k, descending
  Eigen::MatrixXd vectors;  // d x k
  double largest = 0;       // the largest eigenvalue
  double norm = 0;          // the largest magnitude of an eigenvalue (the spectral norm)
};

// The k largest eigenvalues of the symmetric matrix whose lower triangle is `a`, descending,
// with unit eigenvectors, and the largest eigenvalue (Eigen::SelfAdjointEigenSolver's algorithm).
TopEigen top_eigen(const Eigen::MatrixXd& a, int k);

// The same k eigenpairs by block Lanczos, every copy of a repeated value included; falls back
// to top_eigen where it does not converge.
TopEigen top_eigen_lanczos(const Eigen::MatrixXd& lower, int k);

}  // namespace proxseg::detail
