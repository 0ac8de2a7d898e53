// Colour conversions shared by the colour feature [paper 3.1], the scene generators and the
// benchmarks.
#pragma once
#include <proxseg/core/frame.hpp>

#include <Eigen/Core>

namespace proxseg {

// HSV of an 8-bit colour: h in [0, 1) (fraction of the hue circle), s and v in [0, 1].
Eigen::Vector3d rgb_to_hsv(const Rgb& c);
// RGB of an HSV colour (h taken modulo 1), 0..255 per channel, unrounded (for shading on top).
Eigen::Vector3d hsv_to_rgb(const Eigen::Vector3d& hsv);
// 0..255 per channel, rounded to nearest and clamped, to 8 bits.
Rgb to_rgb8(const Eigen::Vector3d& c);

}  // namespace proxseg
