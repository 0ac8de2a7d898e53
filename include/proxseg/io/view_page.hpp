// The 3D page of a result: one self-contained HTML file (no network needed to open it) that shows
// the cloud in any browser with WebGL, coloured by the scene's colours or by each per-point field
// of the result (labels, instances, recognised objects), with a legend that picks out an object
// when hovered, a click that shows the object under the pointer (name, score, fitness, coverage,
// pose), and each candidate's or recognised object's oriented box (and a recognised object's
// axes at its estimated pose). `proxseg view PREFIX` and `--outputs html` write it.
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace proxseg {

struct ViewOptions {
  // Clouds with more valid points than this keep every k-th (the page says so): at about 5 bytes
  // a point, a page stays within about 5 MB (a 640x480 frame, about 300k points, keeps all).
  std::size_t max_points = 1000000;
  std::string title;  // shown at the top; "" = the report's input
};

// A per-point field of a result: one id per frame point, 0 = none ("label", "instance",
// "object", as the PCD outputs name them).
struct ViewField {
  std::string name;
  std::vector<std::uint32_t> ids;
};

// The page of frame with its fields, the legends and boxes read from the result's report (the
// segmentation report of write_segmentation, or recognize's). InputError when a field is not one
// id per point.
std::string view_page(const Frame& frame, const std::vector<ViewField>& fields,
                      const nlohmann::json& report, const ViewOptions& options = {});

// The page of a result as its files hold it: PREFIX.json (the report) and PREFIX.pcd (points,
// colours and the fields the report names). InputError naming the file when one is missing or is
// not a proxseg output.
std::string view_page_of(const std::string& prefix, const ViewOptions& options = {});

}  // namespace proxseg
