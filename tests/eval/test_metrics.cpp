// Tests of the segmentation metrics on hand-made labellings whose every score is worked out by
// hand in the comments (the other checks: test_metrics_properties.cpp).
#include <proxseg/eval/metrics.hpp>
#include <proxseg/io/cloud_io.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <map>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "support/metrics_cases.hpp"

using namespace metrics_test;

namespace {

// Background 1 (4 points), objects 2 and 3 (3 points each).
const Labels kThree = {1, 1, 1, 1, 2, 2, 2, 3, 3, 3};

}  // namespace

TEST(Metrics, PerfectSegmentation) {
  // Every region is one segment, under other ids: every ratio is 1, nothing over/under-segmented.
  // Object P/R: segment 7 (all background) is left out; 8 and 9 match 2 and 3 with F = 1.
  SegmentationScores want = counts(10, 3, 2, 3);
  want.paper_precision = want.paper_recall = 1;
  want.v = {1, 1, 1};
  want.weighted_overlap = 1;
  want.object_precision = want.object_recall = want.object_f = want.detected_075 = 1;
  expect_scores(score(kThree, {7, 7, 7, 7, 8, 8, 8, 9, 9, 9}), want);
  expect_scores(score(kThree, kThree), want);
}

TEST(Metrics, EverythingOneSegment) {
  // Segment 5 = all 10 points: 4 background, 3 of object 2, 3 of object 3.
  // Paper: 5 -> region 1 (4 points, the majority). Region 1: P = 4/10, R = 4/4; regions 2, 3:
  //   no label, 0 and 0. Macro: P = 0.4 / 3, R = 1 / 3.
  // V: one cluster -> completeness 1 (convention), H(C|K) = H(C) -> homogeneity 0, V 0.
  // Weighted overlap: IoU(2, 5) = IoU(3, 5) = 3/10 -> (3 * 0.3 + 3 * 0.3) / 6 = 0.3.
  // Object: 5 has 4/10 on the background (not more than half): kept, |S| = 10.
  //   F(2,5) = F(3,5) = 6/13; one segment -> one pair, |S∩G| = 3. P = 3/10, R = 3/6,
  //   F = 2 * 0.3 * 0.5 / 0.8 = 0.375; F(S,G) = 6/13 < 0.75 -> detected 0.
  // Over: one segment -> 0. Under: both objects' largest segment is 5, with 4/10 >= 10% on
  //   the background -> 2.
  SegmentationScores want = counts(10, 3, 2, 1);
  set_paper_scores(want, 0.4 / 3, 1.0 / 3);
  want.v = {0, 1, 0};
  want.weighted_overlap = 0.3;
  set_object_scores(want, 0.3, 0.5, 0.375, 0);
  want.under_segmented = 2;
  expect_scores(score(kThree, Labels(10, 5)), want);
}

TEST(Metrics, ObjectSplitInTwoHalves) {
  // truth: background 1 (4), object 2 (4), object 3 (2); object 2 is split into 6 and 7.
  // Paper: 5 -> 1, 6 -> 2, 7 -> 2, 8 -> 3; every label is pure and covers its region: P = R = 1.
  // V: every cluster pure -> homogeneity 1. H(K|C) = 0.4 * ln 2 (class 2 split 2/2),
  //   H(K) = H(.4, .2, .2, .2) -> completeness c = 1 - 0.4 ln 2 / H(K), V = 2c / (1 + c).
  // Weighted overlap: IoU(2, 6) = IoU(2, 7) = 2/4, IoU(3, 8) = 1 -> (4 * 0.5 + 2 * 1) / 6 = 2/3.
  // Object: 5 is all background, left out; kept 6, 7, 8 (6 points). F(2,6) = F(2,7) = 4/6,
  //   F(3,8) = 1. Matching: 2-6 (or 2-7), 3-8, |S∩G| = 2 + 2 = 4. P = 4/6, R = 4/6, F = 2/3.
  //   Detected: object 3 (F 1); object 2 (F 2/3 < 0.75) not -> 1/2.
  // Over: object 2 has 6 and 7 each with 50% -> 1. Under: largest segment of 2 is 6 (tie with 7,
  //   smaller label), pure; of 3 is 8, pure -> 0.
  const Labels truth = {1, 1, 1, 1, 2, 2, 2, 2, 3, 3};
  const Labels pred = {5, 5, 5, 5, 6, 6, 7, 7, 8, 8};
  SegmentationScores want = counts(10, 3, 2, 4);
  want.paper_precision = want.paper_recall = 1;
  const double c = 1 - 0.4 * std::log(2.0) / H({0.4, 0.2, 0.2, 0.2});
  want.v = vm(1, c);
  want.weighted_overlap = 4.0 / 6;
  want.object_precision = want.object_recall = want.object_f = 4.0 / 6;
  want.detected_075 = 0.5;
  want.over_segmented = 1;
  expect_scores(score(truth, pred), want);
}

