// Weak connections [paper 3.3]: point density against the cluster's median, Euclidean
// components of the dense points, reattachment of the rest (weak_links.hpp).
#include "weak_links.hpp"

#include "cell_index.hpp"
#include "util/nearest_points.hpp"
#include "util/parallel_for.hpp"
#include "util/union_find.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace proxseg::detail {
namespace {

// Per point, the number of points of its own cluster within radius (itself included), scaled by
// the squared range on organized frames.
std::vector<float> point_density(const Frame& frame, const std::vector<int>& points,
                                 const std::vector<int>& group, double radius, int threads) {
  const CellIndex index(frame, points, group, radius);
  const float r2 = static_cast<float>(radius * radius);
  std::vector<float> density(frame.size(), 0.0f);
  const std::vector<int>& order = index.order();
  detail::parallel_for(
      static_cast<int>(index.cells()), detail::thread_count(threads),
      [&](int c) {
        const CellKey k = index.cell(c);
        std::vector<int> near;
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int n = index.find({k.group, k.x + dx, k.y + dy, k.z + dz});
              if (n >= 0) near.push_back(n);
            }
        for (int i = index.begin(c); i < index.end(c); ++i) {
          const int p = order[i];
          int count = 0;
          for (int n : near)
            for (int j = index.begin(n); j < index.end(n); ++j)
              count += (frame.xyz[order[j]] - frame.xyz[p]).squaredNorm() <= r2;
          density[p] =
              static_cast<float>(count) * (frame.organized() ? frame.xyz[p].squaredNorm() : 1);
        }
      },
      64);
  return density;
}

}  // namespace

std::vector<int> euclidean_components(const Frame& frame, const std::vector<int>& points,
                                      const std::vector<int>& group, double tolerance) {
  const double side = tolerance / std::sqrt(3.0) * (1 - 1e-9);
  const CellIndex index(frame, points, group, side);
  const float t2 = static_cast<float>(tolerance * tolerance);
  const std::vector<int>& order = index.order();
  const int reach = static_cast<int>(std::ceil(tolerance / side));
  // Per cell, the bounding box of its points: two cells whose boxes are farther apart than t
  // cannot link, two whose boxes are within t link without looking at points.
  std::vector<Eigen::Vector3f> lo(index.cells()), hi(index.cells());
  for (std::size_t c = 0; c < index.cells(); ++c) {
    lo[c] = hi[c] = frame.xyz[order[index.begin(c)]];
    for (int i = index.begin(c) + 1; i < index.end(c); ++i) {
      lo[c] = lo[c].cwiseMin(frame.xyz[order[i]]);
      hi[c] = hi[c].cwiseMax(frame.xyz[order[i]]);
    }
  }
  // Neighbour offsets nearest first: once the near cells are linked, the far ones are usually in
  // the same set already and are skipped without a look at their points.
  std::vector<Eigen::Vector3i> offsets;
  for (int dz = -reach; dz <= reach; ++dz)
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx)
        if (dx || dy || dz) offsets.emplace_back(dx, dy, dz);
  std::stable_sort(offsets.begin(), offsets.end(),
                   [](const auto& a, const auto& b) { return a.squaredNorm() < b.squaredNorm(); });
  detail::UnionFind sets(index.cells());
  for (int c = 0; c < static_cast<int>(index.cells()); ++c) {
    const CellKey k = index.cell(c);
    for (const Eigen::Vector3i& d : offsets) {
      const int n = index.find({k.group, k.x + d.x(), k.y + d.y(), k.z + d.z()});
      if (n <= c || sets.find(n) == sets.find(c)) continue;
      const Eigen::Vector3f gap =
          (lo[n] - hi[c]).cwiseMax(lo[c] - hi[n]).cwiseMax(Eigen::Vector3f::Zero());
      if (gap.squaredNorm() > t2) continue;
      const Eigen::Vector3f span = hi[c].cwiseMax(hi[n]) - lo[c].cwiseMin(lo[n]);
      bool linked = span.squaredNorm() <= t2;
      for (int i = index.begin(c); i < index.end(c) && !linked; ++i)
        for (int j = index.begin(n); j < index.end(n) && !linked; ++j)
          linked = (frame.xyz[order[i]] - frame.xyz[order[j]]).squaredNorm() <= t2;
      if (linked) sets.unite(c, n);
    }
  }
  std::vector<int> component(frame.size(), -1);
  for (std::size_t c = 0; c < index.cells(); ++c)
    for (int i = index.begin(c); i < index.end(c); ++i) component[order[i]] = sets.find(c);
  return component;
}

