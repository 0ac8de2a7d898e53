// An RGB-D capture as a frame: the pinhole back-projection of a depth image into organized points.
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace proxseg {

// Pinhole intrinsics of a depth camera. depth_scale = depth units per metre
// (metres = value / depth_scale; 1000 for millimetre PNGs, YCB-Video's factor_depth = 10000).
struct Intrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double depth_scale = 1000.0;
};

// Throws InputError unless fx, fy and depth_scale are finite and > 0 and cx, cy finite.
void check(const Intrinsics& k);

// The points of a row-major width x height depth image in the camera frame, metres, row-major:
// x = (u - cx) z / fx, y = (v - cy) z / fy, z = value / depth_scale. A pixel with value 0 (or,
// for float depth, not finite or <= 0) has no return: NaN. Checks k (check()).
std::vector<Eigen::Vector3f> back_project(const std::uint16_t* depth, int width, int height,
                                          const Intrinsics& k);
std::vector<Eigen::Vector3f> back_project(const float* depth, int width, int height,
                                          const Intrinsics& k);

}  // namespace proxseg
