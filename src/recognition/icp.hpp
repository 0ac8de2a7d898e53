// ICP [paper 3.4, Algorithm 2]: refines a pose (candidate <- model) of a view on a candidate.
// Private to src/recognition.
#pragma once
#include <proxseg/core/registration_types.hpp>

#include <Eigen/Core>

namespace proxseg::detail {

// The refined pose after at most icp_iterations steps; the steps taken in `iterations`.
Eigen::Matrix4d icp(const Cloud& cand, const Cloud& view, Eigen::Matrix4d pose,
                    const RegistrationParams& p, int& iterations);

}  // namespace proxseg::detail
