// What the sensor saw, as a depth image: a check that a model put in place does not predict
// surface where the sensor saw through it [extension, docs/method.md "Recognition that
// generalises"]. Fitness and coverage compare the model with the candidate's points only; the
// rest of the frame also says where no surface can be.
#pragma once
#include <proxseg/core/frame.hpp>
#include <proxseg/recognition/registration.hpp>

#include <Eigen/Core>
#include <vector>

namespace proxseg {

// An organized frame's measured depths (z, metres; NaN where there is no return) and the
// pinhole projection of its pixels, fitted to its points (the frame carries no intrinsics).
struct DepthImage {
  int width = 0, height = 0;
  std::vector<float> z;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  bool empty() const { return z.empty(); }
};

// The frame's depth image; empty for an unorganized frame or one whose points do not fit a
// pinhole projection (fewer than 100 valid points, or a fit off by more than a pixel).
DepthImage depth_image(const Frame& frame);

// Of the points of `view` put in the sensor frame by `pose` (sensor <- model) that face the
// sensor, the share that lies more than tolerance + slope x z^2 nearer than the depth measured
// at their pixel (surface the model predicts where the sensor saw farther, through it) or off
// the image (where it saw nothing, and the model cannot be checked). Points on pixels without a
// return say nothing (dark and shiny surfaces lose them). 0 when no point counts.
double free_space_violation(const DepthImage& image, const Cloud& view, const Eigen::Matrix4d& pose,
                            double tolerance, double slope = 0.005);

// Of the candidate's points (sensor frame) that lie within one point spacing of the image's
// border, the share that the view put in place by pose (sensor <- model) does not explain within
// delta; 0 when fewer than 5 lie there. A candidate cut by the border goes on past it: a model
// that ends inside the image while the candidate runs on to the border (a marker laid on the
// edge of a monitor that the image cuts) is not what the candidate is; a model that explains
// the candidate up to the border may be.
double border_unexplained(const DepthImage& image, const Cloud& candidate, const Cloud& view,
                          const Eigen::Matrix4d& pose, double delta);

}  // namespace proxseg
