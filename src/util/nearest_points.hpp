// Exact nearest-neighbour queries among a fixed set of 3D points: a uniform grid of cells
// searched ring by ring outwards from the query's cell, until no point further out can be nearer
// than the k-th found. For the segmentation path's few searches (sparse voxels to their nearest
// clustered voxel, weak points to their cluster, the neighbours of an unorganized cloud's
// normals), without a k-d tree library.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <utility>
#include <vector>

namespace proxseg::detail {

class NearestPoints {
 public:
  explicit NearestPoints(std::vector<Eigen::Vector3d> points) : points_(std::move(points)) {
    if (points_.empty()) return;
    lo_ = hi_ = points_[0];
    for (const auto& p : points_) lo_ = lo_.cwiseMin(p), hi_ = hi_.cwiseMax(p);
    // About two points per cell over the box (a thin extent counts as a thousandth of the
    // largest), then coarser until there are at most about 4 cells per point.
    const Eigen::Vector3d extent = hi_ - lo_;
    const double largest = std::max(extent.maxCoeff(), 1e-9);
    const double volume = extent.cwiseMax(largest / 1000).prod();
    const double n = static_cast<double>(points_.size());
    cell_ = std::max(std::cbrt(2 * volume / n), largest / 1000);
    auto total = [&] {
      double cells = 1;
      for (int a = 0; a < 3; ++a) cells *= std::floor(extent[a] / cell_) + 1;
      return cells;
    };
    while (total() > 4 * n + 64) cell_ *= 1.26;
    for (int a = 0; a < 3; ++a) dims_[a] = static_cast<int>(std::floor(extent[a] / cell_)) + 1;
    // Points by cell (a counting sort): cell c holds order_[start_[c] .. start_[c + 1]).
    start_.assign(static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2] + 1, 0);
    for (const auto& p : points_) ++start_[index(cell_of(p)) + 1];
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    std::vector<int> next(start_.begin(), start_.end() - 1);
    order_.resize(points_.size());
    for (std::size_t i = 0; i < points_.size(); ++i)
      order_[next[index(cell_of(points_[i]))]++] = static_cast<int>(i);
  }

  std::size_t size() const { return points_.size(); }

  // The k nearest points to q (fewer when there are fewer), nearest first, ties to the smaller
  // index; each as (index, squared distance). With a radius, only those at a squared distance
  // under radius^2: the k nearest cut at the radius, as Open3D's hybrid search gives them.
  // The squared distance is summed x, y, z in that order, as nanoflann (Open3D's) does.
  std::vector<std::pair<int, double>> nearest(
      const Eigen::Vector3d& q, int k,
      double radius = std::numeric_limits<double>::infinity()) const {
    std::vector<std::pair<int, double>> best;
    if (points_.empty() || k <= 0) return best;
    const double radius2 = radius * radius;
    const auto closer = [](const std::pair<int, double>& a, const std::pair<int, double>& b) {
      return a.second < b.second || (a.second == b.second && a.first < b.first);
    };
    const auto distance2 = [&](int i) {
      const Eigen::Vector3d d = points_[i] - q;
      return d.x() * d.x() + d.y() * d.y() + d.z() * d.z();
    };
    if (std::isfinite(radius)) {
      // Every point within the radius, then the k nearest of them: cheaper than keeping a
      // sorted list of k while the rings are walked (FPFH's 100 neighbours).
      walk_rings(
          q,
          [&](int i) {
            const double d2 = distance2(i);
            if (d2 < radius2) best.emplace_back(i, d2);
          },
          [&](double reach2) { return reach2 >= radius2; });
      if (static_cast<int>(best.size()) > k) {
        std::nth_element(best.begin(), best.begin() + k, best.end(), closer);
        best.resize(k);
      }
      std::sort(best.begin(), best.end(), closer);
      return best;
    }
    walk_rings(
        q,
        [&](int i) {
          const std::pair<int, double> c{i, distance2(i)};
          if (static_cast<int>(best.size()) == k && !closer(c, best.back())) return;
          best.insert(std::upper_bound(best.begin(), best.end(), c, closer), c);
          if (static_cast<int>(best.size()) > k) best.pop_back();
        },
        [&](double reach2) {
          return static_cast<int>(best.size()) == k && best.back().second <= reach2;
        });
    return best;
  }

 private:
  // Calls visit(i) for the points of the cells around q, ring by ring outwards from q's cell
  // (clamped into the grid), until done(reach2) holds for the squared distance below which no
  // point of a further ring lies. A point of a cell r + 1 or more cells from q's lies at least r
  // cells from q's nearest point of the box, and q is `outside` further (the box is convex):
  // squared distance at least (r cell)^2 + outside^2.
  template <typename Visit, typename Done>
  void walk_rings(const Eigen::Vector3d& q, Visit visit, Done done) const {
    const std::array<int, 3> centre = cell_of(q);
    const double outside2 = (q - q.cwiseMax(lo_).cwiseMin(hi_)).squaredNorm();
    const int last = std::max({dims_[0], dims_[1], dims_[2]});
    for (int r = 0; r <= last; ++r) {
      for (int x = centre[0] - r; x <= centre[0] + r; ++x) {
        if (x < 0 || x >= dims_[0]) continue;
        for (int y = centre[1] - r; y <= centre[1] + r; ++y) {
          if (y < 0 || y >= dims_[1]) continue;
          const bool side = std::abs(x - centre[0]) == r || std::abs(y - centre[1]) == r;
          // On the ring's sides every z; elsewhere only its top and bottom.
          for (int z = centre[2] - r; z <= centre[2] + r; z += side || r == 0 ? 1 : 2 * r) {
            if (z < 0 || z >= dims_[2]) continue;
            const std::size_t c = index({x, y, z});
            for (int j = start_[c]; j < start_[c + 1]; ++j) visit(order_[j]);
          }
        }
      }
      if (done((r * cell_) * (r * cell_) + outside2)) break;
    }
  }

  std::array<int, 3> cell_of(const Eigen::Vector3d& p) const {
    std::array<int, 3> c;
    for (int a = 0; a < 3; ++a)
      c[a] = static_cast<int>(
          std::clamp(std::floor((p[a] - lo_[a]) / cell_), 0.0, static_cast<double>(dims_[a] - 1)));
    return c;
  }
  std::size_t index(const std::array<int, 3>& c) const {
    return (static_cast<std::size_t>(c[2]) * dims_[1] + c[1]) * dims_[0] + c[0];
  }

  std::vector<Eigen::Vector3d> points_;
  Eigen::Vector3d lo_ = Eigen::Vector3d::Zero(), hi_ = Eigen::Vector3d::Zero();
  double cell_ = 1;
  std::array<int, 3> dims_{1, 1, 1};
  std::vector<int> start_, order_;
};

}  // namespace proxseg::detail
