// The pictures of the outputs (pictures.cpp) as output.cpp writes them beside the other files.
// Private to the library.
#pragma once
#include <proxseg/core/database.hpp>
#include <proxseg/core/frame.hpp>
#include <proxseg/core/recognition_types.hpp>

#include <opencv2/core/mat.hpp>
#include <vector>

namespace proxseg::detail {

// The colour of a label or instance id in the pictures (label 0: black).
Rgb label_rgb(std::uint32_t label);

// Per frame point the index into objects of the object that holds it, -1 for none.
// std::invalid_argument if a point index is outside the frame or two objects hold one point.
std::vector<int> point_owners(const Frame& frame, const std::vector<SceneObject>& objects);

// recognition_image_png's picture (8-bit BGR); the size of its scene part in scene_size.
cv::Mat recognition_image(const Frame& frame, const std::vector<SceneObject>& objects,
                          const Database& db, cv::Size& scene_size);

}  // namespace proxseg::detail
