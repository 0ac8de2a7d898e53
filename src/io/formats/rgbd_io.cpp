// RGB-D frames: a colour image and a 16-bit depth image back-projected through the camera's
// intrinsics (rgbd.hpp), and the camera files that give them: our intrinsics JSON and YCB-Video's
// meta JSON (intrinsic_matrix, factor_depth).
#include <proxseg/io/cloud_io.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <sstream>

#include "io/formats/image_file.hpp"
#include "io/input_file.hpp"
#include "io/json_file.hpp"
#include "io/reader_errors.hpp"

namespace proxseg {
namespace {

using detail::fail;
using detail::mat_kind;
using detail::read_image;
using detail::size_str;

std::string num(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

// Number check for JSON readers.
double json_number(const std::string& path, const nlohmann::json& j, const char* name) {
  if (!j.is_number())
    fail(path, std::string("field \"") + name + "\" is " + j.type_name() + " (expected a number)");
  const double v = j.get<double>();
  if (!std::isfinite(v))
    fail(path, std::string("field \"") + name + "\" is not finite (expected a number)");
  return v;
}

// Camera files are read as configs are: nesting bounded, messages quoting excerpts (json_file.hpp).
nlohmann::json read_json(const std::string& path) {
  return detail::read_json_file(path);
}

void check_intrinsics(const std::string& path, const Intrinsics& k) {
  auto positive = [&](const char* name, double v) {
    if (!(v > 0) || !std::isfinite(v))
      fail(path, std::string("field \"") + name + "\" is " + num(v) + " (expected a number > 0)");
  };
  positive("fx", k.fx);
  positive("fy", k.fy);
  positive("depth_scale", k.depth_scale);
  if (!std::isfinite(k.cx) || !std::isfinite(k.cy))
    fail(path, "cx or cy is not finite (expected numbers)");
}

}  // namespace

Intrinsics read_intrinsics(const std::string& path) {
  const nlohmann::json j = read_json(path);
  if (!j.is_object())
    fail(path, std::string("top level is ") + j.type_name() +
                   " (expected an object with fx, fy, cx, cy, depth_scale)");
  Intrinsics k;
  auto get = [&](const char* name, double& out, bool required) {
    if (!j.contains(name)) {
      if (required) fail(path, std::string("missing field \"") + name + "\" (expected a number)");
      return;
    }
    out = json_number(path, j.at(name), name);
  };
  get("fx", k.fx, true);
  get("fy", k.fy, true);
  get("cx", k.cx, true);
  get("cy", k.cy, true);
  get("depth_scale", k.depth_scale, false);
  check_intrinsics(path, k);
  return k;
}

Intrinsics read_ycb_meta(const std::string& path) {
  const nlohmann::json j = read_json(path);
  if (!j.is_object()) fail(path, "top level is not an object (expected YCB-Video meta JSON)");
  if (!j.contains("intrinsic_matrix"))
    fail(path, "missing field \"intrinsic_matrix\" (expected a 3x3 array)");
  const auto& m = j.at("intrinsic_matrix");
  auto row_ok = [](const nlohmann::json& r) {
    return r.is_array() && r.size() == 3 &&
           std::all_of(r.begin(), r.end(), [](const nlohmann::json& v) { return v.is_number(); });
  };
  if (!m.is_array() || m.size() != 3 || !std::all_of(m.begin(), m.end(), row_ok))
    fail(path,
         "field \"intrinsic_matrix\" is not a 3x3 array of numbers (expected "
         "[[fx,0,cx],[0,fy,cy],[0,0,1]])");
  if (!j.contains("factor_depth"))
    fail(path, "missing field \"factor_depth\" (expected a number or [[number]])");
  const nlohmann::json* fd = &j.at("factor_depth");
  while (fd->is_array() && fd->size() == 1) fd = &(*fd)[0];
  Intrinsics k;
  k.fx = json_number(path, m[0][0], "intrinsic_matrix");
  k.cx = json_number(path, m[0][2], "intrinsic_matrix");
  k.fy = json_number(path, m[1][1], "intrinsic_matrix");
  k.cy = json_number(path, m[1][2], "intrinsic_matrix");
  k.depth_scale = json_number(path, *fd, "factor_depth");
  if (!(k.depth_scale > 0))
    fail(path, "field \"factor_depth\" is " + num(k.depth_scale) + " (expected > 0)");
  check_intrinsics(path, k);
  return k;
}

Frame read_rgbd(const std::string& colour_path, const std::string& depth_path,
                const Intrinsics& k) {
  check(k);
  const cv::Mat colour = read_image(colour_path);
  const cv::Mat depth = read_image(depth_path);
  if (colour.depth() != CV_8U ||
      (colour.channels() != 1 && colour.channels() != 3 && colour.channels() != 4))
    fail(colour_path, "colour image is " + mat_kind(colour) +
                          " (expected 8-bit grey, 3-channel colour or 4-channel colour+alpha)");
  if (depth.depth() != CV_16U || depth.channels() != 1)
    fail(depth_path, "depth image is " + mat_kind(depth) + " (expected 16-bit 1-channel)");
  if (colour.size() != depth.size())
    fail(depth_path, "depth image is " + size_str(depth) + " but colour image " + colour_path +
                         " is " + size_str(colour) + " (expected the same size)");
  Frame frame;
  frame.width = colour.cols;
  frame.height = colour.rows;
  const cv::Mat dense = depth.isContinuous() ? depth : depth.clone();
  frame.xyz = back_project(dense.ptr<std::uint16_t>(0), depth.cols, depth.rows, k);
  frame.rgb.resize(frame.xyz.size());
  const int ch = colour.channels();
  for (int v = 0; v < colour.rows; ++v) {
    const auto* crow = colour.ptr<std::uint8_t>(v);
    for (int u = 0; u < colour.cols; ++u) {
      const std::uint8_t* c = crow + static_cast<std::size_t>(u) * ch;
      frame.rgb[static_cast<std::size_t>(v) * colour.cols + u] =
          ch == 1 ? Rgb{c[0], c[0], c[0]} : Rgb{c[2], c[1], c[0]};  // BGR(A) -> RGB
    }
  }
  if (frame.valid_count() == 0)
    fail(depth_path, "has no valid depth (all pixels are 0; expected some depth > 0)");
  return frame;
}

}  // namespace proxseg
