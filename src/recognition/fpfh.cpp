// FPFH at several radii from one neighbour search per point (fpfh.hpp).
#include "fpfh.hpp"

#include "util/angles.hpp"
#include "util/nearest_points.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace proxseg::detail {
namespace {

constexpr int kBins = 11;  // per angle; three angles

// The max_nn nearest points of each point (itself first) within the radius, nearest first,
// with their squared distances: the list every radius up to it cuts.
struct Neighbours {
  std::vector<std::vector<int>> index;
  std::vector<std::vector<double>> distance2;
};

Neighbours nearest_neighbours(const std::vector<Eigen::Vector3d>& points, int max_nn,
                              double radius) {
  const NearestPoints search(points);
  Neighbours n;
  n.index.resize(points.size());
  n.distance2.resize(points.size());
#pragma omp parallel for schedule(static)
  for (int i = 0; i < static_cast<int>(points.size()); ++i)
    for (const auto& [j, d2] : search.nearest(points[i], max_nn, radius)) {
      n.index[i].push_back(j);
      n.distance2[i].push_back(d2);
    }
  return n;
}

// How many of a point's nearest lie within the radius (squared distance under radius^2).
int within(const std::vector<double>& distance2, double radius) {
  return static_cast<int>(std::lower_bound(distance2.begin(), distance2.end(), radius * radius) -
                          distance2.begin());
}

// The three angles of the pair (p, n), (q, m) in the Darboux frame u, v, w of the point whose
// normal makes the smaller angle with the line between them (u its normal), in the histogram's
// order: theta (the other normal's angle about v, atan2), alpha (the other normal along v) and
// phi (the line's cosine with u); zero for a degenerate pair.
Eigen::Vector3d pair_angles(const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                            const Eigen::Vector3d& q, const Eigen::Vector3d& m) {
  Eigen::Vector3d line = q - p;
  const double length = line.norm();
  if (length == 0.0) return Eigen::Vector3d::Zero();
  Eigen::Vector3d u = n, other = m;
  const double cos_p = n.dot(line) / length, cos_q = m.dot(line) / length;
  double phi = cos_p;
  if (std::acos(std::fabs(cos_p)) > std::acos(std::fabs(cos_q))) {
    u = m;
    other = n;
    line *= -1.0;
    phi = -cos_q;
  }
  Eigen::Vector3d v = line.cross(u);
  const double v_norm = v.norm();
  if (v_norm == 0.0) return Eigen::Vector3d::Zero();
  v /= v_norm;
  const Eigen::Vector3d w = u.cross(v);
  return {std::atan2(w.dot(other), u.dot(other)), v.dot(other), phi};
}

int bin(double x) {
  return std::clamp(static_cast<int>(std::floor(x)), 0, kBins - 1);
}

// SPFH of every point over its first `count[i]` neighbours (the point itself excluded).
Eigen::MatrixXd spfh(const std::vector<Eigen::Vector3d>& points,
                     const std::vector<Eigen::Vector3d>& normals, const Neighbours& nb,
                     const std::vector<int>& count) {
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(3 * kBins, static_cast<Eigen::Index>(points.size()));
#pragma omp parallel for schedule(static)
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    if (count[i] <= 1) continue;
    const double step = 100.0 / static_cast<double>(count[i] - 1);
    for (int k = 1; k < count[i]; ++k) {
      const int j = nb.index[i][k];
      const Eigen::Vector3d a = pair_angles(points[i], normals[i], points[j], normals[j]);
      h(bin(kBins * (a(0) + kPi) / (2.0 * kPi)), i) += step;
      h(bin(kBins * (a(1) + 1.0) * 0.5) + kBins, i) += step;
      h(bin(kBins * (a(2) + 1.0) * 0.5) + 2 * kBins, i) += step;
    }
  }
  return h;
}

// FPFH of every point at one radius: its SPFH plus its neighbours' weighted by the inverse
// squared distance, each angle's histogram of them scaled to sum 100.
Eigen::MatrixXd fpfh(const std::vector<Eigen::Vector3d>& points,
                     const std::vector<Eigen::Vector3d>& normals, const Neighbours& nb,
                     double radius) {
  const int n = static_cast<int>(points.size());
  std::vector<int> count(n);
  for (int i = 0; i < n; ++i) count[i] = within(nb.distance2[i], radius);
  const Eigen::MatrixXd s = spfh(points, normals, nb, count);
  Eigen::MatrixXd f = Eigen::MatrixXd::Zero(3 * kBins, n);
#pragma omp parallel for schedule(static)
  for (int i = 0; i < n; ++i) {
    if (count[i] <= 1) continue;
    double sum[3] = {0.0, 0.0, 0.0};
    for (int k = 1; k < count[i]; ++k) {
      const double d2 = nb.distance2[i][k];
      if (d2 == 0.0) continue;
      const int j = nb.index[i][k];
      for (int b = 0; b < 3 * kBins; ++b) {
        const double weighted = s(b, j) / d2;
        sum[b / kBins] += weighted;
        f(b, i) += weighted;
      }
    }
    for (double& t : sum)
      if (t != 0.0) t = 100.0 / t;
    for (int b = 0; b < 3 * kBins; ++b) {
      f(b, i) *= sum[b / kBins];
      f(b, i) += s(b, i);
    }
  }
  return f;
}

}  // namespace

Eigen::MatrixXd fpfh_features(const std::vector<Eigen::Vector3d>& points,
                              const std::vector<Eigen::Vector3d>& normals,
                              const std::vector<double>& radii, int max_nn) {
  const Eigen::Index n = static_cast<Eigen::Index>(points.size());
  Eigen::MatrixXd out(3 * kBins * static_cast<Eigen::Index>(radii.size()), n);
  if (n == 0 || radii.empty()) return out;
  const Neighbours nb =
      nearest_neighbours(points, max_nn, *std::max_element(radii.begin(), radii.end()));
  for (std::size_t r = 0; r < radii.size(); ++r)
    out.middleRows(static_cast<Eigen::Index>(r) * 3 * kBins, 3 * kBins) =
        fpfh(points, normals, nb, radii[r]);
  return out;
}

}  // namespace proxseg::detail
