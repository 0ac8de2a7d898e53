// Weak connections [paper 3.3]: the labelled points of each cluster split by their density,
// Euclidean components of the dense ones, the set-aside points joined back afterwards. Used by
// the voxel selection (selection.cpp).
#pragma once
#include <proxseg/core/frame.hpp>
#include <proxseg/core/selection.hpp>
#include <proxseg/core/voxels.hpp>

#include <vector>

namespace proxseg::detail {

// The labelled points split by their density against their cluster's median [3.3, weak
// connections]: `dense` (sorted) are clustered, `set_aside` join them afterwards. A cluster that
// is weak everywhere is kept whole (all dense).
struct DensitySplit {
  std::vector<int> dense, set_aside;
  std::vector<char> is_weak;  // per frame point: set aside
};

DensitySplit split_weak_points(const Frame& frame, const std::vector<int>& labelled,
                               const std::vector<int>& cluster, int clusters,
                               const SelectionParams& params, int threads);

// Set-aside points go back to the component of the nearest dense point of their cluster,
// looked up in their own and neighbouring voxels; a kd-tree of the cluster is the fallback.
void reattach_weak_points(const Frame& frame, const VoxelGrid& grid, const DensitySplit& split,
                          const std::vector<int>& cluster, int clusters,
                          std::vector<int>& component);

// Euclidean clustering with tolerance t, exact: cells of side t / sqrt(3) hold points that are all
// within t of each other, so components are found between cells, with an early exit per pair.
// Returns, per point of `points`, a component id (the smallest cell index of the component).
std::vector<int> euclidean_components(const Frame& frame, const std::vector<int>& points,
                                      const std::vector<int>& group, double tolerance);

}  // namespace proxseg::detail
