// Physical support [extension, docs/method.md "Real sensors"]: an object stands on the support
// plane (the table the selection cut, SelectionParams::cut_support_plane) or on another object;
// it neither floats in the air nor sinks through the table. A model that fits the visible top of
// a bottle hidden behind a box floats above the table with nothing under it; a model that fits a
// face of a box sinks through the table. Either is not what the candidate is, however well it
// fits what was seen.
#pragma once
#include <proxseg/core/frame.hpp>
#include <proxseg/core/recognition_types.hpp>
#include <proxseg/core/selection.hpp>
#include <proxseg/recognition/visibility.hpp>

#include <Eigen/Core>
#include <vector>

namespace proxseg {

// The plane the objects stand on: height(x) = normal . x + offset, normal towards the sensor.
// normal zero: the frame has none (no background component), and nothing is judged.
struct SupportPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double offset = 0;
  bool empty() const { return normal.isZero(); }
  double height(const Eigen::Vector3d& x) const { return normal.dot(x) + offset; }
};

// The plane fitted (least squares) to the largest background component of the selection (by
// points); empty when the selection has none.
SupportPlane support_plane(const Frame& frame, const Selection& selection);

// The scene's object surfaces over the support plane, for telling what else an object may stand
// on: the points of the selection's candidates (background left out) in cells of `cell` metres
// of the plane, each with its height. Points at or below 1 cm over the plane are left out (the
// plane itself supports).
struct SupportScene {
  SupportPlane plane;
  Eigen::Vector3d u = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();  // in-plane axes
  double cell = 0.01;
  int x0 = 0, y0 = 0, nx = 0, ny = 0;  // the grid's first cell and its size, in cells
  std::vector<int> points;             // frame indices, ascending
  std::vector<int> cells;              // per point, its cell (x - x0) + nx (y - y0)
  std::vector<float> heights;          // per point, its height over the plane
  bool empty() const { return plane.empty(); }
};
SupportScene support_scene(const Frame& frame, const Selection& selection,
                           const SupportPlane& plane, double cell = 0.01);

// Per cell of scene's grid, the height of the highest surface over it of every object but the
// candidate (its frame indices, ascending): NaN where there is none.
std::vector<float> surfaces_around(const SupportScene& scene, const std::vector<int>& candidate);

// How a posed model stands on the scene (Stance, registration_types.hpp): it floats when its
// lowest point is more than gap over the plane and no other object's top surface lies within
// gap under it (or 1 cm over it), within 2 cm across; it sinks when its lowest point is more than
// gap under the plane.
struct StanceCheck {
  Stance stance = Stance::kStands;
  double bottom = 0;  // the lowest model point's height over the plane (m)
};
// The candidate's points (sensor frame) say where it is: one whose own lowest point lies more
// than gap under the plane (beyond the table's edge) or higher than max_height over it (on a
// shelf over the table) is not judged. `surfaces`: surfaces_around() for the candidate.
StanceCheck stance(const SupportScene& scene, const std::vector<float>& surfaces,
                   const Cloud& candidate, const Cloud& view, const Eigen::Matrix4d& pose,
                   double gap, double max_height = 0.5);

// What the rest of the frame tells of a candidate's poses: its depths (free space, the image
// border) and the surfaces it may stand on. Either may be null.
struct SceneEvidence {
  const DepthImage* depths = nullptr;
  const SupportScene* support = nullptr;
  const std::vector<float>* surfaces = nullptr;  // surfaces_around() the candidate
};

}  // namespace proxseg