TEST(Metrics, TwoObjectsMerged) {
  // truth: background 1 (4), objects 2 and 3 (3 each); segment 6 = objects 2 and 3.
  // Paper: 5 -> 1; 6 has 3 on 2 and 3 on 3, tie -> smaller truth label 2. Region 1: P = R = 1;
  //   region 2: hit 3, claimed 6 -> P = 0.5, R = 1; region 3: 0, 0. P = 1.5/3, R = 2/3.
  // V: H(C|K) = 0.6 ln 2 (cluster 6 split 3/3), H(C) = H(.4, .3, .3) -> h = 1 - 0.6 ln 2 / H(C);
  //   every class in one cluster -> completeness 1.
  // Weighted overlap: IoU(2, 6) = IoU(3, 6) = 3/6 -> 0.5.
  // Object: kept 6 only (5 is all background), |S| = 6. F(2,6) = F(3,6) = 6/9; one pair,
  //   |S∩G| = 3: P = 3/6, R = 3/6, F = 0.5; 2/3 < 0.75 -> detected 0.
  // Over: 0. Under: both objects' largest segment is 6, with 50% on the other object -> 2.
  SegmentationScores want = counts(10, 3, 2, 2);
  set_paper_scores(want, 0.5, 2.0 / 3);
  const double h = 1 - 0.6 * std::log(2.0) / H({0.4, 0.3, 0.3});
  want.v = vm(h, 1);
  want.weighted_overlap = 0.5;
  want.object_precision = want.object_recall = want.object_f = 0.5;
  want.under_segmented = 2;
  expect_scores(score(kThree, {5, 5, 5, 5, 6, 6, 6, 6, 6, 6}), want);
}

namespace {

// Background 1 (6 points), object 2 (4); segment 6 = object 2 and a 2-point background patch.
const Labels kPatchTruth = {1, 1, 1, 1, 1, 1, 2, 2, 2, 2};
const Labels kPatchPred = {5, 5, 5, 5, 6, 6, 6, 6, 6, 6};

// Paper: 5 -> 1 (pure, 4 of 6 background points): P = 1, R = 4/6; 6 -> 2 (4 vs 2): P = 4/6,
//   R = 1. Macro: P = R = (1 + 2/3) / 2 = 5/6.
// V: H(C|K) = 0.6 H(1/3, 2/3) (cluster 6: 2 + 4), H(K|C) = 0.6 H(2/3, 1/3) (class 1: 4 + 2),
//   H(C) = H(K) = H(.6, .4) -> h = c = v = 1 - 0.6 H(1/3, 2/3) / H(.6, .4).
// Weighted overlap: IoU(2, 6) = 4/6.
// Object: 6 has 2/6 on the background: kept; 5 left out. F(2,6) = 8/10. P = 4/6, R = 4/4,
//   F = 2 (2/3) / (5/3) = 0.8 >= 0.75 -> detected 1.
// Over: 0. Under: the largest segment of 2 is 6, 2/6 >= 10% on the background -> 1.
SegmentationScores patch_scores() {
  SegmentationScores want = counts(10, 2, 1, 2);
  want.paper_precision = want.paper_recall = 5.0 / 6;
  const double x = 1 - 0.6 * H({1.0 / 3, 2.0 / 3}) / H({0.6, 0.4});
  want.v = {x, x, x};
  want.weighted_overlap = 4.0 / 6;
  set_object_scores(want, 4.0 / 6, 1, 0.8, 1);
  want.under_segmented = 1;
  return want;
}

}  // namespace

TEST(Metrics, ObjectMergedWithBackgroundPatch) {
  expect_scores(score(kPatchTruth, kPatchPred), patch_scores());
}

