// PCL peer segmenters (see peers_pcl.hpp). The only translation unit that includes PCL.
#include "peers_pcl.hpp"
#include "nearest_fill.hpp"

#include <pcl/ModelCoefficients.h>
#include <pcl/PointIndices.h>
#include <pcl/console/print.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/lccp_segmentation.h>
#include <pcl/segmentation/region_growing_rgb.h>
#include <pcl/segmentation/sac_segmentation.h>
#include <pcl/segmentation/supervoxel_clustering.h>

#include <algorithm>
#include <cstddef>
#include <map>
#include <type_traits>
#include <unordered_map>

namespace proxseg::peers {
namespace {

void quiet() {
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
}

// Renumbers the non-zero labels 1..n (first_id..) in the order of their smallest point index;
// labels listed in `fixed` keep the id given there.
void renumber(std::vector<std::uint32_t>& labels,
              const std::map<std::uint32_t, std::uint32_t>& fixed = {},
              std::uint32_t first_id = 1) {
  std::unordered_map<std::uint32_t, std::uint32_t> ids(fixed.begin(), fixed.end());
  std::uint32_t next = first_id;
  for (std::uint32_t& l : labels) {
    if (l == 0) continue;
    auto [it, inserted] = ids.emplace(l, next);
    if (inserted) ++next;
    l = it->second;
  }
}

// Frame indices of the valid points, in order.
std::vector<std::size_t> valid_indices(const Frame& frame) {
  std::vector<std::size_t> idx;
  idx.reserve(frame.size());
  for (std::size_t i = 0; i < frame.size(); ++i)
    if (frame.valid(i)) idx.push_back(i);
  return idx;
}

// A PCL cloud of the given frame points (x y z, and colour when the point type has it).
template <class Point>
typename pcl::PointCloud<Point>::Ptr to_pcl(const Frame& frame,
                                            const std::vector<std::size_t>& indices) {
  typename pcl::PointCloud<Point>::Ptr cloud(new pcl::PointCloud<Point>);
  cloud->resize(indices.size());
  for (std::size_t k = 0; k < indices.size(); ++k) {
    Point& q = (*cloud)[k];
    const std::size_t i = indices[k];
    q.x = frame.xyz[i].x();
    q.y = frame.xyz[i].y();
    q.z = frame.xyz[i].z();
    if constexpr (!std::is_same_v<Point, pcl::PointXYZ>) {
      // An XYZ-only frame: one grey for every point, so that only the geometry tells them apart.
      const Rgb c = frame.coloured() ? frame.rgb[i] : Rgb{128, 128, 128};
      q.r = c[0];
      q.g = c[1];
      q.b = c[2];
      q.a = 255;
    }
  }
  cloud->width = static_cast<std::uint32_t>(indices.size());
  cloud->height = 1;
  cloud->is_dense = true;
  return cloud;
}

}  // namespace

std::vector<std::uint32_t> lccp(const Frame& frame, const LccpParams& p) {
  quiet();
  const std::size_t n = frame.size();
  std::vector<std::uint32_t> labels(n, 0);
  if (frame.valid_count() == 0) return labels;

  // The whole frame, NaNs included (organized when the frame is): SupervoxelClustering skips
  // non-finite points and getLabeledCloud() returns one label per input point.
  std::vector<std::size_t> all(n);
  for (std::size_t i = 0; i < n; ++i) all[i] = i;
  const auto cloud = to_pcl<pcl::PointXYZRGBA>(frame, all);
  cloud->width = static_cast<std::uint32_t>(frame.width);
  cloud->height = static_cast<std::uint32_t>(frame.height);
  if (std::size_t(cloud->width) * cloud->height != n) {  // inconsistent header: unorganized
    cloud->width = static_cast<std::uint32_t>(n);
    cloud->height = 1;
  }
  cloud->is_dense = false;

  pcl::SupervoxelClustering<pcl::PointXYZRGBA> super(p.voxel_resolution, p.seed_resolution);
  super.setUseSingleCameraTransform(p.use_single_camera_transform);
  super.setInputCloud(cloud);
  super.setColorImportance(p.colour_importance);
  super.setSpatialImportance(p.spatial_importance);
  super.setNormalImportance(p.normal_importance);
  std::map<std::uint32_t, pcl::Supervoxel<pcl::PointXYZRGBA>::Ptr> clusters;
  super.extract(clusters);
  if (p.use_supervoxel_refinement) super.refineSupervoxels(2, clusters);
  if (clusters.empty()) return labels;
  std::multimap<std::uint32_t, std::uint32_t> adjacency;
  super.getSupervoxelAdjacency(adjacency);

  pcl::LCCPSegmentation<pcl::PointXYZRGBA> seg;
  seg.setConcavityToleranceThreshold(p.concavity_tolerance);
  seg.setSanityCheck(p.use_sanity_criterion);
  seg.setSmoothnessCheck(true, p.voxel_resolution, p.seed_resolution, p.smoothness_threshold);
  seg.setKFactor(p.use_extended_convexity ? 1 : 0);
  seg.setInputSupervoxels(clusters, adjacency);
  seg.setMinSegmentSize(p.min_segment_size);
  seg.segment();

  pcl::PointCloud<pcl::PointXYZL>::Ptr labelled = super.getLabeledCloud();
  seg.relabelCloud(*labelled);
  if (labelled->size() != n) return labels;  // not expected: one label per input point
  for (std::size_t i = 0; i < n; ++i)
    if (frame.valid(i)) labels[i] = (*labelled)[i].label;

  // Valid points in voxels that no supervoxel reached: nearest labelled point.
  if (p.fill_radius > 0) {
    const float r2 = p.fill_radius * p.fill_radius;
    fill_from_nearest(
        labels, [&](std::size_t i) { return frame.valid(i); },
        [&](std::size_t i) {
          return pcl::PointXYZ(frame.xyz[i].x(), frame.xyz[i].y(), frame.xyz[i].z());
        },
        r2);
  }
  renumber(labels);
  return labels;
}

std::vector<std::uint32_t> region_growing_rgb(const Frame& frame, const RegionGrowingRgbParams& p) {
  quiet();
  std::vector<std::uint32_t> labels(frame.size(), 0);
  const std::vector<std::size_t> idx = valid_indices(frame);
  if (idx.empty()) return labels;

  const auto cloud = to_pcl<pcl::PointXYZRGB>(frame, idx);

  pcl::RegionGrowingRGB<pcl::PointXYZRGB> reg;
  reg.setDistanceThreshold(p.distance_threshold);
  reg.setPointColorThreshold(p.point_colour_threshold);
  reg.setRegionColorThreshold(p.region_colour_threshold);
  reg.setMinClusterSize(p.min_cluster_size);
  pcl::search::Search<pcl::PointXYZRGB>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZRGB>);
  reg.setSearchMethod(tree);
  reg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> clusters;
  reg.extract(clusters);

