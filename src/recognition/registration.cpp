// Registration [paper 3.4, Algorithm 2]: a model view aligned to a candidate object by RANSAC on
// FPFH correspondences (ransac.cpp), ICP from the best hypotheses (icp.cpp) and the scores of
// eq. 4-5 (alignment_scores.cpp).
#include <proxseg/recognition/registration.hpp>

#include "colour_scores.hpp"
#include "coverage_bound.hpp"
#include "icp.hpp"
#include "ransac.hpp"
#include "search_index.hpp"
#include "util/stopwatch.hpp"

#include <algorithm>
#include <functional>
#include <random>

namespace proxseg {

using detail::correspondences;
using detail::explained_colour;
using detail::Hypothesis;
using detail::icp;
using detail::ransac;

Alignment align(const Cloud& candidate, const Cloud& view, const RegistrationParams& params,
                std::uint64_t seed) {
  return align(candidate, subsample(candidate, params.max_points), view, params, seed);
}

Alignment align(const Cloud& candidate_all, const Cloud& candidate, const Cloud& view,
                const RegistrationParams& params, std::uint64_t seed) {
  Alignment a;
  detail::Stopwatch watch;
  std::mt19937_64 rng(seed);
  const int blocks = static_cast<int>(view.features.rows()) / kFpfhBins;
  std::vector<Hypothesis> top;
  if (params.multi_radius == MultiRadius::kBestOf && blocks > 1) {
    for (int b = 0; b < blocks; ++b) {
      const auto corr = correspondences(candidate, view, b, params.mutual_filter);
      auto h = ransac(candidate, view, corr, params, rng);
      a.correspondences = std::max<int>(a.correspondences, corr.size());
      top.insert(top.end(), h.begin(), h.end());
    }
    std::stable_sort(top.begin(), top.end(), [](const Hypothesis& x, const Hypothesis& y) {
      return x.overlap > y.overlap;
    });
  } else {
    const auto corr = correspondences(candidate, view, -1, params.mutual_filter);
    a.correspondences = static_cast<int>(corr.size());
    top = ransac(candidate, view, corr, params, rng);
  }
  // Algorithm 2 starts from the centroid shift: without a RANSAC hypothesis, the view's
  // centroid is put on the candidate's and ICP starts from there.
  if (top.empty() || top[0].overlap <= 0) {
    Hypothesis h;
    h.pose.topRightCorner<3, 1>() = candidate.centroid - view.centroid;
    top.assign(1, h);
  }
  a.ransac_inliers = top[0].inliers;
  a.ransac_ms = watch.lap();
  // ICP from the best few hypotheses; near-symmetric objects (boxes, bricks) have several
  // hypotheses of almost equal overlap, and only after ICP does the right one stand out.
  double best = -1;
  const int starts = std::min<int>(std::max(1, params.icp_starts), static_cast<int>(top.size()));
  for (int k = 0; k < starts; ++k) {
    int iterations = 0;
    const Eigen::Matrix4d pose = icp(candidate, view, top[k].pose, params, iterations);
    double agree = 1;
    const bool coloured =
        params.colour_alignment && !candidate.colours.empty() && !view.colours.empty();
    const double explained = starts == 1 ? 0
                             : coloured
                                 ? explained_colour(candidate, view, pose, params.score_distance,
                                                    params.brightness_sigma, agree)
                                 : fitness(candidate, view, pose, params.score_distance);
    // A start whose score cannot exceed the best so far need not be counted out.
    const auto overlap = [&](double cov) { return symmetric_overlap(explained, cov) * agree; };
    std::function<bool(double)> hopeless;
    if (k > 0) hopeless = [&](double cov) { return !(overlap(cov) > best); };
    const double score = starts == 1
                             ? 0
                             : overlap(detail::coverage_unless(candidate, view, pose,
                                                               params.score_distance, 1, hopeless));
    if (score > best) {
      best = score;
      a.pose = pose;
      a.icp_iterations = iterations;
    }
  }
  a.icp_ms = watch.lap();
  const Alignment scored = score_pose(candidate_all, view, a.pose, params);
  a.fitness = scored.fitness;
  a.close_fitness = scored.close_fitness;
  a.coverage = scored.coverage;
  a.occluded_coverage = scored.occluded_coverage;
  a.rmse = scored.rmse;
  a.colour = scored.colour;
  a.coloured = scored.coloured;
  a.score_ms = watch.lap();
  return a;
}

}  // namespace proxseg
