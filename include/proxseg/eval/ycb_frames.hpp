// YCB-Video frames for recognition (../shared/data/ycbv): one frame's colour, depth, per-pixel
// class labels and per-object poses, and the class list.
#pragma once
#include <proxseg/core/frame.hpp>
#include <proxseg/core/rgbd.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace proxseg {

struct ObjectTruth {
  std::string name;         // class name from classes.txt
  int class_index = 0;      // 1-based, the value of its pixels in -label.png
  Eigen::Matrix4d pose;     // camera <- model (meta.json "poses")
  std::vector<int> points;  // its pixels (indices into frame) with a valid depth
};
struct YcbFrame {
  Frame frame;            // camera frame, organized
  Intrinsics intrinsics;  // from -meta.json
  std::vector<ObjectTruth> objects;
  std::vector<std::uint8_t> labels;  // -label.png per pixel (class index, 0 = background)
};
// Reads DIR/<stem>-color.png, -depth.png, -label.png and -meta.json; classes from classes.txt.
YcbFrame read_ycb_frame(const std::string& dir, const std::string& stem,
                        const std::vector<std::string>& classes);
// Non-empty lines of a text file (classes.txt).
std::vector<std::string> read_lines(const std::string& path);

}  // namespace proxseg
