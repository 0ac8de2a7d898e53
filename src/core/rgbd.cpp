// Pinhole back-projection of depth images (rgbd.hpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/core/rgbd.hpp>

#include <cmath>
#include <limits>
#include <sstream>
#include <string>

namespace proxseg {
namespace {

std::string text(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

// A pixel with depth must give a point: one that cannot be held is the intrinsics' fault (a
// scale or focal length off by orders of magnitude), not the depth image's, so say so.
[[noreturn]] void beyond_float_range(int u, int v, double d, const Eigen::Vector3f& p,
                                     const Intrinsics& k) {
  const char* axis = !std::isfinite(p.z()) ? "z" : !std::isfinite(p.x()) ? "x" : "y";
  throw InputError("intrinsics: pixel (" + std::to_string(u) + ", " + std::to_string(v) +
                   ") with depth " + text(d) + " back-projects beyond the range of a float (" +
                   axis + ") with fx " + text(k.fx) + ", fy " + text(k.fy) + ", cx " + text(k.cx) +
                   ", cy " + text(k.cy) + ", depth_scale " + text(k.depth_scale) +
                   " (expected fx, fy in pixels, cx, cy near the image centre, depth_scale in "
                   "depth units per metre, 1000 for millimetres)");
}

template <class Depth>
std::vector<Eigen::Vector3f> back_project_image(const Depth* depth, int width, int height,
                                                const Intrinsics& k) {
  check(k);
  if (width < 0 || height < 0) throw InputError("depth image: negative size");
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  std::vector<Eigen::Vector3f> xyz(n);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * width + u;
      const double d = static_cast<double>(depth[i]);
      if (!(d > 0) || !std::isfinite(d)) {
        xyz[i] = Eigen::Vector3f(nan, nan, nan);
        continue;
      }
      const double z = d / k.depth_scale;
      xyz[i] = Eigen::Vector3f(static_cast<float>((u - k.cx) * z / k.fx),
                               static_cast<float>((v - k.cy) * z / k.fy), static_cast<float>(z));
      if (!xyz[i].allFinite()) beyond_float_range(u, v, d, xyz[i], k);
    }
  return xyz;
}

}  // namespace

void check(const Intrinsics& k) {
  if (!(k.fx > 0) || !(k.fy > 0) || !(k.depth_scale > 0) || !std::isfinite(k.fx) ||
      !std::isfinite(k.fy) || !std::isfinite(k.depth_scale) || !std::isfinite(k.cx) ||
      !std::isfinite(k.cy))
    throw InputError("intrinsics: fx, fy and depth_scale must be finite and > 0, cx and cy finite");
}

std::vector<Eigen::Vector3f> back_project(const std::uint16_t* depth, int width, int height,
                                          const Intrinsics& k) {
  return back_project_image(depth, width, height, k);
}

std::vector<Eigen::Vector3f> back_project(const float* depth, int width, int height,
                                          const Intrinsics& k) {
  return back_project_image(depth, width, height, k);
}

}  // namespace proxseg
