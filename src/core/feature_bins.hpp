// The histogram helpers of the feature blocks [paper 3.1]: a value's bin, a block normalised to
// sum 1.
#pragma once
#include <Eigen/Core>
#include <algorithm>

namespace proxseg::detail {

inline int bin_of(double t, int bins) {  // t in [0, 1] -> 0..bins-1
  return std::clamp(static_cast<int>(t * bins), 0, bins - 1);
}

inline void normalise(Eigen::Ref<Eigen::VectorXf> block) {
  const float sum = block.sum();
  if (sum > 0) block /= sum;
}

}  // namespace proxseg::detail
