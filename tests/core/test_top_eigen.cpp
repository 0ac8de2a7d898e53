// The eigensolvers of the principal axes [paper 3.2] (src/core/top_eigen.hpp) against
// Eigen::SelfAdjointEigenSolver, at the size the features have (454 dimensions: colour 110,
// texture 240, shape 104) and around the size where top_eigen_lanczos starts to use Lanczos.
#include "core/top_eigen.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <cmath>
#include <random>
#include <vector>

namespace {

using proxseg::detail::top_eigen;
using proxseg::detail::top_eigen_lanczos;
using proxseg::detail::TopEigen;

// The covariance of n samples of d features whose scales fall off as the features' histogram
// bins do (a few strong directions, a long tail), some of them sparse.
Eigen::MatrixXd feature_covariance(int n, int d, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> uniform;
  Eigen::MatrixXd x(n, d);
  for (int j = 0; j < d; ++j) {
    const double scale = 1.0 / std::pow(1.0 + j, 0.8);
    for (int i = 0; i < n; ++i) x(i, j) = uniform(rng) < 0.3 ? scale * gauss(rng) : 0.0;
  }
  // Correlated features: mix each with its neighbour.
  for (int j = 1; j < d; ++j) x.col(j) += 0.5 * x.col(j - 1);
  const Eigen::MatrixXd centred = x.rowwise() - x.colwise().mean();
  return centred.transpose() * centred / (n - 1.0);
}

// A symmetric matrix with the given eigenvalues and a random orthonormal basis.
Eigen::MatrixXd with_eigenvalues(const Eigen::VectorXd& values, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss;
  const int d = static_cast<int>(values.size());
  Eigen::MatrixXd g(d, d);
  for (int i = 0; i < d; ++i)
    for (int j = 0; j < d; ++j) g(i, j) = gauss(rng);
  const Eigen::MatrixXd q = Eigen::HouseholderQR<Eigen::MatrixXd>(g).householderQ();
  return q * values.asDiagonal() * q.transpose();
}

// The result is the top k of Eigen's decomposition: values within 1e-10 of the norm, each
// vector a unit eigenvector (residual within 1e-8 of the norm), the vectors orthonormal, and
// where a value stands apart from its neighbours (gap over 1e-6 of the norm) the vector is
// Eigen's up to its sign.
void expect_top_eigen(const Eigen::MatrixXd& a, const TopEigen& got, int k) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> reference(a);
  const Eigen::Index d = a.rows();
  const double largest = reference.eigenvalues()(d - 1);
  // The tolerances scale with the matrix's norm (the largest magnitude; 1 for a zero matrix).
  double norm = reference.eigenvalues().cwiseAbs().maxCoeff();
  if (norm == 0) norm = 1;
  ASSERT_EQ(got.values.size(), std::min<Eigen::Index>(k, d));
  ASSERT_EQ(got.vectors.cols(), got.values.size());
  EXPECT_NEAR(got.largest, largest, 1e-10 * norm);
  for (Eigen::Index c = 0; c < got.values.size(); ++c) {
    const double expected = reference.eigenvalues()(d - 1 - c);
    EXPECT_NEAR(got.values(c), expected, 1e-10 * norm) << "value " << c;
    const Eigen::VectorXd v = got.vectors.col(c);
    EXPECT_NEAR(v.norm(), 1.0, 1e-10) << "vector " << c;
    EXPECT_LE((a * v - got.values(c) * v).norm(), 1e-8 * norm) << "vector " << c;
    const double below = c + 1 < d ? reference.eigenvalues()(d - 2 - c) : -INFINITY;
    const double above = c > 0 ? reference.eigenvalues()(d - c) : INFINITY;
    if (std::min(expected - below, above - expected) > 1e-6 * norm) {
      EXPECT_GT(std::abs(v.dot(reference.eigenvectors().col(d - 1 - c))), 1 - 1e-8)
          << "vector " << c;
    }
  }
  const Eigen::MatrixXd gram = got.vectors.transpose() * got.vectors;
  EXPECT_LT((gram - Eigen::MatrixXd::Identity(gram.rows(), gram.cols())).norm(), 1e-8);
}

TEST(TopEigen, MatchesEigenOnAFeatureCovarianceOf454Dimensions) {
  const Eigen::MatrixXd a = feature_covariance(3000, 454, 1);
  for (int k : {1, 4, 20}) {
    SCOPED_TRACE(k);
    expect_top_eigen(a, top_eigen(a, k), k);
  }
}

TEST(TopEigen, LanczosMatchesEigenOnAFeatureCovarianceOf454Dimensions) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const Eigen::MatrixXd a = feature_covariance(3000, 454, seed);
    for (int k : {1, 4, 20}) {
      SCOPED_TRACE(testing::Message() << "seed " << seed << ", k " << k);
      expect_top_eigen(a, top_eigen_lanczos(a, k), k);
    }
  }
}

TEST(TopEigen, LanczosReadsOnlyTheLowerTriangle) {
  const Eigen::MatrixXd a = feature_covariance(2000, 300, 4);
  Eigen::MatrixXd lower = a.triangularView<Eigen::Lower>();
  lower.triangularView<Eigen::StrictlyUpper>().setConstant(1e6);  // must not be read
  const TopEigen got = top_eigen_lanczos(lower, 4), dense = top_eigen(lower, 4);
  expect_top_eigen(a, got, 4);
  expect_top_eigen(a, dense, 4);
}