TEST(Metrics, MostlyBackgroundSegmentLeftOutOfObjectScores) {
  // truth: background 1 (6), object 2 (4). Segment 6 = 2 background + 1 object point (majority
  // background), segment 7 = 3 object points.
  // Paper: 5 -> 1, 6 -> 1 (2 vs 1), 7 -> 2. Region 1: hit 4 + 2, claimed 4 + 3 -> P = 6/7,
  //   R = 6/6; region 2: P = 3/3, R = 3/4. P = (6/7 + 1) / 2 = 13/14, R = (1 + 3/4) / 2 = 7/8.
  // V: H(C|K) = 0.3 H(2/3, 1/3) (cluster 6), H(C) = H(.6, .4) -> h = 1 - 0.3 H(2/3,1/3) / H(C).
  //   H(K|C) = 0.6 H(4/6, 2/6) + 0.4 H(1/4, 3/4), H(K) = H(.4, .3, .3) -> c = 1 - H(K|C) / H(K).
  // Weighted overlap: IoU(2, 6) = 1/6, IoU(2, 7) = 3/4 -> 0.75.
  // Object: 6 is left out (2 of its 3 points on the background), so only 7 (3 points) counts:
  //   F(2,7) = 6/7. P = 3/3, R = 3/4, F = 2 * 0.75 / 1.75 = 6/7 >= 0.75 -> detected 1.
  //   (Were 6 kept, P would be 3/6.)
  // Over: 6 holds 1/4 >= 10% and 7 holds 3/4 of object 2 -> 1 (background segments count).
  // Under: the largest segment of 2 is 7, pure -> 0.
  const Labels pred = {5, 5, 5, 5, 6, 6, 6, 7, 7, 7};
  SegmentationScores want = counts(10, 2, 1, 3);
  set_paper_scores(want, 13.0 / 14, 7.0 / 8);
  const double h = 1 - 0.3 * H({2.0 / 3, 1.0 / 3}) / H({0.6, 0.4});
  const double c = 1 - (0.6 * H({4.0 / 6, 2.0 / 6}) + 0.4 * H({0.25, 0.75})) / H({0.4, 0.3, 0.3});
  want.v = vm(h, c);
  want.weighted_overlap = 0.75;
  set_object_scores(want, 1, 0.75, 6.0 / 7, 1);
  want.over_segmented = 1;
  expect_scores(score(kPatchTruth, pred), want);
}

TEST(Metrics, PredictedZeroIsUnassigned) {
  // truth: background 1 (4), object 2 (4), object 3 (2). One background and one object-2 point
  // and all of object 3 are predicted 0.
  // Segments: 5, 6 (0 is no segment) -> 2.
  // Paper: 0 maps nowhere; 5 -> 1: P = 3/3, R = 3/4; 6 -> 2: P = 3/3, R = 3/4; region 3: 0, 0.
  //   P = 2/3, R = 1.5/3.
  // V (0 is one more cluster): clusters 5 (3), 6 (3), 0 (4: one each of 1, 2, two of 3).
  //   H(C|K) = 0.4 H(.25, .25, .5), H(C) = H(.4, .4, .2) -> h = 1 - H(C|K) / H(C).
  //   H(K|C) = 0.4 H(.75, .25) * 2 (classes 1, 2; class 3 all in 0), H(K) = H(.3, .3, .4).
  // Weighted overlap: IoU(2, 6) = 3/4; object 3 meets no segment: 0 -> (4 * 0.75 + 0) / 6 = 0.5.
  // Object: 5 is all background, left out; kept 6 (3 points). F(2,6) = 6/7. P = 3/3,
  //   R = 3/(4 + 2) = 0.5, F = 2/3. Detected: object 2 (6/7), not 3 -> 0.5.
  // Over: 0 (object 2: only 6; 0 is no segment). Under: object 2's largest is 6, pure; object 3
  //   has no segment -> 0.
  // Lost: object 2's majority segment 6 is pure object -> not lost; object 3 is all predicted 0:
  //   no majority segment -> unassigned 1, lost 0.
  const Labels truth = {1, 1, 1, 1, 2, 2, 2, 2, 3, 3};
  const Labels pred = {5, 5, 5, 0, 6, 6, 6, 0, 0, 0};
  SegmentationScores want = counts(10, 3, 2, 2);
  set_paper_scores(want, 2.0 / 3, 0.5);
  const double h = 1 - 0.4 * H({0.25, 0.25, 0.5}) / H({0.4, 0.4, 0.2});
  const double c = 1 - 0.8 * H({0.75, 0.25}) / H({0.3, 0.3, 0.4});
  want.v = vm(h, c);
  want.weighted_overlap = 0.5;
  set_object_scores(want, 1, 0.5, 2.0 / 3, 0.5);
  want.unassigned_objects = 1;
  expect_scores(score(truth, pred), want);
}

