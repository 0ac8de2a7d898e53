// Initial clustering [paper Algorithm 1] and k-means [paper 3.2].
#include <proxseg/core/clustering.hpp>

#include "util/parallel_for.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Jacobi>
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace proxseg {

namespace {

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
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(d);
  // Non-zeros per row (compressed rows, columns ascending), built column by column.
  std::vector<int> start(n + 1, 0);
  for (int a = 0; a < d; ++a) {
    const float* column = features.col(cols[a]).data();
    int* count = start.data() + 1;
    for (Eigen::Index k = 0; k < n; ++k) count[k] += column[k] != 0.f;  // vectorises
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<int> index(start[n]);
  std::vector<double> value(start[n]);
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int a = 0; a < d; ++a)
      for (Eigen::Index k = 0; k < n; ++k) {
        const float v = features(k, cols[a]);
        sum(a) += v;
        if (v != 0.f) index[fill[k]] = a, value[fill[k]++] = v;
      }
  }
  const Eigen::VectorXd mean = sum / static_cast<double>(n);
  // Multiply-adds of each path; a dense one costs about a tenth of a scattered sparse one.
  double sparse_work = 0;
  for (Eigen::Index k = 0; k < n; ++k) sparse_work += 0.5 * std::pow(start[k + 1] - start[k], 2.0);
  const double dense_work = 0.5 * static_cast<double>(n) * d * d;
  const int nthreads = detail::thread_count(threads);

  Eigen::MatrixXd cov(d, d);
  constexpr int kPanel = 32;  // output columns per task
  const int panels = (d + kPanel - 1) / kPanel;
  if (sparse_work < 0.1 * dense_work) {
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
  } else {
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
  return cov;
}

// The k largest eigenvalues of the symmetric matrix whose lower triangle is `a`, descending,
// with unit eigenvectors, and the largest eigenvalue. Same algorithm as
// Eigen::SelfAdjointEigenSolver (scaling, Householder tridiagonalisation, implicit symmetric QR
// with Wilkinson shifts), but the Givens rotations are recorded instead of being applied to a
// full d x d basis: the k wanted eigenvectors of the tridiagonal matrix are then the rotations
// applied, last first, to unit vectors, and only those k are taken back through the Householder
// reflections. A full eigen-decomposition of a 454 x 454 covariance costs about 30 ms; this
// costs the tridiagonalisation (a third of that).
struct TopEigen {
  Eigen::VectorXd values;   // k, descending
  Eigen::MatrixXd vectors;  // d x k
  double largest = 0;
};
TopEigen top_eigen(const Eigen::MatrixXd& a, int k) {
  const Eigen::Index d = a.rows();
  TopEigen out;
  if (d == 1) {
    out.values = Eigen::VectorXd::Constant(1, a(0, 0));
    out.vectors = Eigen::MatrixXd::Ones(1, 1);
    out.largest = a(0, 0);
    out.values.conservativeResize(std::min<Eigen::Index>(k, 1));
    out.vectors.conservativeResize(1, out.values.size());
    return out;
  }
  // Map the coefficients to [-1, 1] against over- and underflow.
  Eigen::MatrixXd m = a.triangularView<Eigen::Lower>();
  double scale = m.cwiseAbs().maxCoeff();
  if (scale == 0) scale = 1;
  m /= scale;
  const Eigen::Tridiagonalization<Eigen::MatrixXd> tri(m);
  Eigen::VectorXd diag = tri.diagonal();
  Eigen::VectorXd sub = tri.subDiagonal();

  struct Rotation {
    Eigen::Index k;
    double c, s;
  };
  std::vector<Rotation> rotations;
  const double zero = std::numeric_limits<double>::min();
  const double precision_inv = 1.0 / std::numeric_limits<double>::epsilon();
  const Eigen::Index max_iterations = 30 * d;  // Eigen's default budget
  Eigen::Index end = d - 1, iter = 0;
  while (end > 0) {
    for (Eigen::Index i = 0; i < end; ++i) {  // deflate negligible off-diagonal entries
      const double scaled = precision_inv * sub[i];
      if (std::abs(sub[i]) < zero || scaled * scaled <= std::abs(diag[i]) + std::abs(diag[i + 1]))
        sub[i] = 0;
    }
    while (end > 0 && sub[end - 1] == 0) --end;
    if (end <= 0) break;
    if (++iter > max_iterations) break;  // as Eigen: keep what there is (never seen)
    Eigen::Index start = end - 1;
    while (start > 0 && sub[start - 1] != 0) --start;
    // One implicit QR step with Wilkinson shift on the unreduced block [start, end].
    const double td = (diag[end - 1] - diag[end]) * 0.5, e = sub[end - 1];
    double mu = diag[end];
    if (td == 0) {
      mu -= std::abs(e);
    } else if (e != 0) {
      const double e2 = e * e, h = std::hypot(td, e);
      mu -= e2 == 0 ? e / ((td + (td > 0 ? h : -h)) / e) : e2 / (td + (td > 0 ? h : -h));
    }
    double x = diag[start] - mu, z = sub[start];
    for (Eigen::Index j = start; j < end && z != 0; ++j) {
      Eigen::JacobiRotation<double> rot;
      rot.makeGivens(x, z);
      const double c = rot.c(), s = rot.s();
      const double sdk = s * diag[j] + c * sub[j];
      const double dkp1 = s * sub[j] + c * diag[j + 1];
      diag[j] = c * (c * diag[j] - s * sub[j]) - s * (c * sub[j] - s * diag[j + 1]);
      diag[j + 1] = s * sdk + c * dkp1;
      sub[j] = c * sdk - s * dkp1;
      if (j > start) sub[j - 1] = c * sub[j - 1] - s * z;
      x = sub[j];
      if (j < end - 1) {
        z = -s * sub[j + 1];
        sub[j + 1] = c * sub[j + 1];
      }
      rotations.push_back({j, c, s});  // basis Z <- Z G, G = [c s; -s c] on columns j, j+1
    }
  }
  // Largest first (equal values in position order).
  std::vector<Eigen::Index> order(d);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](Eigen::Index p, Eigen::Index q) { return diag[p] > diag[q]; });
  const Eigen::Index keep = std::min<Eigen::Index>(k, d);
  out.largest = diag[order[0]] * scale;
  out.values.resize(keep);
  Eigen::MatrixXd z = Eigen::MatrixXd::Zero(d, keep);
  for (Eigen::Index c = 0; c < keep; ++c) {
    out.values(c) = diag[order[c]] * scale;
    z(order[c], c) = 1;
  }
  // Z e = G_1 (G_2 (... (G_m e))): apply the rotations to the wanted columns, last first.
  for (auto r = rotations.rbegin(); r != rotations.rend(); ++r)
    for (Eigen::Index c = 0; c < keep; ++c) {
      const double u = z(r->k, c), v = z(r->k + 1, c);
      z(r->k, c) = r->c * u + r->s * v;
      z(r->k + 1, c) = -r->s * u + r->c * v;
    }
  out.vectors = tri.matrixQ() * z;
  return out;
}

