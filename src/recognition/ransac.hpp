// RANSAC [paper 3.4, Algorithm 2]: pose hypotheses of a view on a candidate from feature
// correspondences, for align() to start ICP from. Private to src/recognition.
#pragma once
#include <proxseg/core/registration_types.hpp>

#include <Eigen/Core>
#include <random>
#include <utility>
#include <vector>

namespace proxseg::detail {

struct Hypothesis {
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  int inliers = 0;
  // sqrt(fitness x coverage) within ransac_distance; -1 when not judged (judge())
  double overlap = 0;
};

// Feature correspondences (candidate point, view point) in the features of radius block `block`
// (all radii when negative): each candidate point's nearest view feature, optionally kept only
// when the view point's nearest candidate feature is it.
std::vector<std::pair<int, int>> correspondences(const Cloud& cand, const Cloud& view, int block,
                                                 bool mutual);

// The best distinct hypotheses over the correspondences c (at most ransac_candidates), refitted
// on their inliers, best overlap first; none for fewer than 3 correspondences.
std::vector<Hypothesis> ransac(const Cloud& cand, const Cloud& view,
                               const std::vector<std::pair<int, int>>& c,
                               const RegistrationParams& p, std::mt19937_64& rng);

}  // namespace proxseg::detail