// Eigenvalues 1 / (1 + i) below `leading`, which are the largest, in random directions.
Eigen::MatrixXd with_leading(const std::vector<double>& leading, int d, unsigned seed) {
  Eigen::VectorXd values(d);
  for (int i = 0; i < d; ++i) values(i) = 1.0 / (1 + i);
  for (std::size_t i = 0; i < leading.size(); ++i) values(d - 1 - static_cast<int>(i)) = leading[i];
  return with_eigenvalues(values, seed);
}

// A Krylov space grown from one start vector holds one vector per distinct eigenvalue in exact
// arithmetic: it finds the repeated copies only through rounding noise, which differs between
// processors. Any orthonormal basis of a repeated value's space is right, and every copy must be
// there, whatever the multiplicity.
TEST(TopEigen, RepeatedLeadingEigenvaluesGiveAnOrthonormalBasisOfTheirSpace) {
  for (int copies : {2, 3, 10}) {
    for (int d : {200, 454}) {
      const Eigen::MatrixXd a = with_leading(std::vector<double>(copies, 5.0), d, 5 + copies);
      for (int k : {1, 4, 12}) {
        SCOPED_TRACE(testing::Message() << copies << " copies, d " << d << ", k " << k);
        expect_top_eigen(a, top_eigen(a, k), k);
        expect_top_eigen(a, top_eigen_lanczos(a, k), k);
      }
    }
  }
}

// A repeated value below a distinct leading one (5, then 3 ten times), and two repeated groups.
TEST(TopEigen, RepeatedValuesBelowTheLeadingOneAreAllFound) {
  const std::vector<std::vector<double>> cases = {
      {5, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3}, {5, 5, 3, 3, 3, 2}, {4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4}};
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const Eigen::MatrixXd a = with_leading(cases[c], 300, 40 + static_cast<unsigned>(c));
    for (int k : {2, 4, 8, 13}) {
      SCOPED_TRACE(testing::Message() << "case " << c << ", k " << k);
      expect_top_eigen(a, top_eigen_lanczos(a, k), k);
    }
  }
}

// Leading values 1e-9 apart (relative): numerically distinct, but no power of the matrix tells
// them apart in fewer than ~1e9 steps; the space must hold all of them to order them.
TEST(TopEigen, ClusteredLeadingEigenvaluesAreAllFound) {
  for (int copies : {2, 3, 10}) {
    std::vector<double> leading(copies);
    for (int i = 0; i < copies; ++i) leading[i] = 5.0 * (1 + 1e-9 * (copies - 1 - i));
    for (int d : {200, 454}) {
      const Eigen::MatrixXd a = with_leading(leading, d, 20 + copies);
      for (int k : {1, 4, 12}) {
        SCOPED_TRACE(testing::Message() << copies << " clustered, d " << d << ", k " << k);
        expect_top_eigen(a, top_eigen(a, k), k);
        expect_top_eigen(a, top_eigen_lanczos(a, k), k);
      }
    }
  }
}

TEST(TopEigen, SizesAroundTheLanczosThresholdAndSmallMatrices) {
  for (int d : {1, 2, 3, 63, 64, 65, 128}) {
    Eigen::VectorXd values(d);
    for (int i = 0; i < d; ++i) values(i) = std::exp(-0.1 * i) + 0.01 * i;
    const Eigen::MatrixXd a = with_eigenvalues(values, 10 + d);
    for (int k : {1, 4, d}) {
      SCOPED_TRACE(testing::Message() << "d " << d << ", k " << k);
      expect_top_eigen(a, top_eigen(a, k), k);
      expect_top_eigen(a, top_eigen_lanczos(a, k), k);
    }
  }
}

TEST(TopEigen, ARankDeficientCovarianceHasZeroTrailingValues) {
  // Fewer samples than dimensions (a frame with few voxels): rank n - 1, and the zero value
  // repeated hundreds of times.
  for (int n : {2, 5, 30}) {
    const Eigen::MatrixXd a = feature_covariance(n, 454, 6);
    for (int k : {4, 40}) {
      SCOPED_TRACE(testing::Message() << "n " << n << ", k " << k);
      const TopEigen got = top_eigen_lanczos(a, k);
      expect_top_eigen(a, got, k);
      if (n - 1 < k) {
        EXPECT_LT(std::abs(got.values(n - 1)), 1e-10 * got.largest);
      }
    }
  }
  // A zero matrix and a rank-one one.
  const Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(100, 100);
  expect_top_eigen(zero, top_eigen_lanczos(zero, 4), 4);
  Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(100, -1, 2);
  const Eigen::MatrixXd rank_one = u * u.transpose();
  expect_top_eigen(rank_one, top_eigen_lanczos(rank_one, 4), 4);
}

TEST(TopEigen, ALargeMatrixMatchesEigen) {
  const Eigen::MatrixXd a = feature_covariance(4000, 1000, 7);
  expect_top_eigen(a, top_eigen_lanczos(a, 4), 4);
  const Eigen::MatrixXd repeated = with_leading({2, 2, 2, 2}, 1000, 8);
  expect_top_eigen(repeated, top_eigen_lanczos(repeated, 6), 6);
}

TEST(TopEigen, NegativeAndMixedSpectraMatchEigen) {
  // Covariances are positive semi-definite, but the solvers take any symmetric matrix: the
  // largest values are the most positive ones.
  Eigen::VectorXd values = Eigen::VectorXd::LinSpaced(150, -3, 1);
  values(0) = -10;  // the largest magnitude is negative
  const Eigen::MatrixXd a = with_eigenvalues(values, 9);
  for (int k : {1, 4}) expect_top_eigen(a, top_eigen_lanczos(a, k), k);
}

}  // namespace