TEST(Metrics, TruthZeroPointsIgnored) {
  // ObjectMergedWithBackgroundPatch with truth-0 points slipped in: some predicted as its
  // segments, some 0, and labels 9 and 77 that occur only there (so they are no segments).
  const Labels truth = {0, 1, 1, 1, 0, 1, 1, 1, 2, 2, 0, 2, 2, 0};
  const Labels pred = {9, 5, 5, 5, 6, 5, 6, 6, 6, 6, 0, 6, 6, 77};
  expect_scores(score(truth, pred), patch_scores());
}

TEST(Metrics, LargeNonContiguousLabelsAndTieBreaks) {
  // truth: background X = 4294967295 (3), object A = 4000000000 (2), object B = 70000 (4).
  // pred: X on the background; M = 2147483648 on A's 2 and 2 of B's; 99 on the other 2 of B.
  // Ids above 2^31 catch signed comparisons in the tie-breaks below.
  // Paper: X -> X; M has 2 on A and 2 on B, tie -> smaller truth label B (70000); 99 -> B.
  //   Region X: P = R = 1; A: no label, 0, 0; B: hit 2 + 2, claimed 4 + 2 -> P = 2/3, R = 1.
  //   P = (1 + 0 + 2/3) / 3 = 5/9, R = 2/3. (A tie to A would give P = R = 2.5/3.)
  // V: H(C|K) = H(K|C) = (4/9) ln 2 (cluster M split A/B; class B split M/99),
  //   H(C) = H(K) = H(3/9, 2/9, 4/9) -> h = c = v = 1 - (4/9) ln 2 / H(C).
  // Weighted overlap: A: IoU(A, M) = 2/4; B: IoU(B, M) = 2/6, IoU(B, 99) = 2/4 ->
  //   (2 * 0.5 + 4 * 0.5) / 6 = 0.5.
  // Object: X left out; kept M (4), 99 (2). F(A,M) = 4/6, F(B,M) = 4/8, F(B,99) = 4/6,
  //   F(A,99) = 0. Best: A-M + B-99 (4/3 > 1/2): |S∩G| = 4. P = 4/6, R = 4/6, F = 2/3,
  //   detected 0 (2/3 < 0.75).
  // Over: B has M and 99 at 50% each -> 1. Under: A's largest is M, 2/4 on B -> under; B's
  //   largest is a tie M/99 -> smaller label 99, pure -> not. 1.
  const std::uint32_t x = kMax, a = 4000000000u, b = 70000u, m = 2147483648u;
  const Labels truth = {x, x, x, a, a, b, b, b, b};
  const Labels pred = {x, x, x, m, m, m, m, 99, 99};
  SegmentationScores want = counts(9, 3, 2, 3);
  set_paper_scores(want, 5.0 / 9, 2.0 / 3);
  const double v = 1 - 4.0 / 9 * std::log(2.0) / H({3.0 / 9, 2.0 / 9, 4.0 / 9});
  want.v = {v, v, v};
  want.weighted_overlap = 0.5;
  want.object_precision = want.object_recall = want.object_f = 2.0 / 3;
  want.over_segmented = 1;
  want.under_segmented = 1;
  expect_scores(score(truth, pred, {x}), want);
}

