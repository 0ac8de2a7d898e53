// The leading eigenpairs of a symmetric matrix (top_eigen.hpp).
#include "top_eigen.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Jacobi>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

#include "util/splitmix.hpp"

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
    out.norm = std::abs(a(0, 0));
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
  out.norm = diag.cwiseAbs().maxCoeff() * scale;
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

namespace {

// The growing orthonormal basis V of the block Lanczos space, A V beside it, and the projection
// H = V^T A V on which the Rayleigh-Ritz step runs.
struct KrylovBasis {
  Eigen::MatrixXd v, av, h;
  Eigen::Index size = 0;
  SplitMix random{0x5eed0f7a11eau};  // the start block and the replacements of deflated columns
};

// Removes from w its part in the first `columns` columns of V: classical Gram-Schmidt, twice
// ("twice is enough": one pass leaves rounding error along V once w has mostly cancelled).
void orthogonalise(const KrylovBasis& basis, Eigen::Index columns, Eigen::Ref<Eigen::VectorXd> w) {
  for (int pass = 0; pass < 2; ++pass)
    w.noalias() -= basis.v.leftCols(columns) * (basis.v.leftCols(columns).transpose() * w);
}

// Appends the candidate columns to V, each orthogonalised against V and normalised. A column
// whose part outside V is under 1e-8 of its norm is deflated: its directions are in V already
// (an invariant subspace, a repeated value, a cluster no power of A tells apart), and a seeded
// random vector takes its place, so that the space keeps growing in every direction that is
// left; this is what finds every copy of a repeated eigenvalue.
void append_block(KrylovBasis& basis, const Eigen::MatrixXd& candidates) {
  constexpr double kDeflate = 1e-8;
  const Eigen::Index d = basis.v.rows();
  for (Eigen::Index c = 0; c < candidates.cols() && basis.size < d; ++c) {
    Eigen::VectorXd w = candidates.col(c);
    for (int attempt = 0;; ++attempt) {
      const double before = w.norm();
      orthogonalise(basis, basis.size, w);
      const double after = w.norm();
      if (after > kDeflate * before && after > 0) break;
      if (attempt == 8) return;  // V holds (numerically) the whole space: never seen below d
      for (Eigen::Index i = 0; i < d; ++i) w(i) = basis.random.uniform(-0.5, 0.5);
    }
    basis.v.col(basis.size++) = w.normalized();
  }
}

// A V and H = V^T A V for the columns [from, size) of V.
void extend_projection(const Eigen::MatrixXd& a, KrylovBasis& basis, Eigen::Index from) {
  const Eigen::Index m = basis.size, added = m - from;
  basis.av.middleCols(from, added).noalias() = a * basis.v.middleCols(from, added);
  const Eigen::MatrixXd column = basis.v.leftCols(m).transpose() * basis.av.middleCols(from, added);
  basis.h.block(0, from, m, added) = column;
  basis.h.block(from, 0, added, m) = column.transpose();
  // The new diagonal block symmetric to the last bit, for the dense solver below.
  const Eigen::MatrixXd block = basis.h.block(from, from, added, added);
  basis.h.block(from, from, added, added) = 0.5 * (block + block.transpose());
}

// The top k Ritz pairs of the space when their residuals ||A y - theta y|| (computed from A V,
// not from the recurrence) are all under `tolerance` times the largest magnitude; else nothing.
bool converged_ritz_pairs(const KrylovBasis& basis, int k, double tolerance, TopEigen& out) {
  const Eigen::Index m = basis.size;
  const TopEigen ritz = top_eigen(basis.h.topLeftCorner(m, m), k);
  const Eigen::MatrixXd y = basis.v.leftCols(m) * ritz.vectors;
  const Eigen::MatrixXd residual =
      basis.av.leftCols(m) * ritz.vectors - y * ritz.values.asDiagonal();
  if (ritz.norm > 0 && residual.colwise().norm().maxCoeff() > tolerance * ritz.norm) return false;
  out.values = ritz.values;
  out.vectors = y;
  out.vectors.colwise().normalize();
  out.largest = ritz.largest;
  out.norm = ritz.norm;
  return true;
}

}  // namespace

// The same k eigenpairs by block Lanczos with full reorthogonalisation: the Krylov space of a
// block of b > k seeded random vectors grows by A times the newest block until the top k Ritz
// pairs have residuals under 1e-11 of the largest magnitude. A single start vector sees one
// vector per distinct eigenvalue in exact arithmetic, so it finds the copies of a repeated value
// only through rounding noise (which differs between processors): a block of b holds up to b
// copies by construction, and deflated columns are replaced by random ones (append_block), so
// that repeated and clustered values are found whatever their multiplicity. Each step costs b
// products with the d x d matrix instead of the O(d^3) tridiagonalisation. Falls back to
// top_eigen (which is exact) when the space reaches half the dimension without converging.
TopEigen top_eigen_lanczos(const Eigen::MatrixXd& lower, int k) {
  const Eigen::Index d = lower.rows();
  constexpr Eigen::Index kDenseBelow = 64;  // small matrices: the dense solver is cheap and exact
  if (d < kDenseBelow || k >= d / 4) return top_eigen(lower, k);
  constexpr double kTolerance = 1e-11;
  const Eigen::MatrixXd a = lower.selfadjointView<Eigen::Lower>();
  const Eigen::Index block = std::max<Eigen::Index>(2 * k, k + 4), limit = d / 2;
  KrylovBasis basis;
  basis.v.resize(d, limit + block);
  basis.av.resize(d, limit + block);
  basis.h.resize(limit + block, limit + block);
  Eigen::MatrixXd start(d, block);
  for (Eigen::Index c = 0; c < block; ++c)
    for (Eigen::Index i = 0; i < d; ++i) start(i, c) = basis.random.uniform(-0.5, 0.5);
  append_block(basis, start);
  Eigen::Index from = 0;
  TopEigen out;
  while (basis.size <= limit) {
    extend_projection(a, basis, from);
    if (converged_ritz_pairs(basis, k, kTolerance, out)) return out;
    const Eigen::Index newest = from;
    from = basis.size;
    append_block(basis, basis.av.middleCols(newest, from - newest));
  }
  return top_eigen(lower, k);
}

}  // namespace proxseg::detail
