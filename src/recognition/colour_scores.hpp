// The colour term of an alignment [extension, docs/method.md "Colour in recognition"], as
// RANSAC's judging and ICP's choice of start weigh it. Private to src/recognition.
#pragma once
#include <proxseg/core/registration_types.hpp>

#include <Eigen/Core>

namespace proxseg::detail {

// fitness() within delta, and in `colour` the mean chromaticity agreement of the explained
// candidate points with the view points that explain them.
double explained_colour(const Cloud& cand, const Cloud& view, const Eigen::Matrix4d& pose,
                        double delta, double brightness_sigma, double& colour);

}  // namespace proxseg::detail