TEST(Metrics, HungarianMatchingBeatsGreedy) {
  // truth: object 2 (10 points), object 3 (4), no background. Segment 5 = 6 of object 2 + all of
  // object 3; segment 6 = the other 4 of object 2.
  // F(2,5) = 12/20 = 0.6, F(2,6) = 8/14, F(3,5) = 8/14, F(3,6) = 0.
  // Greedy (best pair first) takes 2-5 (0.6), leaving 3-6 (0): |S∩G| = 6, P = R = F = 6/14.
  // Hungarian takes 2-6 + 3-5 (16/14 > 0.6): |S∩G| = 4 + 4 = 8, P = 8/14, R = 8/14, F = 4/7;
  //   detected 0 (8/14 < 0.75). Both segments are kept (no background).
  // Paper: 5 -> 2 (6 vs 4), 6 -> 2. Region 2: hit 6 + 4, claimed 10 + 4 -> P = 5/7, R = 1;
  //   region 3: 0, 0. P = 5/14, R = 1/2.
  // V: H(C|K) = H(K|C) = (10/14) H(.6, .4), H(C) = H(K) = H(10/14, 4/14) -> h = c = v.
  // Weighted overlap: IoU(2, 5) = 6/14, IoU(2, 6) = 4/10 -> 3/7; IoU(3, 5) = 4/10 ->
  //   (10 * 3/7 + 4 * 0.4) / 14 = 103/245.
  // Over: object 2 has 5 (60%) and 6 (40%) -> 1. Under: 2's largest is 5, 4/10 on 3 -> under;
  //   3's largest is 5, 6/10 on 2 -> under. 2.
  Labels truth(10, 2), pred = {5, 5, 5, 5, 5, 5, 6, 6, 6, 6};
  truth.insert(truth.end(), 4, 3);
  pred.insert(pred.end(), 4, 5);
  SegmentationScores want = counts(14, 2, 2, 2);
  set_paper_scores(want, 5.0 / 14, 0.5);
  const double v = 1 - 10.0 / 14 * H({0.6, 0.4}) / H({10.0 / 14, 4.0 / 14});
  want.v = {v, v, v};
  want.weighted_overlap = 103.0 / 245;
  want.object_precision = want.object_recall = want.object_f = 4.0 / 7;
  want.over_segmented = 1;
  want.under_segmented = 2;
  expect_scores(score(truth, pred), want);
}

TEST(Metrics, ThresholdsAreInclusive) {
  {
    SCOPED_TRACE("F exactly 0.75");
    // Objects 2 and 3 (4 points each); segment 5 = three of 2 + one of 3, 6 = the reverse.
    // Paper: 5 -> 2, 6 -> 3, each P = 3/4, R = 3/4 -> 0.75, 0.75.
    // V: H(C|K) = H(.75, .25) = H(K|C), H(C) = H(K) = ln 2 -> h = c = v.
    // Weighted overlap: IoU(2, 5) = IoU(3, 6) = 3/5 -> 0.6.
    // Object: F(2,5) = F(3,6) = 6/8 = 0.75 exactly, F(2,6) = F(3,5) = 0.25 -> 2-5, 3-6,
    //   |S∩G| = 6: P = 6/8, R = 6/8, F = 0.75; both at F = 0.75 count as detected -> 1.
    // Over: each object has 75% + 25% -> 2. Under: each largest segment has 1/4 on the other
    //   object -> 2.
    SegmentationScores want = counts(8, 2, 2, 2);
    want.paper_precision = want.paper_recall = 0.75;
    const double v = 1 - H({0.75, 0.25}) / std::log(2.0);
    want.v = {v, v, v};
    want.weighted_overlap = 0.6;
    want.object_precision = want.object_recall = want.object_f = 0.75;
    want.detected_075 = 1;
    want.over_segmented = want.under_segmented = 2;
    expect_scores(score({2, 2, 2, 2, 3, 3, 3, 3}, {5, 5, 5, 6, 5, 6, 6, 6}), want);
  }
  {
    SCOPED_TRACE("exactly 10%");
    // Object 2 (10 points): 9 in segment 5, 1 in segment 6; object 3 (9 points): all in 6.
    // Paper: 5 -> 2: P = 9/9, R = 9/10; 6 -> 3 (9 vs 1): P = 9/10, R = 9/9 -> 0.95, 0.95.
    // V: H(C|K) = (10/19) H(.1, .9) (cluster 6) = H(K|C) (class 2), H(C) = H(K) =
    //   H(10/19, 9/19) -> h = c = v.
    // Weighted overlap: IoU(2, 5) = 9/10, IoU(3, 6) = 9/10 -> 0.9.
    // Object: F(2,5) = F(3,6) = 18/19 -> |S∩G| = 18, P = 18/19, R = 18/19, F = 18/19,
    //   detected 1.
    // Over: object 2 has 90% + exactly 10% -> 1. Under: 3's largest segment 6 has exactly 1/10
    //   on object 2 -> 1; 2's largest, 5, is pure.
    Labels truth(10, 2), pred(9, 5);
    truth.insert(truth.end(), 9, 3);
    pred.insert(pred.end(), 10, 6);
    SegmentationScores want = counts(19, 2, 2, 2);
    want.paper_precision = want.paper_recall = 0.95;
    const double v = 1 - 10.0 / 19 * H({0.1, 0.9}) / H({10.0 / 19, 9.0 / 19});
    want.v = {v, v, v};
    want.weighted_overlap = 0.9;
    want.object_precision = want.object_recall = want.object_f = 18.0 / 19;
    want.detected_075 = 1;
    want.over_segmented = want.under_segmented = 1;
    expect_scores(score(truth, pred), want);
  }
  {
    SCOPED_TRACE("exactly half on the background");
    // Segment 5 = 2 background + 2 object points: exactly half, so kept.
    // Paper: 5 ties 1 and 2 -> smaller truth label 1: region 1 P = 2/4, R = 1; region 2: 0, 0 ->
    //   P = 0.25, R = 0.5. V: one cluster -> h = 0, c = 1, V = 0. Weighted overlap: 2/4.
    // Object: F(2,5) = 4/6, P = 2/4, R = 2/2, F = 2/3; 2/3 < 0.75 -> detected 0.
    // Over: 0. Under: 2's largest, 5, has half on the background -> 1.
    SegmentationScores want = counts(4, 2, 1, 1);
    set_paper_scores(want, 0.25, 0.5);
    want.v = {0, 1, 0};
    want.weighted_overlap = 0.5;
    want.object_precision = 0.5;
    want.object_recall = 1;
    want.object_f = 2.0 / 3;
    want.under_segmented = 1;
    expect_scores(score({1, 1, 2, 2}, {5, 5, 5, 5}), want);
  }
}

