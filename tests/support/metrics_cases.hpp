// Scores of hand-made labellings for the tests of the segmentation metrics (tests/eval/): the
// scores with the V-measure checked on the way, every field compared, and the expected scores
// written field group by field group.
#pragma once
#include <gtest/gtest.h>
#include <proxseg/eval/metrics.hpp>

#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <vector>

namespace metrics_test {

using proxseg::SegmentationScores;
using Labels = std::vector<std::uint32_t>;

inline constexpr double kTol = 1e-9;
inline constexpr std::uint32_t kMax = 4294967295u;

// Entropy in nats of a distribution given by its probabilities.
inline double H(std::initializer_list<double> p) {
  double h = 0;
  for (const double x : p) h -= x * std::log(x);
  return h;
}

// Scores with background {1}; checks on the way that the V-measure field is v_measure's value.
inline SegmentationScores score(const Labels& truth, const Labels& predicted,
                                const Labels& background = {1}) {
  const SegmentationScores s = proxseg::score_segmentation(truth, predicted, background);
  const proxseg::VMeasure v = proxseg::v_measure(truth, predicted);
  EXPECT_EQ(s.v.homogeneity, v.homogeneity);
  EXPECT_EQ(s.v.completeness, v.completeness);
  EXPECT_EQ(s.v.v, v.v);
  return s;
}

// Compares every field, so that no metric goes untested in any case.
inline void expect_scores(const SegmentationScores& got, const SegmentationScores& want) {
  EXPECT_EQ(got.points, want.points);
  EXPECT_EQ(got.truth_regions, want.truth_regions);
  EXPECT_EQ(got.truth_objects, want.truth_objects);
  EXPECT_EQ(got.segments, want.segments);
  EXPECT_NEAR(got.paper_precision, want.paper_precision, kTol) << "paper_precision";
  EXPECT_NEAR(got.paper_recall, want.paper_recall, kTol) << "paper_recall";
  EXPECT_NEAR(got.v.homogeneity, want.v.homogeneity, kTol) << "homogeneity";
  EXPECT_NEAR(got.v.completeness, want.v.completeness, kTol) << "completeness";
  EXPECT_NEAR(got.v.v, want.v.v, kTol) << "v";
  EXPECT_NEAR(got.weighted_overlap, want.weighted_overlap, kTol) << "weighted_overlap";
  EXPECT_NEAR(got.object_precision, want.object_precision, kTol) << "object_precision";
  EXPECT_NEAR(got.object_recall, want.object_recall, kTol) << "object_recall";
  EXPECT_NEAR(got.object_f, want.object_f, kTol) << "object_f";
  EXPECT_NEAR(got.detected_075, want.detected_075, kTol) << "detected_075";
  EXPECT_EQ(got.over_segmented, want.over_segmented);
  EXPECT_EQ(got.under_segmented, want.under_segmented);
  EXPECT_EQ(got.lost_in_background, want.lost_in_background);
  EXPECT_EQ(got.unassigned_objects, want.unassigned_objects);
  EXPECT_NEAR(got.lost_in_background_share, want.lost_in_background_share, kTol)
      << "lost_in_background_share";
}

inline SegmentationScores counts(std::size_t points, int regions, int objects, int segments) {
  SegmentationScores s;
  s.points = points;
  s.truth_regions = regions;
  s.truth_objects = objects;
  s.segments = segments;
  return s;
}

// 2hc / (h + c), the V-measure of given homogeneity and completeness.
inline proxseg::VMeasure vm(double h, double c) {
  return {h, c, 2 * h * c / (h + c)};
}

// The paper's precision and recall [paper 4] of the expected scores.
inline void set_paper_scores(SegmentationScores& s, double precision, double recall) {
  s.paper_precision = precision;
  s.paper_recall = recall;
}

// The object scores of the expected scores: precision, recall, F and the share of objects
// detected at F >= 0.75.
inline void set_object_scores(SegmentationScores& s, double precision, double recall, double f,
                              double detected) {
  s.object_precision = precision;
  s.object_recall = recall;
  s.object_f = f;
  s.detected_075 = detected;
}

}  // namespace metrics_test
