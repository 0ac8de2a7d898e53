// The error of an estimated pose [paper 4]: translation and rotation against the truth, the least
// over the model's symmetries (the box symmetries a model has), or about an axis for objects
// that look the same under any turn about it.
#pragma once
#include <Eigen/Core>
#include <vector>

namespace proxseg {

// The rotational symmetries of a model that are symmetries of its box (the 180 degree turns
// about its axes, the 90 degree turns about an axis whose two other extents are equal, and their
// products) and that map the model's points onto themselves within tolerance (mean distance), as
// model-frame transforms about the box centre. The box is found from the model's face normals
// (principal axes as a fallback). The identity is always first.
std::vector<Eigen::Matrix4d> box_symmetries(const std::vector<Eigen::Vector3d>& model,
                                            double tolerance);
struct PoseError {
  double translation = 0;  // metres
  double rotation_deg = 0;
};
// Error of an estimated pose (camera <- model) against the truth, the least over the truth's
// symmetric equivalents truth * S.
PoseError pose_error(const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth,
                     const std::vector<Eigen::Matrix4d>& symmetries);
// The error of a pose of an object that looks the same under any turn about an axis (model
// frame: a point and a direction), e.g. a mug whose handle is hidden: the angle between the
// estimated and true axes and the distance between the estimated and true positions of centre.
PoseError axial_pose_error(const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth,
                           const Eigen::Vector3d& centre, const Eigen::Vector3d& axis);

}  // namespace proxseg