// The same k eigenpairs by the Lanczos method with full reorthogonalisation: the Krylov space of
// a fixed start vector grows until the top k Ritz pairs have residuals ||A y - theta y|| under
// 1e-10 of the largest Ritz value. Each step costs one product with the d x d matrix instead of
// the O(d^3) tridiagonalisation, and 40-80 steps suffice for a feature covariance. Falls back to
// top_eigen when the space stops growing before the pairs have converged (an invariant subspace:
// a repeated eigenvalue could be missed) or reaches d.
TopEigen top_eigen_lanczos(const Eigen::MatrixXd& lower, int k) {
  const Eigen::Index d = lower.rows();
  constexpr Eigen::Index kDenseBelow = 64;  // small matrices: the dense solver is cheap and exact
  if (d < kDenseBelow || k >= d / 4) return top_eigen(lower, k);
  const Eigen::MatrixXd a = lower.selfadjointView<Eigen::Lower>();
  constexpr double kTolerance = 1e-10;
  const Eigen::Index max_steps = d - 1;
  Eigen::MatrixXd v(d, max_steps + 1);  // Lanczos vectors
  Eigen::VectorXd alpha(max_steps), beta(max_steps);
  // A fixed start vector with no special direction (the golden-ratio sequence, centred).
  for (Eigen::Index i = 0; i < d; ++i) {
    const double t = static_cast<double>(i + 1) * 0.6180339887498949;
    v(i, 0) = t - std::floor(t) - 0.5;
  }
  v.col(0).normalize();
  Eigen::VectorXd w(d);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ritz;
  for (Eigen::Index j = 0; j < max_steps; ++j) {
    w.noalias() = a * v.col(j);
    alpha(j) = v.col(j).dot(w);
    // Full reorthogonalisation, twice (classical Gram-Schmidt): the three-term recurrence alone
    // loses orthogonality as soon as a Ritz pair converges.
    for (int pass = 0; pass < 2; ++pass)
      w.noalias() -= v.leftCols(j + 1) * (v.leftCols(j + 1).transpose() * w);
    beta(j) = w.norm();
    const Eigen::Index m = j + 1;
    if (m >= k && (m % 4 == 0 || !(beta(j) > 0))) {
      Eigen::MatrixXd t = Eigen::MatrixXd::Zero(m, m);
      t.diagonal() = alpha.head(m);
      t.diagonal(-1) = beta.head(m - 1);
      ritz.compute(t);  // ascending
      const double largest = ritz.eigenvalues()(m - 1);
      bool converged = largest > 0;
      for (int c = 0; c < k && converged; ++c)
        converged =
            std::abs(beta(j) * ritz.eigenvectors()(m - 1, m - 1 - c)) <= kTolerance * largest;
      if (converged) {
        TopEigen out;
        out.largest = largest;
        out.values.resize(k);
        out.vectors.resize(d, k);
        for (int c = 0; c < k; ++c) {
          out.values(c) = ritz.eigenvalues()(m - 1 - c);
          out.vectors.col(c) = (v.leftCols(m) * ritz.eigenvectors().col(m - 1 - c)).normalized();
        }
        return out;
      }
    }
    if (!(beta(j) > 1e-12 * std::abs(alpha(0)))) break;  // invariant subspace: not converged
    v.col(j + 1) = w / beta(j);
  }
  return top_eigen(lower, k);
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

double chi_square_quantile(double alpha, int dof) {
  if (dof < 1 || !(alpha > 0 && alpha < 1))
    throw std::invalid_argument("chi-square: need dof >= 1, 0 < alpha < 1");
  return boost::math::quantile(boost::math::chi_squared(dof), alpha);
}

namespace {

// A centroid of Algorithm 1 with the Cholesky factor of its regularised covariance.
struct Growing {
  Centroid c;
  Eigen::LLT<Eigen::MatrixXd> llt;
};

void refactor(Growing& g, const Eigen::VectorXd& prior, double prior_weight) {
  const double n = g.c.n;
  Eigen::MatrixXd s = (n * g.c.sigma) / (n + prior_weight);
  s.diagonal() += prior * (prior_weight / (n + prior_weight));
  g.llt.compute(s);
}

double mahalanobis(const Growing& g, const Eigen::VectorXd& f) {
  return g.llt.matrixL().solve(f - g.c.mu).squaredNorm();
}

}  // namespace

std::vector<Centroid> initial_centroids(const Eigen::MatrixXd& x,
                                        const std::vector<std::vector<int>>& neighbours,
                                        const Eigen::VectorXd& global_variances,
                                        const ClusteringParams& params) {
  const int n = static_cast<int>(x.rows()), d = static_cast<int>(x.cols());
  if (static_cast<int>(neighbours.size()) != n)
    throw std::invalid_argument("initial_centroids: graph size");
  std::vector<Centroid> out;
  if (n == 0) return out;
  if (d == 0) {  // every feature identical: one centroid
    out.push_back({n, Eigen::VectorXd::Zero(0), Eigen::MatrixXd::Zero(0, 0)});
    return out;
  }
  // Shrinkage target: the global covariance (diagonal on the principal axes), floored so that a
  // nearly constant axis cannot make the metric singular.
  const Eigen::VectorXd prior =
      global_variances.cwiseMax(global_variances.maxCoeff() * 1e-6 + 1e-12);
  const double threshold = chi_square_quantile(params.alpha, d);

  std::vector<Growing> centroids;
  std::vector<char> visited(n, 0), queued(n, 0);
  std::deque<int> queue;
  int next_seed = 0;
  std::vector<std::pair<double, int>> order;
  for (int visits = 0; visits < n; ++visits) {
    // Lines 5-9: pop from the queue, or start a new connected component at the first unvisited
    // voxel (lowest index, so the walk is deterministic).
    int j;
    if (!queue.empty()) {
      j = queue.front();
      queue.pop_front();
    } else {
      while (visited[next_seed]) ++next_seed;
      j = next_seed;
    }
    visited[j] = 1;
    const Eigen::VectorXd f = x.row(j).transpose();
    // Line 10: nearest centroid in Mahalanobis distance.
    int nearest = -1;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t s = 0; s < centroids.size(); ++s) {
      const double dist = mahalanobis(centroids[s], f);
      if (dist < best) best = dist, nearest = static_cast<int>(s);
    }
    int current;
    if (nearest >= 0 && best < threshold) {
      // Lines 12-15: running mean and covariance.
      Centroid& c = centroids[nearest].c;
      const Eigen::VectorXd old_mu = c.mu;
      const double m = c.n;
      c.mu = (m * c.mu + f) / (m + 1);
      c.sigma = (m * c.sigma + m * old_mu * old_mu.transpose() + f * f.transpose() -
                 (m + 1) * c.mu * c.mu.transpose()) /
                (m + 1);
      c.n += 1;
      refactor(centroids[nearest], prior, params.prior_weight);
      current = nearest;
    } else {
      // Lines 17-19: a new centroid at this voxel's feature, zero covariance.
      Growing g;
      g.c = {1, f, Eigen::MatrixXd::Zero(d, d)};
      refactor(g, prior, params.prior_weight);
      centroids.push_back(std::move(g));
      current = static_cast<int>(centroids.size()) - 1;
    }
    // Lines 21-24: queue the neighbours that are neither visited nor queued (the evident intent
    // of line 22), nearest to the current centroid first.
    order.clear();
    for (int k : neighbours[j])
      if (!visited[k] && !queued[k])
        order.emplace_back(mahalanobis(centroids[current], x.row(k).transpose()), k);
    std::sort(order.begin(), order.end());
    for (const auto& [dist, k] : order) {
      queue.push_back(k);
      queued[k] = 1;
    }
  }
  for (auto& g : centroids) out.push_back(std::move(g.c));
  return out;
}

