// A frame: one RGB-D capture as a point cloud, organized (image grid) or not.
#pragma once
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace proxseg {

using Rgb = std::array<std::uint8_t, 3>;  // r, g, b

struct Frame {
  int width = 0;                     // image columns; number of points when unorganized
  int height = 0;                    // image rows; 1 when unorganized
  std::vector<Eigen::Vector3f> xyz;  // metres, sensor frame; NaN = invalid (no return)
  // One per point, or empty: the frame has no colour (an XYZ-only cloud). segment() then works
  // without the colour and texture blocks, and pictures show grey instead.
  std::vector<Rgb> rgb;
  std::vector<std::uint32_t> label;  // optional ground truth (empty when absent)

  bool organized() const { return height > 1; }
  bool coloured() const { return !rgb.empty(); }
  std::size_t size() const { return xyz.size(); }
  bool valid(std::size_t i) const {
    return std::isfinite(xyz[i].x()) && std::isfinite(xyz[i].y()) && std::isfinite(xyz[i].z());
  }
  std::size_t valid_count() const {
    std::size_t n = 0;
    for (std::size_t i = 0; i < xyz.size(); ++i) n += valid(i);
    return n;
  }
};

}  // namespace proxseg