DensitySplit split_weak_points(const Frame& frame, const std::vector<int>& labelled,
                               const std::vector<int>& cluster, int clusters,
                               const SelectionParams& params, int threads) {
  const std::vector<float> density =
      point_density(frame, labelled, cluster, params.density_radius, threads);
  std::vector<std::vector<float>> per_cluster(clusters);
  for (int p : labelled) per_cluster[cluster[p]].push_back(density[p]);
  std::vector<float> threshold(clusters, 0.0f);
  for (int c = 0; c < clusters; ++c) {
    auto& d = per_cluster[c];
    std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
    threshold[c] = static_cast<float>(params.weak_density_ratio) * d[d.size() / 2];
  }
  DensitySplit out;
  std::vector<int> weak;
  std::vector<char> cluster_has_dense(clusters, 0);
  for (int p : labelled) {
    if (density[p] >= threshold[cluster[p]]) {
      out.dense.push_back(p);
      cluster_has_dense[cluster[p]] = 1;
    } else {
      weak.push_back(p);
    }
  }
  out.is_weak.assign(frame.size(), 0);
  for (int p : weak) {
    (cluster_has_dense[cluster[p]] ? out.set_aside : out.dense).push_back(p);
    out.is_weak[p] = cluster_has_dense[cluster[p]];
  }
  std::sort(out.dense.begin(), out.dense.end());
  return out;
}

void reattach_weak_points(const Frame& frame, const VoxelGrid& grid, const DensitySplit& split,
                          const std::vector<int>& cluster, int clusters,
                          std::vector<int>& component) {
  std::vector<int> orphans;
  for (int p : split.set_aside) {
    const int v = grid.voxel_of_point[p];
    float best = INFINITY;
    int nearest = -1;
    auto scan = [&](int voxel) {
      for (int q : grid.points[voxel]) {
        if (cluster[q] != cluster[p] || component[q] < 0 || split.is_weak[q]) continue;
        const float d = (frame.xyz[q] - frame.xyz[p]).squaredNorm();
        if (d < best) best = d, nearest = q;
      }
    };
    scan(v);
    for (int n : grid.neighbours[v]) scan(n);
    if (nearest >= 0)
      component[p] = component[nearest];
    else
      orphans.push_back(p);
  }
  if (orphans.empty()) return;
  std::vector<std::vector<int>> dense_of(clusters), orphans_of(clusters);
  for (int p : split.dense) dense_of[cluster[p]].push_back(p);
  for (int p : orphans) orphans_of[cluster[p]].push_back(p);
  for (int c = 0; c < clusters; ++c) {
    if (orphans_of[c].empty()) continue;
    if (dense_of[c].empty()) continue;
    std::vector<Eigen::Vector3d> xyz(dense_of[c].size());
    for (std::size_t i = 0; i < dense_of[c].size(); ++i)
      xyz[i] = frame.xyz[dense_of[c][i]].cast<double>();
    const detail::NearestPoints index(std::move(xyz));
    for (int p : orphans_of[c]) {
      const int nearest = index.nearest(frame.xyz[p].cast<double>(), 1)[0].first;
      component[p] = component[dense_of[c][nearest]];
    }
  }
}

}  // namespace proxseg::detail
