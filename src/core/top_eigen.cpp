// The leading eigenpairs of a symmetric matrix (top_eigen.hpp).
#include "top_eigen.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Jacobi>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

namespace proxseg::detail {

namespace {

// A Givens rotation of the implicit QR steps: basis Z <- Z G, G = [c s; -s c] on columns k, k+1.
struct Rotation {
  Eigen::Index k;
  double c, s;
};

// Implicit symmetric QR with Wilkinson shifts on the tridiagonal matrix (diag, sub), as
// Eigen::SelfAdjointEigenSolver runs it: diag ends as the eigenvalues; returns the rotations.
std::vector<Rotation> qr_rotations(Eigen::VectorXd& diag, Eigen::VectorXd& sub) {
  const Eigen::Index d = diag.size();
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
  return rotations;
}

}  // namespace

// The k largest eigenvalues of the symmetric matrix whose lower triangle is `a`, descending,
// with unit eigenvectors, and the largest eigenvalue. Same algorithm as
// Eigen::SelfAdjointEigenSolver (scaling, Householder tridiagonalisation, implicit symmetric QR
// with Wilkinson shifts), but the Givens rotations are recorded instead of being applied to a
// full d x d basis: the k wanted eigenvectors of the tridiagonal matrix are then the rotations
// applied, last first, to unit vectors, and only those k are taken back through the Householder
// reflections. A full eigen-decomposition of a 454 x 454 covariance costs about 30 ms; this
// costs the tridiagonalisation (a third of that).
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

  const std::vector<Rotation> rotations = qr_rotations(diag, sub);
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

}  // namespace proxseg::detail
