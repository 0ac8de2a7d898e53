// The feature space of the clustering [paper 3.2]: covariance of the features, their principal
// axes (top_eigen.hpp), the blocks' balance and the projection.
#include <proxseg/core/clustering.hpp>

#include "top_eigen.hpp"
#include "util/parallel_for.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

namespace proxseg {
namespace {

using detail::top_eigen;
using detail::top_eigen_lanczos;
using detail::TopEigen;

struct SparseRows {
  std::vector<int> start, index;  // row k's entries are [start[k], start[k + 1]), columns ascending
  std::vector<double> value;
  Eigen::VectorXd sum;  // of each column
};

// The non-zeros of the columns `cols` of `features` as compressed rows, built column by column.
SparseRows sparse_rows(const Eigen::MatrixXf& features, const std::vector<int>& cols) {
  const Eigen::Index n = features.rows();
  const int d = static_cast<int>(cols.size());
  SparseRows r;
  r.sum = Eigen::VectorXd::Zero(d);
  std::vector<int>& start = r.start;
  start.assign(n + 1, 0);
  for (int a = 0; a < d; ++a) {
    const float* column = features.col(cols[a]).data();
    int* count = start.data() + 1;
    for (Eigen::Index k = 0; k < n; ++k) count[k] += column[k] != 0.f;  // vectorises
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  r.index.resize(start[n]);
  r.value.resize(start[n]);
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int a = 0; a < d; ++a)
    for (Eigen::Index k = 0; k < n; ++k) {
      const float v = features(k, cols[a]);
      r.sum(a) += v;
      if (v != 0.f) r.index[fill[k]] = a, r.value[fill[k]++] = v;
    }
  return r;
}

constexpr int kPanel = 32;  // output columns per task

// The sparse path: S accumulated over the non-zeros, then S - n m m^T.
void sparse_covariance(const SparseRows& rows, Eigen::Index n, const Eigen::VectorXd& mean,
                       int nthreads, Eigen::MatrixXd& cov) {
  const int d = static_cast<int>(mean.size());
  const int panels = (d + kPanel - 1) / kPanel;
  const std::vector<int>& start = rows.start;
  const std::vector<int>& index = rows.index;
  const std::vector<double>& value = rows.value;
  const Eigen::VectorXd& sum = rows.sum;
  // Row a of the lower triangle, S(a, 0..a), belongs to one task; within it the rows k of the
  // features are added in order.
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> s =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>::Zero(d, d);
  detail::parallel_for(
      panels, nthreads,
      [&](int p) {
        const int a0 = p * kPanel, a1 = std::min(d, a0 + kPanel);
        for (Eigen::Index k = 0; k < n; ++k) {
          const int* idx = index.data() + start[k];
          const double* val = value.data() + start[k];
          const int m = start[k + 1] - start[k];
          const int first = static_cast<int>(std::lower_bound(idx, idx + m, a0) - idx);
          const int last = static_cast<int>(std::lower_bound(idx + first, idx + m, a1) - idx);
          // Each entry takes one product per feature row, so within a row the products may come
          // in any order: four output rows at a time share the loads of the column indices and
          // values.
          int i = first;
          for (; i + 3 < last; i += 4) {
            double* row[4];
            double v[4];
            for (int r = 0; r < 4; ++r) {
              row[r] = s.data() + static_cast<Eigen::Index>(idx[i + r]) * d;
              v[r] = val[i + r];
            }
            for (int j = 0; j <= i; ++j) {
              const int c = idx[j];
              const double f = val[j];
              row[0][c] += v[0] * f;
              row[1][c] += v[1] * f;
              row[2][c] += v[2] * f;
              row[3][c] += v[3] * f;
            }
            for (int r = 1; r < 4; ++r)  // the triangle's corner
              for (int j = i + 1; j <= i + r; ++j) row[r][idx[j]] += v[r] * val[j];
          }
          for (; i < last; ++i) {
            double* row = s.data() + static_cast<Eigen::Index>(idx[i]) * d;
            for (int j = 0; j <= i; ++j) row[idx[j]] += val[i] * val[j];
          }
        }
      },
      1);
  for (int a = 0; a < d; ++a)
    for (int b = 0; b <= a; ++b) cov(a, b) = (s(a, b) - mean(b) * sum(a)) / (n - 1.0);
}

// The dense path: the product of the centred columns.
void dense_covariance(const Eigen::MatrixXf& features, const std::vector<int>& cols,
                      const Eigen::VectorXd& mean, int nthreads, Eigen::MatrixXd& cov) {
  const Eigen::Index n = features.rows();
  const int d = static_cast<int>(cols.size());
  const int panels = (d + kPanel - 1) / kPanel;
  Eigen::MatrixXd centred(n, d);
  for (int a = 0; a < d; ++a) {
    centred.col(a) = features.col(cols[a]).cast<double>().array() - mean(a);
  }
  // Panel p: columns [b0, b1) of the lower triangle, rows b0..d-1.
  detail::parallel_for(
      panels, nthreads,
      [&](int p) {
        const int b0 = p * kPanel, w = std::min(d, b0 + kPanel) - b0;
        cov.block(b0, b0, d - b0, w).noalias() =
            centred.rightCols(d - b0).transpose() * centred.middleCols(b0, w) / (n - 1.0);
      },
      1);
}

// Covariance (lower triangle only) of the columns `cols` of `features`, in double. Histogram
// features are mostly zeros (about 1 value in 8 is non-zero on mOSD), so when that pays the
// cross products are accumulated over the non-zeros only, as S - n m m^T with S = sum f f^T (the
// products of two floats are exact in double); dense features use a dense product of the
// centred columns. Every entry is summed by one thread in row order: the result does not depend
// on the number of threads.
Eigen::MatrixXd covariance_lower(const Eigen::MatrixXf& features, const std::vector<int>& cols,
                                 int threads) {
  const Eigen::Index n = features.rows();
  const int d = static_cast<int>(cols.size());
  const SparseRows rows = sparse_rows(features, cols);
  const Eigen::VectorXd mean = rows.sum / static_cast<double>(n);
  // Multiply-adds of each path; a dense one costs about a tenth of a scattered sparse one.
  double sparse_work = 0;
  for (Eigen::Index k = 0; k < n; ++k)
    sparse_work += 0.5 * std::pow(rows.start[k + 1] - rows.start[k], 2.0);
  const double dense_work = 0.5 * static_cast<double>(n) * d * d;
  const int nthreads = detail::thread_count(threads);
  Eigen::MatrixXd cov(d, d);
  if (sparse_work < 0.1 * dense_work)
    sparse_covariance(rows, n, mean, nthreads, cov);
  else
    dense_covariance(features, cols, mean, nthreads, cov);
  return cov;
}

}  // namespace

FeatureSpace principal_axes(const Eigen::MatrixXf& features, int dims) {
  return principal_axes(features, dims, 0, PcaSolver::kDense);
}

FeatureSpace principal_axes(const Eigen::MatrixXf& features, int dims, int threads,
                            PcaSolver solver) {
  FeatureSpace space;
  const Eigen::Index n = features.rows(), d = features.cols();
  space.mean = n > 0 ? Eigen::VectorXd(features.cast<double>().colwise().mean().transpose())
                     : Eigen::VectorXd::Zero(d);
  space.axes = Eigen::MatrixXd::Zero(d, 0);
  space.variances = Eigen::VectorXd::Zero(0);
  if (n < 2) return space;
  // Constant columns (bins no voxel of the frame uses, switched-off blocks) carry no variance:
  // the eigenproblem is solved on the others, and the axes are zero in those columns.
  std::vector<int> varying;
  for (Eigen::Index c = 0; c < d; ++c)
    if ((features.col(c).array() != features(0, c)).any()) varying.push_back(static_cast<int>(c));
  if (varying.empty()) return space;
  const Eigen::MatrixXd cov = covariance_lower(features, varying, threads);
  const int k = std::min<int>(dims, d);
  const TopEigen eig =
      solver == PcaSolver::kLanczos ? top_eigen_lanczos(cov, k) : top_eigen(cov, k);
  // Keep the leading axes, but none that carries no variance (switched-off blocks, n < dims).
  const double floor = std::max(eig.largest, 0.0) * 1e-9;
  int keep = 0;
  while (keep < eig.values.size() && eig.values(keep) > floor) ++keep;
  space.axes = Eigen::MatrixXd::Zero(d, keep);
  space.variances.resize(keep);
  for (int a = 0; a < keep; ++a) {
    Eigen::VectorXd axis = eig.vectors.col(a);
    // Fix the sign (largest component positive) so the projection is reproducible.
    Eigen::Index arg;
    axis.cwiseAbs().maxCoeff(&arg);
    if (axis(arg) < 0) axis = -axis;
    for (std::size_t c = 0; c < varying.size(); ++c) space.axes(varying[c], a) = axis(c);
    space.variances(a) = eig.values(a);
  }
  return space;
}

void balance_blocks(Eigen::MatrixXf& features, const std::vector<FeatureBlock>& blocks) {
  if (features.rows() < 2) return;
  for (const FeatureBlock& b : blocks) {
    auto block = features.middleCols(b.start, b.size);
    const Eigen::RowVectorXf mean = block.colwise().mean();
    const double variance = (block.rowwise() - mean).squaredNorm() / (features.rows() - 1.0);
    if (variance > 0) block *= static_cast<float>(b.weight / std::sqrt(variance));
  }
}

Eigen::MatrixXd project(const FeatureSpace& space, const Eigen::MatrixXf& features) {
  // By blocks of rows: the centred double copy of the whole matrix (10 MB for 3000 voxels) would
  // cost more in fresh memory than the product itself.
  constexpr Eigen::Index kBlock = 256;
  Eigen::MatrixXd x(features.rows(), space.axes.cols());
  Eigen::MatrixXd centred;
  for (Eigen::Index r = 0; r < features.rows(); r += kBlock) {
    const Eigen::Index m = std::min(kBlock, features.rows() - r);
    centred = features.middleRows(r, m).cast<double>().rowwise() - space.mean.transpose();
    x.middleRows(r, m).noalias() = centred * space.axes;
  }
  return x;
}

}  // namespace proxseg