KMeansResult kmeans(const Eigen::MatrixXd& x, const Eigen::MatrixXd& initial,
                    const KMeansParams& params) {
  KMeansResult r;
  r.centroids = initial;
  const Eigen::Index n = x.rows(), d = x.cols();
  r.labels.assign(n, 0);
  if (n == 0 || initial.rows() == 0) {
    r.centroids.resize(0, d);
    return r;
  }
  // Distances and means are summed over the dimensions in order, as Eigen's row-wise squaredNorm
  // and row additions do, so the results are those of the Eigen expressions, bit for bit. The
  // distances to one centroid are computed for all rows at once, down the columns of x (which
  // vectorises).
  const Eigen::MatrixXd xt = x.transpose();  // rows of x as contiguous columns, for the means
  Eigen::ArrayXd dist(n), best(n);
  // Assignment to the nearest centroid (ties to the lowest index); clusters left empty are
  // dropped and the labels renumbered.
  auto assign = [&] {
    for (Eigen::Index c = 0; c < r.centroids.rows(); ++c) {
      dist.setZero();
      for (Eigen::Index j = 0; j < d; ++j) dist += (r.centroids(c, j) - x.col(j).array()).square();
      const int label = static_cast<int>(c);
      for (Eigen::Index i = 0; i < n; ++i)
        if (c == 0 || dist[i] < best[i]) {
          best[i] = dist[i];
          r.labels[i] = label;
        }
    }
    std::vector<int> renumber(r.centroids.rows(), -1);
    for (int l : r.labels) renumber[l] = 0;
    int kept = 0;
    for (int& id : renumber)
      if (id == 0) id = kept++;
    if (kept == r.centroids.rows()) return;
    Eigen::MatrixXd compact(kept, d);
    for (Eigen::Index c = 0; c < r.centroids.rows(); ++c)
      if (renumber[c] >= 0) compact.row(renumber[c]) = r.centroids.row(c);
    r.centroids = std::move(compact);
    for (int& l : r.labels) l = renumber[l];
  };
  // Movement is judged relative to the spread of the data.
  const double scale =
      std::sqrt(std::max((x.rowwise() - x.colwise().mean()).squaredNorm() / n, 1e-300));
  for (int it = 0; it < params.max_iterations; ++it) {
    r.iterations = it + 1;
    assign();
    const Eigen::Index k = r.centroids.rows();
    Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(d, k);  // column c: the sum of cluster c's rows
    Eigen::VectorXd count = Eigen::VectorXd::Zero(k);
    for (Eigen::Index i = 0; i < n; ++i) {
      sum.col(r.labels[i]) += xt.col(i);
      count(r.labels[i]) += 1;
    }
    const Eigen::MatrixXd mean = (sum.array().rowwise() / count.transpose().array()).transpose();
    const double moved = (mean - r.centroids).rowwise().norm().maxCoeff();
    r.centroids = mean;
    if (moved <= params.tolerance * scale) break;
  }
  assign();  // labels agree with the returned centroids
  return r;
}

}  // namespace proxseg
