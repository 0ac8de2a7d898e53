// PCL "peer" segmenters that the benchmark compares proxseg against: LCCP on supervoxels,
// colour-based region growing and RANSAC plane + Euclidean clustering. The implementation
// (bench/peers_pcl.cpp) is the only place that includes PCL; this header needs none of it.
//
// Every function takes a frame (organized or not; NaN xyz = invalid point) and returns one label
// per point of the frame (same size as frame.xyz): 0 = invalid or unassigned, 1..n = segment.
// Same input and parameters give the same labels. Segments are numbered in the order of their
// smallest point index (except euclidean(): see there). Nothing is printed on stdout (PCL's
// console verbosity is set to errors only, which go to stderr).
#pragma once
#include <proxseg/core/frame.hpp>

#include <cstdint>
#include <vector>

namespace proxseg::peers {

// pcl::SupervoxelClustering<PointXYZRGBA> + pcl::LCCPSegmentation, defaults of PCL's
// examples/segmentation/example_lccp_segmentation.cpp, except the sanity criterion (on here,
// "-sc" there).
struct LccpParams {
  // Supervoxels.
  float voxel_resolution = 0.0075f;  // m
  float seed_resolution = 0.03f;     // m
  float colour_importance = 0.0f;
  float spatial_importance = 1.0f;
  float normal_importance = 4.0f;
  // The example calls setUseSingleCameraTransform(false) unless "-tvoxel" is given, which also
  // overrides PCL's own default (transform on for organized clouds).
  bool use_single_camera_transform = false;
  bool use_supervoxel_refinement = false;  // "-refine" (2 iterations)
  // LCCP.
  float concavity_tolerance = 10.0f;  // degrees
  float smoothness_threshold = 0.1f;
  std::uint32_t min_segment_size = 0;  // in supervoxels; 0 = no merging of small segments
  bool use_sanity_criterion = true;
  bool use_extended_convexity = false;  // k-factor 1 when on, 0 when off
  // Valid points whose voxel no supervoxel owns take the label of the nearest labelled point
  // within this distance (m); <= 0 leaves them 0.
  float fill_radius = 0.03f;
};
std::vector<std::uint32_t> lccp(const Frame& frame, const LccpParams& params = {});

// pcl::RegionGrowingRGB<PointXYZRGB> with the values of PCL's tutorial "Color-based region
// growing segmentation" (region_growing_rgb_segmentation.cpp), on the valid points.
// Points of clusters smaller than min_cluster_size stay 0.
struct RegionGrowingRgbParams {
  float distance_threshold = 10.0f;  // m, neighbour distance (the tutorial's value)
  float point_colour_threshold = 6.0f;
  float region_colour_threshold = 5.0f;
  int min_cluster_size = 600;  // points
};
std::vector<std::uint32_t> region_growing_rgb(const Frame& frame,
                                              const RegionGrowingRgbParams& params = {});

// PCL's tutorial "Euclidean Cluster Extraction" (cluster_extraction.cpp): voxel grid, RANSAC
// removal of the largest plane (pcl::SACSegmentation, SACMODEL_PLANE, SAC_RANSAC, optimized
// coefficients; PCL's fixed seed 12345, so reproducible), pcl::EuclideanClusterExtraction on
// the rest. Label 1 = the plane (e.g. the table) when one is found; clusters are 2..n in the
// order of their smallest point index (1..n when no plane is found). Every valid point takes the
// label of the nearest labelled downsampled point within cluster_tolerance, else 0.
struct EuclideanParams {
  float leaf_size = 0.01f;       // m, voxel grid
  float plane_distance = 0.02f;  // m, RANSAC inlier threshold
  int plane_max_iterations = 100;
  float cluster_tolerance = 0.02f;  // m
  int min_cluster_size = 100;       // downsampled points
  int max_cluster_size = 25000;     // downsampled points
};
// plane_found (optional) tells which of the two numberings the labels use.
std::vector<std::uint32_t> euclidean(const Frame& frame, const EuclideanParams& params = {},
                                     bool* plane_found = nullptr);

}  // namespace proxseg::peers
