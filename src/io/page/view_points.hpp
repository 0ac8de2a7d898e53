// The points of the 3D page as its script reads them (view_points.cpp). Private to io.
#pragma once
#include <proxseg/core/frame.hpp>
#include <proxseg/io/view_page.hpp>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace proxseg::detail {

struct ViewPoints {
  nlohmann::json arrays;  // name -> [offset, count] in the inflated bytes ("position": three)
  nlohmann::json bounds;  // {"min": [x, y, z], "step": [x, y, z]}: a position's quantisation
  std::string base64;     // the bytes, deflated (zlib) and base64-encoded
};

// The given points of frame (indices of valid points): positions, colours and each field's ids
// (uint16; larger ids are clamped to 65535).
ViewPoints encode_view_points(const Frame& frame, const std::vector<int>& points,
                              const std::vector<ViewField>& fields);

}  // namespace proxseg::detail
