// Labels for the points that a segmentation left out, from their nearest labelled point: what
// both LCCP runs (peers_pcl.cpp, lccp_process.cpp) do for the valid points in voxels that no
// supervoxel reached. PCL's k-d tree, header-only so that lccp_process stays a plain PCL program.
#pragma once
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace proxseg::peers {

// labels[i] == 0 for each valid point i (valid(i)) that is left out: it takes the label of the
// nearest labelled valid point when that lies within sqrt(max_d2), else stays 0. xyz(i) gives
// point i as a pcl::PointXYZ.
template <class Valid, class Xyz>
void fill_from_nearest(std::vector<std::uint32_t>& labels, const Valid& valid, const Xyz& xyz,
                       double max_d2) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr done(new pcl::PointCloud<pcl::PointXYZ>);
  std::vector<std::size_t> done_index, todo;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (!valid(i)) continue;
    if (labels[i] == 0) {
      todo.push_back(i);
    } else {
      done->push_back(xyz(i));
      done_index.push_back(i);
    }
  }
  if (todo.empty() || done->empty()) return;
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(done);
  pcl::Indices nn(1);
  std::vector<float> d2(1);
  std::vector<std::uint32_t> fill(todo.size(), 0);
  for (std::size_t t = 0; t < todo.size(); ++t)
    if (tree.nearestKSearch(xyz(todo[t]), 1, nn, d2) > 0 && d2[0] <= max_d2)
      fill[t] = labels[done_index[nn[0]]];
  for (std::size_t t = 0; t < todo.size(); ++t) labels[todo[t]] = fill[t];
}

}  // namespace proxseg::peers
