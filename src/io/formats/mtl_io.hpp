// The materials of Wavefront OBJ meshes: MTL files (newmtl, Kd, map_Kd and its -s/-o options)
// and the PNG/JPEG textures they name, sampled as a GL_REPEAT sampler would. Private to the
// library (read_obj in obj_io.hpp draws them).
#pragma once
#include <Eigen/Core>
#include <functional>
#include <map>
#include <opencv2/core/mat.hpp>
#include <string>

namespace proxseg::detail::wavefront {

struct Material {
  bool has_kd = false;
  Eigen::Vector3f kd = Eigen::Vector3f::Zero();     // 0..255
  std::string texture;                              // map_Kd, resolved; empty = none
  Eigen::Vector2d uv_scale{1, 1}, uv_offset{0, 0};  // map_Kd -s and -o
  std::string texture_named_by;                     // for messages: " named by MTL line N"
};

using Materials = std::map<std::string, Material, std::less<>>;

// Adds the materials of an MTL file (newmtl, Kd, map_Kd; everything else is not drawn);
// `named_by` says where its name came from.
void read_mtl(const std::string& mtl, const std::string& named_by, Materials& materials);

// A texture as 8-bit BGR, whatever the file held (grey, alpha and 16-bit are converted).
cv::Mat read_texture(const Material& m);

// Bilinear texture colour (0..255 floats, r g b) at (u, v). Texel centres are at (i + 0.5) / size;
// UVs repeat, so the border texels blend with the opposite border as a GL_REPEAT sampler does.
Eigen::Vector3f sample(const cv::Mat& bgr, const Eigen::Vector2d& uv);

}  // namespace proxseg::detail::wavefront
