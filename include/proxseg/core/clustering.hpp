// Initial clustering [paper Algorithm 1] and k-means [paper 3.2].
#pragma once
#include <Eigen/Core>
#include <string>
#include <vector>

namespace proxseg {

// How the principal axes are found: kDense, a full symmetric eigensolver (tridiagonalisation and
// QR); kLanczos, Krylov iterations until the axes' residuals are 1e-10 of the largest variance
// (a tenth of the cost; the axes agree to about that precision).
enum class PcaSolver { kDense, kLanczos };
// The names of its values, in its order: how the CLI, JSON configs and Python spell them.
inline std::vector<std::string> value_names(PcaSolver) {
  return {"dense", "lanczos"};
}

struct ClusteringParams {
  double alpha = 0.85;  // chi-square confidence of the "same centroid" test (paper: 0.85)
  int pca_dims = 4;     // features are projected on this many principal axes (docs/method.md)
  PcaSolver pca_solver = PcaSolver::kLanczos;
  // Centroid covariance = (n * sample + prior_weight * global) / (n + prior_weight): shrinkage
  // towards the global feature covariance, so a one-voxel centroid has a usable metric. The
  // default (1e6) in effect uses the global covariance for every centroid: best on mOSD learn.
  double prior_weight = 1e6;
  // Scale the colour, texture and shape blocks to equal total variance over the frame before
  // the principal axes are taken, so that no block dominates by its size alone (docs/method.md).
  bool balance_blocks = true;
};

struct Centroid {
  int n = 0;              // voxels merged into it
  Eigen::VectorXd mu;     // mean feature
  Eigen::MatrixXd sigma;  // sample covariance (line 14 of Algorithm 1)
};

// Principal axes of the feature rows: the space Algorithm 1, k-means and the MRF work in.
struct FeatureSpace {
  Eigen::VectorXd mean;       // of the raw features
  Eigen::MatrixXd axes;       // raw dims x pca_dims, orthonormal columns
  Eigen::VectorXd variances;  // along each axis (the global covariance there is diagonal)
};
// (with the dense solver)
FeatureSpace principal_axes(const Eigen::MatrixXf& features, int dims);
// The same with `threads` worker threads (0 = all cores; the result does not depend on it) and
// the given solver.
FeatureSpace principal_axes(const Eigen::MatrixXf& features, int dims, int threads,
                            PcaSolver solver);
// A block of feature columns [start, start + size) and the weight it should carry.
struct FeatureBlock {
  int start = 0, size = 0;
  double weight = 1.0;
};
// Scales each block to a total variance of weight^2 over the rows: equal footing for the blocks,
// then the user's block weights on top (a block whose values are all equal is left as it is).
void balance_blocks(Eigen::MatrixXf& features, const std::vector<FeatureBlock>& blocks);
Eigen::MatrixXd project(const FeatureSpace& space, const Eigen::MatrixXf& features);

// Algorithm 1: breadth-first walk over the voxel graph growing centroids in feature space.
// x: one row per voxel (projected features); neighbours: voxel graph in the same numbering.
// global_variances: the prior covariance (diagonal) used for shrinkage.
std::vector<Centroid> initial_centroids(const Eigen::MatrixXd& x,
                                        const std::vector<std::vector<int>>& neighbours,
                                        const Eigen::VectorXd& global_variances,
                                        const ClusteringParams& params);

// chi-square quantile: P(X <= q) = alpha for d degrees of freedom.
double chi_square_quantile(double alpha, int dof);

struct KMeansParams {
  int max_iterations = 100;
  double tolerance =
      1e-6;  // stop when no centroid moves more than this (relative to the data scale)
};
struct KMeansResult {
  Eigen::MatrixXd centroids;  // k x dims, empty clusters dropped
  std::vector<int> labels;    // per row, 0..k-1
  int iterations = 0;
};
// Lloyd's algorithm from the given centroids (rows).
KMeansResult kmeans(const Eigen::MatrixXd& x, const Eigen::MatrixXd& initial,
                    const KMeansParams& params);

}  // namespace proxseg
