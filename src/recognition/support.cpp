// Physical support [extension, docs/method.md "Real sensors"]: the support plane, the object
// surfaces over it, and how a posed model stands among them (support.hpp).
#include <proxseg/recognition/support.hpp>

#include "util/moments.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace proxseg {

SupportPlane support_plane(const Frame& frame, const Selection& selection) {
  const Candidate* largest = nullptr;
  for (const Candidate& c : selection.components)
    if (c.background && (!largest || c.points.size() > largest->points.size())) largest = &c;
  SupportPlane plane;
  if (!largest || largest->points.size() < 3) return plane;
  const auto& pts = largest->points;
  const auto m = detail::moments(pts.size(), [&](std::size_t j) { return frame.xyz[pts[j]]; });
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(m.scatter);
  Eigen::Vector3d n = eig.eigenvectors().col(0).normalized();
  if (n.dot(m.mean) > 0) n = -n;  // towards the sensor (at the origin): objects stand that way
  plane.normal = n;
  plane.offset = -n.dot(m.mean);
  return plane;
}

namespace {

// Over this height a point is an object's surface, not the plane's (its noise band, roughness).
constexpr double kOverPlane = 0.01;
// A grid of at most this many cells: a larger scene gets coarser cells.
constexpr double kMaxCells = 4e6;

Eigen::Vector2d in_plane(const SupportScene& s, const Eigen::Vector3d& x) {
  return {s.u.dot(x) / s.cell, s.v.dot(x) / s.cell};
}

}  // namespace

SupportScene support_scene(const Frame& frame, const Selection& selection,
                           const SupportPlane& plane, double cell) {
  SupportScene s;
  s.plane = plane;
  if (plane.empty()) return s;
  // Any two axes across the normal; the grid only needs them fixed for the frame.
  const Eigen::Vector3d n = plane.normal;
  const Eigen::Vector3d a =
      std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  s.u = n.cross(a).normalized();
  s.v = n.cross(s.u);
  for (const Candidate& c : selection.components)
    if (!c.background)
      for (int p : c.points)
        if (frame.valid(p) && plane.height(frame.xyz[p].cast<double>()) > kOverPlane)
          s.points.push_back(p);
  std::sort(s.points.begin(), s.points.end());
  if (s.points.empty()) return s;
  Eigen::AlignedBox2d box;
  for (int p : s.points)
    box.extend(Eigen::Vector2d(s.u.dot(frame.xyz[p].cast<double>()),
                               s.v.dot(frame.xyz[p].cast<double>())));
  s.cell = cell;
  while ((box.sizes().x() / s.cell + 1) * (box.sizes().y() / s.cell + 1) > kMaxCells) s.cell *= 2;
  s.x0 = static_cast<int>(std::floor(box.min().x() / s.cell));
  s.y0 = static_cast<int>(std::floor(box.min().y() / s.cell));
  s.nx = static_cast<int>(std::floor(box.max().x() / s.cell)) - s.x0 + 1;
  s.ny = static_cast<int>(std::floor(box.max().y() / s.cell)) - s.y0 + 1;
  s.cells.reserve(s.points.size());
  s.heights.reserve(s.points.size());
  for (int p : s.points) {
    const Eigen::Vector3d x = frame.xyz[p].cast<double>();
    const Eigen::Vector2d g = in_plane(s, x);
    const int cx = std::clamp(static_cast<int>(std::floor(g.x())) - s.x0, 0, s.nx - 1);
    const int cy = std::clamp(static_cast<int>(std::floor(g.y())) - s.y0, 0, s.ny - 1);
    s.cells.push_back(cx + s.nx * cy);
    s.heights.push_back(static_cast<float>(plane.height(x)));
  }
  return s;
}

std::vector<float> surfaces_around(const SupportScene& scene, const std::vector<int>& candidate) {
  std::vector<float> top(static_cast<std::size_t>(scene.nx) * scene.ny,
                         std::numeric_limits<float>::quiet_NaN());
  // Both lists ascending: one walk leaves the candidate's own points out.
  std::size_t k = 0;
  for (std::size_t i = 0; i < scene.points.size(); ++i) {
    while (k < candidate.size() && candidate[k] < scene.points[i]) ++k;
    if (k < candidate.size() && candidate[k] == scene.points[i]) continue;
    float& t = top[scene.cells[i]];
    if (!(t >= scene.heights[i])) t = scene.heights[i];
  }
  return top;
}

StanceCheck stance(const SupportScene& scene, const std::vector<float>& surfaces,
                   const Cloud& candidate, const Cloud& view, const Eigen::Matrix4d& pose,
                   double gap, double max_height) {
  StanceCheck out;
  if (scene.empty() || view.points.empty() || candidate.points.empty()) {
    out.bottom = std::numeric_limits<double>::quiet_NaN();
    return out;
  }
  double lowest_seen = std::numeric_limits<double>::infinity();
  for (const auto& p : candidate.points) lowest_seen = std::min(lowest_seen, scene.plane.height(p));
  const Eigen::Matrix3d r = pose.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = pose.topRightCorner<3, 1>();
  std::vector<Eigen::Vector3d> posed;
  posed.reserve(view.points.size());
  out.bottom = std::numeric_limits<double>::infinity();
  for (const auto& p : view.points) {
    posed.push_back(r * p + t);
    out.bottom = std::min(out.bottom, scene.plane.height(posed.back()));
  }
  // Beyond the table's edge or on a shelf over it: this plane says nothing of what holds it.
  if (lowest_seen < -gap || lowest_seen > max_height) return out;
  if (out.bottom < -gap) {
    out.stance = Stance::kSinks;
    return out;
  }
  if (out.bottom <= gap) return out;
  // Resting on another object: its top surface just under the model's lowest points.
  constexpr double kFoot = 0.01, kAcross = 0.02;
  const int reach = static_cast<int>(std::ceil(kAcross / scene.cell));
  for (const auto& x : posed) {
    if (scene.plane.height(x) > out.bottom + kFoot) continue;
    const Eigen::Vector2d g = in_plane(scene, x);
    const int cx = static_cast<int>(std::floor(g.x())) - scene.x0;
    const int cy = static_cast<int>(std::floor(g.y())) - scene.y0;
    for (int y = std::max(0, cy - reach); y <= std::min(scene.ny - 1, cy + reach); ++y)
      for (int xx = std::max(0, cx - reach); xx <= std::min(scene.nx - 1, cx + reach); ++xx) {
        const float top = surfaces[xx + static_cast<std::size_t>(scene.nx) * y];
        if (top >= out.bottom - gap && top <= out.bottom + kFoot) return out;
      }
  }
  out.stance = Stance::kFloats;
  return out;
}

}  // namespace proxseg