  for (std::size_t c = 0; c < clusters.size(); ++c)
    for (const auto k : clusters[c].indices)
      labels[idx[static_cast<std::size_t>(k)]] = std::uint32_t(c + 1);
  renumber(labels);
  return labels;
}

namespace {

// The largest plane of `down` (SACSegmentation seeds its generators with 12345: reproducible).
pcl::PointIndices::Ptr largest_plane(const pcl::PointCloud<pcl::PointXYZ>::Ptr& down,
                                     const EuclideanParams& p) {
  pcl::PointIndices::Ptr plane(new pcl::PointIndices);
  if (down->size() < 3) return plane;
  pcl::ModelCoefficients::Ptr coefficients(new pcl::ModelCoefficients);
  pcl::SACSegmentation<pcl::PointXYZ> sac;
  sac.setOptimizeCoefficients(true);
  sac.setModelType(pcl::SACMODEL_PLANE);
  sac.setMethodType(pcl::SAC_RANSAC);
  sac.setMaxIterations(p.plane_max_iterations);
  sac.setDistanceThreshold(p.plane_distance);
  sac.setInputCloud(down);
  sac.segment(*plane, *coefficients);
  return plane;
}

// Euclidean clusters of the points of `down` still unlabelled, labelled 2, 3, ...
void label_clusters(const pcl::PointCloud<pcl::PointXYZ>::Ptr& down, const EuclideanParams& p,
                    std::vector<std::uint32_t>& down_label) {
  pcl::IndicesPtr rest(new pcl::Indices);
  for (std::size_t k = 0; k < down->size(); ++k)
    if (down_label[k] == 0) rest->push_back(static_cast<pcl::index_t>(k));
  if (rest->empty()) return;
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  tree->setInputCloud(down, rest);
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
  ec.setClusterTolerance(p.cluster_tolerance);
  ec.setMinClusterSize(p.min_cluster_size);
  ec.setMaxClusterSize(p.max_cluster_size);
  ec.setSearchMethod(tree);
  ec.setInputCloud(down);
  ec.setIndices(rest);
  std::vector<pcl::PointIndices> clusters;
  ec.extract(clusters);
  for (std::size_t c = 0; c < clusters.size(); ++c)
    for (const auto k : clusters[c].indices)
      down_label[static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(c + 2);
}

// Every point of `cloud` (frame point idx[k]): the label of the nearest labelled point of `down`
// within the cluster tolerance.
void label_from_down(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                     const std::vector<std::size_t>& idx,
                     const pcl::PointCloud<pcl::PointXYZ>& down,
                     const std::vector<std::uint32_t>& down_label, float tolerance,
                     std::vector<std::uint32_t>& labels) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr seeds(new pcl::PointCloud<pcl::PointXYZ>);
  std::vector<std::uint32_t> seed_label;
  for (std::size_t k = 0; k < down.size(); ++k)
    if (down_label[k]) {
      seeds->push_back(down[k]);
      seed_label.push_back(down_label[k]);
    }
  if (seeds->empty()) return;
  pcl::KdTreeFLANN<pcl::PointXYZ> nearest;
  nearest.setInputCloud(seeds);
  pcl::Indices nn(1);
  std::vector<float> d2(1);
  const float r2 = tolerance * tolerance;
  for (std::size_t k = 0; k < idx.size(); ++k)
    if (nearest.nearestKSearch(cloud[k], 1, nn, d2) > 0 && d2[0] <= r2)
      labels[idx[k]] = seed_label[static_cast<std::size_t>(nn[0])];
}

}  // namespace

