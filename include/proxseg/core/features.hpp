// Per-voxel features [paper 3.1]: f = [colour 110 | texture 240 | shape 104] = 454 values.
#pragma once
#include <proxseg/core/frame.hpp>
#include <proxseg/core/voxels.hpp>

#include <vector>

namespace proxseg {

constexpr int kColourDims = 110;   // 10x10 hue x saturation + 10 value
constexpr int kTextureDims = 240;  // 6 orientations x 4 scales x 10 bins
constexpr int kShapeDims = 104;    // 3 eigenvalues + curvature + 10x10 normal angles
constexpr int kFeatureDims = kColourDims + kTextureDims + kShapeDims;
constexpr int kGaborOrientations = 6;
constexpr int kGaborScales = 4;
constexpr int kHistogramBins = 10;

struct FeatureParams {
  bool use_colour = true, use_texture = true, use_shape = true;
  // Each block is multiplied by its weight (a switched-off block is all zeros).
  double colour_weight = 1.0, texture_weight = 1.0, shape_weight = 1.0;
  double gabor_wavelength = 4.0;        // pixels, at every pyramid level (scale s = level s)
  double gabor_sigma = 2.0;             // pixels, envelope of the Gabor kernel at each level
  double texture_clip_quantile = 0.99;  // upper bin edge per filter = this quantile over the frame
  // 1 = each filter's response at every pixel (the paper). 2 = on the half-resolution grid of
  // 2 x 2 cells: level 0 computed at every second pixel both ways (a quarter of the inverse DFTs),
  // coarser levels interpolated to the cells, and every pixel takes its cell's response
  // (docs/method.md, Speed).
  int gabor_stride = 2;
  int normal_step = 3;  // organized clouds: pixel offset of the central differences
  int normal_knn = 20;  // unorganized clouds: neighbours for PCA normals
  // Organized clouds: > 0 smooths each pixel only over the neighbours on its own surface (depth
  // within this share of its depth per pixel of offset), so that a silhouette's normals are not
  // bent towards the surface behind it; 0 = a plain box filter (the shape feature's, paper).
  double normal_edge_ratio = 0;
};

// Colour block of one voxel from its points' colours.
Eigen::VectorXf colour_feature(const std::vector<Rgb>& colours);

// Shape block from points and unit normals (oriented towards the sensor).
Eigen::VectorXf shape_feature(const std::vector<Eigen::Vector3f>& points,
                              const std::vector<Eigen::Vector3f>& normals);

// Unit normals per point, oriented towards the sensor (origin); NaN for invalid points.
// threads: 0 = all cores; the result does not depend on it.
std::vector<Eigen::Vector3f> point_normals(const Frame& frame, const FeatureParams& params,
                                           int threads = 0);

// Feature matrix: one row per voxel of `voxels`, kFeatureDims columns, block weights applied.
Eigen::MatrixXf voxel_features(const Frame& frame, const VoxelGrid& grid,
                               const std::vector<int>& voxels, const FeatureParams& params,
                               int threads);

}  // namespace proxseg
