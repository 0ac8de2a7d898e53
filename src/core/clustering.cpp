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
