// Voxels [paper 3.1]: cubic cells of the cloud with their occupied 26-neighbours.
#pragma once
#include <proxseg/core/frame.hpp>

#include <vector>

namespace proxseg {

struct VoxelParams {
  double voxel_size = 0.02;       // metres (paper: 2 cm)
  int min_points_per_voxel = 10;  // sparser voxels are not clustered; they inherit a label later
};

// A voxel's integer coordinates stay within this many cells of the origin; points farther out
// (or every point, for a voxel side orders of magnitude too small) are left out of the grid.
constexpr double kVoxelReach = 1e9;

struct VoxelGrid {
  double voxel_size = 0;
  std::vector<Eigen::Vector3i> keys;         // integer cell coordinates
  std::vector<std::vector<int>> points;      // point indices in each voxel (ascending)
  std::vector<std::vector<int>> neighbours;  // occupied 26-neighbours (ascending, symmetric)
  std::vector<int> voxel_of_point;           // per point; -1 for invalid points
  std::size_t valid_points = 0;              // finite points of the frame
  std::size_t voxelised_points = 0;  // of those, the ones in a voxel (the rest lie too far out)
  std::size_t size() const { return keys.size(); }
};

// Voxels are numbered in ascending key order (z, y, x), so the numbering does not depend on the
// point order or on threads.
VoxelGrid build_voxels(const Frame& frame, double voxel_size);
// Per point, whether build_voxels would put it in a voxel (valid and not too far out), without
// building the grid; valid_points and voxelised_points count them as build_voxels does.
std::vector<char> voxelisable(const Frame& frame, double voxel_size, std::size_t& valid_points,
                              std::size_t& voxelised_points);

// The voxels with at least min_points points.
std::vector<int> dense_voxels(const VoxelGrid& grid, int min_points);

// The graph induced on a subset of voxels, in the subset's own numbering.
std::vector<std::vector<int>> induced_neighbours(const VoxelGrid& grid,
                                                 const std::vector<int>& subset);

}  // namespace proxseg
