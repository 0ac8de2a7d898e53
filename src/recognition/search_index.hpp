// The search index of a described cloud (Cloud::index) [paper 3.4, Algorithm 2]: the point grid
// that answers the nearest-point queries of ICP and the alignment scores (eq. 4-5), and the
// feature matrices that RANSAC's correspondences are found in. Private to src/recognition.
#pragma once
#include <proxseg/core/registration_types.hpp>

#include <Eigen/Core>
#include <memory>
#include <vector>

namespace proxseg {

// FPFH's histogram size: Cloud::features holds one block of it per radius.
constexpr int kFpfhBins = 33;

// Nearest-point queries all have a small radius (ICP, fitness, overlap: about 1 cm), so a dense
// grid of 1 cm cells over the cloud's bounding box answers them by looking at a few cells; it is
// several times faster than a kd-tree here and is exact.
struct PointGrid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double cell = 0.01;
  Eigen::Vector3i dims = Eigen::Vector3i::Zero();
  std::vector<int> start;  // points of cell c: order[start[c] .. start[c + 1])
  std::vector<int> order;
  std::vector<Eigen::Vector3d> points;  // in cell order, for locality
};

// Feature matching is brute force on floats (one matrix product per pair of clouds): with 33-99
// dimensions and a few hundred points a kd-tree visits most leaves anyway, and the product
// vectorises.
struct SearchIndex {
  PointGrid points;
  std::vector<Eigen::MatrixXf> features;   // [0]: all radii; [1 + b]: radius block b
  std::vector<Eigen::RowVectorXf> norms2;  // squared norms of their columns
};

namespace detail {

// Nearest point of the grid to q within r (-1 if none), squared distance in d2. Most queries
// (ICP after its first steps, fitness, coverage) have a point within half a cell, and the box
// of that radius spans ~8 cells instead of ~64 for ICP's 1.5 cm: searching it first is exact (a
// nearer point would lie in it too) and about four times cheaper. A point found in it farther
// than half a cell narrows the second box to its distance (ICP's queries: 13 % fewer
// instructions).
int nearest(const PointGrid& g, const Eigen::Vector3d& q, double r, double& d2);

// The same when some point of the grid is known to lie within squared distance bound2 of q (at
// most r^2): the box searched is that distance's (ICP's previous match, mostly a fraction of a
// cell away). Every point as near as the nearest lies in it, in the same cell order: the same
// point as nearest() gives.
int nearest_within(const PointGrid& g, const Eigen::Vector3d& q, double bound2, double& d2);

// Whether the grid has a point within r of q: nearest(g, q, r, d2) >= 0 && d2 <= r * r, without
// looking further once one is found (the scores that count explained points).
bool any_within(const PointGrid& g, const Eigen::Vector3d& q, double r);

// The grid of the cloud's points and its features as floats, whole and per radius block.
std::shared_ptr<const SearchIndex> build_index(const Cloud& c);

}  // namespace detail
}  // namespace proxseg