std::vector<std::uint32_t> euclidean(const Frame& frame, const EuclideanParams& p,
                                     bool* plane_found) {
  quiet();
  if (plane_found) *plane_found = false;
  std::vector<std::uint32_t> labels(frame.size(), 0);
  const std::vector<std::size_t> idx = valid_indices(frame);
  if (idx.empty()) return labels;

  const auto cloud = to_pcl<pcl::PointXYZ>(frame, idx);

  // Voxel grid (the tutorial's 1 cm).
  pcl::PointCloud<pcl::PointXYZ>::Ptr down(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setInputCloud(cloud);
  grid.setLeafSize(p.leaf_size, p.leaf_size, p.leaf_size);
  grid.filter(*down);
  if (down->empty()) return labels;

  // Labels of the downsampled points: 1 = plane, 2.. = clusters (temporary ids), 0 = none.
  std::vector<std::uint32_t> down_label(down->size(), 0);
  const pcl::PointIndices::Ptr plane = largest_plane(down, p);
  const bool has_plane = !plane->indices.empty();
  if (plane_found) *plane_found = has_plane;
  for (const auto k : plane->indices) down_label[static_cast<std::size_t>(k)] = 1;
  label_clusters(down, p, down_label);
  label_from_down(*cloud, idx, *down, down_label, p.cluster_tolerance, labels);
  if (has_plane)
    renumber(labels, {{1u, 1u}}, 2);
  else
    renumber(labels);
  return labels;
}

}  // namespace proxseg::peers
