// The error of an estimated pose: box symmetries of a model, the error under them, the error about
// an axis (pose_error.hpp).
#include <proxseg/eval/pose_error.hpp>

#include <proxseg/core/frame.hpp>
#include <proxseg/core/selection.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "util/angles.hpp"
#include "util/nearest_points.hpp"
#include "util/pca_normal.hpp"

namespace proxseg {

namespace {

// The frame of a box from its faces: the most common normal direction (sign ignored), then the
// most common one at right angles to it. Principal axes fail for boxes with two near-equal sides
// (the foam brick): their cross-section has no preferred direction, so PCA turns the box frame
// by an arbitrary angle and no turn of that frame maps the box onto itself.
Eigen::Matrix3d face_axes(const std::vector<Eigen::Vector3d>& model) {
  constexpr int kNeighbours = 20;
  const detail::NearestPoints search(model);
  std::vector<Eigen::Vector3d> normals(model.size(), Eigen::Vector3d::UnitZ());
  for (std::size_t i = 0; i < model.size(); ++i) {
    const auto neighbours = search.nearest(model[i], kNeighbours);
    if (neighbours.size() >= 3) normals[i] = detail::pca_normal(model, neighbours);
  }
  const double parallel = std::cos(detail::radians(5)), orthogonal = std::sin(detail::radians(5));
  const std::size_t stride = std::max<std::size_t>(1, normals.size() / 300);
  auto most_common = [&](auto accept) {
    Eigen::Vector3d best = Eigen::Vector3d::Zero();
    std::size_t best_count = 0;
    for (std::size_t i = 0; i < normals.size(); i += stride) {
      if (!accept(normals[i])) continue;
      std::size_t count = 0;
      for (const auto& n : normals) count += std::abs(n.dot(normals[i])) >= parallel;
      if (count > best_count) best_count = count, best = normals[i];
    }
    return best;
  };
  const Eigen::Vector3d a = most_common([](const Eigen::Vector3d&) { return true; });
  Eigen::Vector3d b =
      most_common([&](const Eigen::Vector3d& n) { return std::abs(n.dot(a)) <= orthogonal; });
  if (a.isZero() || b.isZero()) return Eigen::Matrix3d::Identity();
  b = (b - b.dot(a) * a).normalized();
  Eigen::Matrix3d axes;
  axes << a, b, a.cross(b);
  return axes;
}

// The model's box in the frame of its faces (face_axes): its extents and centre.
OrientedBox face_box(const std::vector<Eigen::Vector3d>& model) {
  OrientedBox box;
  box.axes = face_axes(model);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const auto& p : model) {
    const Eigen::Vector3d q = box.axes.transpose() * p;
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  box.extent = hi - lo;
  box.centre = box.axes * ((lo + hi) / 2);
  return box;
}

}  // namespace

std::vector<Eigen::Matrix4d> box_symmetries(const std::vector<Eigen::Vector3d>& model,
                                            double tolerance) {
  if (model.empty()) return {Eigen::Matrix4d::Identity()};
  Frame f;
  for (const auto& p : model) f.xyz.push_back(p.cast<float>());
  f.rgb.assign(model.size(), Rgb{0, 0, 0});
  f.width = static_cast<int>(model.size());
  f.height = 1;
  std::vector<int> all(model.size());
  std::iota(all.begin(), all.end(), 0);
  // Two candidate box frames: the face normals, then (as a fallback) the principal axes.
  std::vector<OrientedBox> boxes;
  boxes.push_back(face_box(model));
  boxes.push_back(oriented_box(f, all));
  std::vector<Eigen::Matrix4d> out = {Eigen::Matrix4d::Identity()};
  // Mean distance from each turned point to the nearest model point (brute force on a subsample:
  // models are a few thousand points and this runs once per model).
  const std::size_t stride = std::max<std::size_t>(1, model.size() / 400);
  auto maps_onto_itself = [&](const Eigen::Matrix4d& s) {
    double sum = 0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < model.size(); i += stride, ++n) {
      const Eigen::Vector3d q = s.topLeftCorner<3, 3>() * model[i] + s.topRightCorner<3, 1>();
      double best = std::numeric_limits<double>::infinity();
      for (const auto& p : model) best = std::min(best, (p - q).squaredNorm());
      sum += std::sqrt(best);
    }
    return n && sum / n < tolerance;
  };
  // A turn within 10 degrees of a known one is the same symmetry seen from the other frame.
  auto known = [&](const Eigen::Matrix3d& r) {
    for (const auto& o : out)
      if (Eigen::AngleAxisd(Eigen::Matrix3d(o.topLeftCorner<3, 3>().transpose() * r)).angle() <
          detail::radians(10))
        return true;
    return false;
  };
  for (const OrientedBox& box : boxes) {
    // The principal axes only when the faces gave nothing: where both give turns, the principal
    // ones are the same symmetries a few degrees off, and their products would pass for small
    // symmetric turns.
    if (out.size() > 1) break;
    // Candidate turns in the box frame: 180 degrees about each axis; 90 and 270 about an axis
    // whose other two extents are equal within tolerance.
    std::vector<Eigen::Matrix3d> turns;
    for (int a = 0; a < 3; ++a) {
      const Eigen::Vector3d axis = Eigen::Vector3d::Unit(a);
      turns.push_back(Eigen::AngleAxisd(detail::kPi, axis).toRotationMatrix());
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      if (std::abs(box.extent[b] - box.extent[c]) < 2 * tolerance)
        for (double angle : {detail::kPi / 2, 3 * detail::kPi / 2})
          turns.push_back(Eigen::AngleAxisd(angle, axis).toRotationMatrix());
    }
    for (const Eigen::Matrix3d& t : turns) {
      Eigen::Matrix4d s = Eigen::Matrix4d::Identity();
      const Eigen::Matrix3d r = box.axes * t * box.axes.transpose();
      s.topLeftCorner<3, 3>() = r;
      s.topRightCorner<3, 1>() = box.centre - r * box.centre;
      if (!known(r) && maps_onto_itself(s)) out.push_back(s);
    }
  }
  // Products of symmetries are symmetries: a square prism's 180-degree turns about the diagonals
  // of its square are a 90-degree turn about its axis followed by a 180-degree one about a side.
  for (std::size_t i = 1; i < out.size(); ++i)
    for (std::size_t j = 1; j <= i && out.size() < 24; ++j)
      for (const Eigen::Matrix4d& s :
           {Eigen::Matrix4d(out[i] * out[j]), Eigen::Matrix4d(out[j] * out[i])})
        if (!known(s.topLeftCorner<3, 3>()) && maps_onto_itself(s)) out.push_back(s);
  return out;
}