TEST(Metrics, ObjectSwallowedByTheTableSegment) {
  // truth: background 1 (6 points), object 2 (3), object 3 (3). Segment 5 = the whole table and
  // object 2 (the table segment swallows it); segment 6 = object 3.
  // Paper: 5 -> 1 (6 vs 3): P = 6/9, R = 1; 6 -> 3: P = R = 1; region 2: no label, 0, 0.
  //   P = (2/3 + 1) / 3 = 5/9, R = 2/3.
  // V: H(C|K) = (9/12) H(6/9, 3/9) (cluster 5), H(C) = H(.5, .25, .25) -> h = 1 - H(C|K)/H(C);
  //   every class in one cluster -> H(K|C) = 0, c = 1.
  // Weighted overlap: IoU(2, 5) = 3/9, IoU(3, 6) = 1 -> (3 * 1/3 + 3 * 1) / 6 = 2/3.
  // Object: 5 has 6/9 on the background: left out; kept 6 (3). F(3,6) = 1. P = 3/3, R = 3/6,
  //   F = 2/3; detected: 3 yes, 2 no -> 0.5.
  // Over: 0. Under: 2's largest is 5, 6/9 on the background -> 1; 3's is 6, pure.
  // Lost: object 2's majority segment 5 has more than half of its points on the table -> lost 1,
  //   share 1/2; object 3 not; unassigned 0.
  const Labels truth = {1, 1, 1, 1, 1, 1, 2, 2, 2, 3, 3, 3};
  const Labels pred = {5, 5, 5, 5, 5, 5, 5, 5, 5, 6, 6, 6};
  SegmentationScores want = counts(12, 3, 2, 2);
  set_paper_scores(want, 5.0 / 9, 2.0 / 3);
  const double h = 1 - 0.75 * H({6.0 / 9, 3.0 / 9}) / H({0.5, 0.25, 0.25});
  want.v = vm(h, 1);
  want.weighted_overlap = 2.0 / 3;
  set_object_scores(want, 1, 0.5, 2.0 / 3, 0.5);
  want.under_segmented = 1;
  want.lost_in_background = 1;
  want.lost_in_background_share = 0.5;
  expect_scores(score(truth, pred), want);
}

