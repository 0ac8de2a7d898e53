// The texture block [paper 3.1] computed the plain way, for the tests: every Gabor response kept
// as a full image, each voxel binned from it. voxel_features() computes the same block without
// keeping the bank (tests/core/test_features.cpp checks that they agree).
#pragma once
#include <proxseg/core/features.hpp>
#include <proxseg/core/frame.hpp>

#include <Eigen/Core>
#include <vector>

namespace proxseg {

// Gabor magnitude responses of the frame's grey image: 24 images of width x height
// (orientation-major: filter = scale * 6 + orientation) and the fixed upper bin edge of each.
struct GaborBank {
  int width = 0, height = 0;
  std::vector<std::vector<float>> magnitude;  // [filter][pixel]
  std::vector<float> upper_edge;              // [filter]
};
// The reference: every pixel is computed, whatever params.gabor_stride (voxel_features follows it).
GaborBank gabor_bank(const Frame& frame, const FeatureParams& params);
// Texture block of one voxel from the responses at its points' pixels.
Eigen::VectorXf texture_feature(const GaborBank& bank, const std::vector<int>& pixels);

}  // namespace proxseg