PoseError pose_error(const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth,
                     const std::vector<Eigen::Matrix4d>& symmetries) {
  PoseError best{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  const auto one = [&](const Eigen::Matrix4d& t) {
    const Eigen::Matrix3d dr = estimate.topLeftCorner<3, 3>().transpose() * t.topLeftCorner<3, 3>();
    const double angle = detail::degrees(Eigen::AngleAxisd(dr).angle());
    const double dt = (estimate.topRightCorner<3, 1>() - t.topRightCorner<3, 1>()).norm();
    // Rank by rotation first: symmetric equivalents differ mostly in rotation.
    if (angle < best.rotation_deg) best = {dt, angle};
  };
  one(truth);
  for (const auto& s : symmetries) one(truth * s);
  return best;
}

PoseError axial_pose_error(const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth,
                           const Eigen::Vector3d& centre, const Eigen::Vector3d& axis) {
  const Eigen::Vector3d a = estimate.topLeftCorner<3, 3>() * axis.normalized();
  const Eigen::Vector3d b = truth.topLeftCorner<3, 3>() * axis.normalized();
  const Eigen::Vector3d ca =
      estimate.topLeftCorner<3, 3>() * centre + estimate.topRightCorner<3, 1>();
  const Eigen::Vector3d cb = truth.topLeftCorner<3, 3>() * centre + truth.topRightCorner<3, 1>();
  return {(ca - cb).norm(), detail::degrees(std::acos(std::clamp(a.dot(b), -1.0, 1.0)))};
}

}  // namespace proxseg
