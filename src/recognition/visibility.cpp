// The free-space check of a posed model against the frame's depths (visibility.hpp).
#include <proxseg/recognition/visibility.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace proxseg {

DepthImage depth_image(const Frame& frame) {
  DepthImage out;
  if (!frame.organized()) return out;
  // u = fx x / z + cx and v = fy y / z + cy, fitted by least squares on every 4th pixel.
  Eigen::Matrix2d au = Eigen::Matrix2d::Zero(), av = Eigen::Matrix2d::Zero();
  Eigen::Vector2d bu = Eigen::Vector2d::Zero(), bv = Eigen::Vector2d::Zero();
  int n = 0;
  for (int v = 0; v < frame.height; v += 4)
    for (int u = 0; u < frame.width; u += 4) {
      const std::size_t i = static_cast<std::size_t>(v) * frame.width + u;
      if (!frame.valid(i) || !(frame.xyz[i].z() > 0)) continue;
      const Eigen::Vector2d x(frame.xyz[i].x() / frame.xyz[i].z(), 1.0);
      const Eigen::Vector2d y(frame.xyz[i].y() / frame.xyz[i].z(), 1.0);
      au += x * x.transpose(), bu += x * u;
      av += y * y.transpose(), bv += y * v;
      ++n;
    }
  if (n < 100) return out;
  const Eigen::Vector2d pu = au.ldlt().solve(bu), pv = av.ldlt().solve(bv);
  if (!(pu.x() > 0) || !(pv.x() > 0)) return out;
  // The fit must explain the pixels: a frame whose points were moved off their rays has none.
  double worst = 0;
  for (int v = 0; v < frame.height; v += 16)
    for (int u = 0; u < frame.width; u += 16) {
      const std::size_t i = static_cast<std::size_t>(v) * frame.width + u;
      if (!frame.valid(i) || !(frame.xyz[i].z() > 0)) continue;
      const double eu = pu.x() * frame.xyz[i].x() / frame.xyz[i].z() + pu.y() - u;
      const double ev = pv.x() * frame.xyz[i].y() / frame.xyz[i].z() + pv.y() - v;
      worst = std::max({worst, std::abs(eu), std::abs(ev)});
    }
  if (worst > 1.0) return out;
  out.width = frame.width;
  out.height = frame.height;
  out.fx = pu.x(), out.cx = pu.y(), out.fy = pv.x(), out.cy = pv.y();
  out.z.resize(frame.size());
  for (std::size_t i = 0; i < frame.size(); ++i)
    out.z[i] = frame.valid(i) ? frame.xyz[i].z() : std::nanf("");
  return out;
}

double free_space_violation(const DepthImage& image, const Cloud& view, const Eigen::Matrix4d& pose,
                            double tolerance, double slope) {
  if (image.empty()) return 0;
  const Eigen::Matrix3d r = pose.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = pose.topRightCorner<3, 1>();
  int seen = 0, through = 0;
  for (std::size_t j = 0; j < view.size(); ++j) {
    const Eigen::Vector3d q = r * view.points[j] + t;
    if (!(q.z() > 0) || (r * view.normals[j]).dot(q) >= 0) continue;  // behind, or facing away
    const long u = std::lround(image.fx * q.x() / q.z() + image.cx);
    const long v = std::lround(image.fy * q.y() / q.z() + image.cy);
    if (u < 0 || v < 0 || u >= image.width || v >= image.height) {
      // Off the image the sensor saw nothing: the model cannot be checked there, and a view that
      // must reach past the image to fit is more likely fitted to a piece of the background
      // that the image cuts (a desk's edge) than to an object.
      ++seen, ++through;
      continue;
    }
    const float measured = image.z[static_cast<std::size_t>(v) * image.width + u];
    if (!std::isfinite(measured)) continue;
    ++seen;
    through += measured > q.z() + tolerance + slope * q.z() * q.z();
  }
  return seen ? double(through) / seen : 0;
}

double border_unexplained(const DepthImage& image, const Cloud& candidate, const Cloud& view,
                          const Eigen::Matrix4d& pose, double delta) {
  constexpr int kMinPoints = 5;  // fewer: a corner grazing the border, not a cut
  if (image.empty()) return 0;
  std::vector<Eigen::Vector3d> border;
  for (const Eigen::Vector3d& p : candidate.points) {
    if (!(p.z() > 0)) continue;
    // One point spacing in pixels at this depth: the voxel filter moves points that far inwards.
    const double reach = std::max(1.0, image.fx * candidate.spacing / p.z());
    const double u = image.fx * p.x() / p.z() + image.cx, v = image.fy * p.y() / p.z() + image.cy;
    if (u < reach || v < reach || u > image.width - 1 - reach || v > image.height - 1 - reach)
      border.push_back(p);
  }
  if (static_cast<int>(border.size()) < kMinPoints) return 0;
  const std::vector<char> in = explained(border, view, pose, delta);
  return 1.0 - double(std::count(in.begin(), in.end(), 1)) / border.size();
}

}  // namespace proxseg
