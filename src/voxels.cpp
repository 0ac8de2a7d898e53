// Voxels [paper 3.1]. The paper indexes cells with an octree to reach neighbours quickly; a sorted
// array of integer keys with binary search gives the same neighbourhoods, deterministically.
#include <proxseg/voxels.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace proxseg {
namespace {

bool key_less(const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
  if (a.z() != b.z()) return a.z() < b.z();
  if (a.y() != b.y()) return a.y() < b.y();
  return a.x() < b.x();
}

}  // namespace

VoxelGrid build_voxels(const Frame& frame, double voxel_size) {
  if (!(voxel_size > 0)) throw std::invalid_argument("voxel_size must be > 0");
  VoxelGrid grid;
  grid.voxel_size = voxel_size;
  grid.voxel_of_point.assign(frame.size(), -1);

  // (key, point) pairs sorted by key, then by point index: voxels and their point lists come out
  // in a canonical order.
  std::vector<std::pair<Eigen::Vector3i, int>> keyed;
  keyed.reserve(frame.size());
  const double inv = 1.0 / voxel_size;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    if (!frame.valid(i)) continue;
    const Eigen::Vector3f& p = frame.xyz[i];
    const Eigen::Vector3d c = (p.cast<double>() * inv).array().floor();
    // Coordinates beyond the int range cannot be voxelised; treat them as invalid.
    if ((c.array().abs() > 1e9).any()) continue;
    keyed.emplace_back(c.cast<int>(), static_cast<int>(i));
  }
  std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) {
    if (a.first != b.first) return key_less(a.first, b.first);
    return a.second < b.second;
  });
  for (const auto& [key, index] : keyed) {
    if (grid.keys.empty() || grid.keys.back() != key) {
      grid.keys.push_back(key);
      grid.points.emplace_back();
    }
    grid.points.back().push_back(index);
    grid.voxel_of_point[index] = static_cast<int>(grid.keys.size()) - 1;
  }

  // 26-neighbourhood by binary search in the sorted keys; symmetric by construction.
  grid.neighbours.resize(grid.keys.size());
  for (std::size_t v = 0; v < grid.keys.size(); ++v) {
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const Eigen::Vector3i q = grid.keys[v] + Eigen::Vector3i(dx, dy, dz);
          auto it = std::lower_bound(grid.keys.begin(), grid.keys.end(), q, key_less);
          if (it != grid.keys.end() && *it == q)
            grid.neighbours[v].push_back(static_cast<int>(it - grid.keys.begin()));
        }
    std::sort(grid.neighbours[v].begin(), grid.neighbours[v].end());
  }
  return grid;
}

std::vector<int> dense_voxels(const VoxelGrid& grid, int min_points) {
  std::vector<int> out;
  for (std::size_t v = 0; v < grid.size(); ++v)
    if (static_cast<int>(grid.points[v].size()) >= min_points) out.push_back(static_cast<int>(v));
  return out;
}

std::vector<std::vector<int>> induced_neighbours(const VoxelGrid& grid,
                                                 const std::vector<int>& subset) {
  std::vector<int> local(grid.size(), -1);
  for (std::size_t i = 0; i < subset.size(); ++i) local[subset[i]] = static_cast<int>(i);
  std::vector<std::vector<int>> out(subset.size());
  for (std::size_t i = 0; i < subset.size(); ++i)
    for (int n : grid.neighbours[subset[i]])
      if (local[n] >= 0) out[i].push_back(local[n]);
  return out;
}

}  // namespace proxseg