TEST(Metrics, ObjectLeakingOntoTheTableIsNotLost) {
  // The same truth; segment 5 = 3 table points, segment 6 = the other 3 table points and all of
  // object 2 (exactly half on the background: not a background segment), segment 7 = object 3.
  // Paper: 5 -> 1 (pure): P = 1, R = 3/6; 6 ties 1 and 2 (3 each) -> smaller truth label 1:
  //   region 1 hit 3 + 3, claimed 3 + 6 -> P = 6/9, R = 1; region 2: 0, 0; 7 -> 3: 1, 1.
  //   P = (2/3 + 0 + 1) / 3 = 5/9, R = 2/3.
  // V: H(C|K) = (6/12) ln 2 (cluster 6 split 3/3), H(C) = H(.5, .25, .25) -> h = 1 - H(C|K)/H(C);
  //   H(K|C) = (6/12) ln 2 (class 1 split 3/3), H(K) = H(.25, .5, .25) = H(C) -> c = h.
  // Weighted overlap: IoU(2, 6) = 3/6, IoU(3, 7) = 1 -> (3 * 0.5 + 3) / 6 = 0.75.
  // Object: 5 left out (all table); 6 kept (exactly half); 7 kept: |K| = 9. F(2,6) = 6/9,
  //   F(3,7) = 1: |S∩G| = 3 + 3. P = 6/9, R = 6/6, F = 2 (2/3) / (5/3) = 0.8; detected: 3 yes,
  //   2 no (6/9 < 0.75) -> 0.5.
  // Over: 0. Under: 2's largest is 6, half on the table -> 1.
  // Lost: 6 is not a background segment (exactly half) -> 0; unassigned 0.
  const Labels truth = {1, 1, 1, 1, 1, 1, 2, 2, 2, 3, 3, 3};
  const Labels pred = {5, 5, 5, 6, 6, 6, 6, 6, 6, 7, 7, 7};
  SegmentationScores want = counts(12, 3, 2, 3);
  set_paper_scores(want, 5.0 / 9, 2.0 / 3);
  const double x = 1 - 0.5 * std::log(2.0) / H({0.5, 0.25, 0.25});
  want.v = {x, x, x};
  want.weighted_overlap = 0.75;
  set_object_scores(want, 6.0 / 9, 1, 0.8, 0.5);
  want.under_segmented = 1;
  expect_scores(score(truth, pred), want);
}

TEST(Metrics, UnassignedObjectIsNotLost) {
  // The same truth; the table is segment 5 (pure), object 2 is all predicted 0, object 3 is
  // segment 7 except one point predicted 5 (on the table segment).
  // Paper: 5 -> 1 (6 vs 1): P = 6/7, R = 1; 7 -> 3: P = 1, R = 2/3; region 2: 0, 0.
  //   P = (6/7 + 1) / 3 = 13/21, R = (1 + 2/3) / 3 = 5/9.
  // V: clusters 5 (7: 6 + 1), 0 (3), 7 (2). H(C|K) = (7/12) H(6/7, 1/7), H(C) = H(.5, .25, .25);
  //   H(K|C) = (3/12) H(1/3, 2/3) (class 3), H(K) = H(7/12, 3/12, 2/12).
  // Weighted overlap: object 2 meets no segment: 0; IoU(3, 7) = 2/3 -> (0 + 3 * 2/3) / 6 = 1/3.
  // Object: 5 left out (6/7 table); kept 7 (2). F(3,7) = 4/5. P = 2/2, R = 2/6, F = 0.5;
  //   detected: 3 (0.8) -> 1/2.
  // Over: object 3 has 7 (2/3) and 5 (1/3) -> 1. Under: 3's largest is 7, pure -> 0; object 2
  //   has no segment.
  // Lost: object 2 is unassigned (1), not lost; object 3's majority 7 is an object segment
  //   (its one point on the table segment does not make it lost) -> lost 0.
  const Labels truth = {1, 1, 1, 1, 1, 1, 2, 2, 2, 3, 3, 3};
  const Labels pred = {5, 5, 5, 5, 5, 5, 0, 0, 0, 5, 7, 7};
  SegmentationScores want = counts(12, 3, 2, 2);
  set_paper_scores(want, 13.0 / 21, 5.0 / 9);
  const double h = 1 - 7.0 / 12 * H({6.0 / 7, 1.0 / 7}) / H({0.5, 0.25, 0.25});
  const double c = 1 - 0.25 * H({1.0 / 3, 2.0 / 3}) / H({7.0 / 12, 3.0 / 12, 2.0 / 12});
  want.v = vm(h, c);
  want.weighted_overlap = 1.0 / 3;
  set_object_scores(want, 1, 1.0 / 3, 0.5, 0.5);
  want.over_segmented = 1;
  want.unassigned_objects = 1;
  expect_scores(score(truth, pred), want);
}
