// Coverage (eq. 4's counterpart: the share of the visible view the candidate explains) that
// stops early once the pose cannot matter: RANSAC's judge and ICP's starts only need the
// coverage of a pose that may still beat the ones they keep. Private to src/recognition.
#pragma once
#include <proxseg/core/registration_types.hpp>

#include <Eigen/Core>
#include <functional>

namespace proxseg::detail {

// coverage() (registration.hpp), unless hopeless(b) holds for an upper bound b of it (the
// coverage if every point not yet checked were explained): then some such b, and the true
// coverage is at most b. Without hopeless, exactly coverage().
double coverage_unless(const Cloud& candidate, const Cloud& view, const Eigen::Matrix4d& pose,
                       double delta, double outside_weight,
                       const std::function<bool(double)>& hopeless);

}  // namespace proxseg::detail
