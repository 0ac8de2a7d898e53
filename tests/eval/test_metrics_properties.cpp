// Properties of the segmentation metrics: the matching against a brute-force search, invariance
// under relabelling, the edge cases (sizes, no evaluated point, only background), the mOSD
// schemes and one real mOSD scene.
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

TEST(Metrics, MatchingAgreesWithBruteForce) {
  // Random small scenes; the object recall must be that of a matching with the maximal sum of F
  // found by trying every matching (any of them, should several reach the maximum).
  std::mt19937 rng(12345);
  for (int trial = 0; trial < 400; ++trial) {
    SCOPED_TRACE(trial);
    const int n = 5 + static_cast<int>(rng() % 60);
    const std::uint32_t regions = 1 + rng() % 6, segs = 1 + rng() % 8;
    Labels truth(n), pred(n);
    for (int i = 0; i < n; ++i) {
      truth[i] = rng() % (regions + 1);  // 0 = not evaluated, 1 = background
      // Half the points follow their truth (through a trial-dependent shuffle), so that F values
      // spread out instead of all being alike; the rest is noise. 0 = unassigned.
      pred[i] = rng() % 2 ? (truth[i] * (trial + 3)) % (segs + 1) : rng() % (segs + 1);
    }
    std::map<std::uint32_t, std::size_t> g_size, s_size, s_bg;
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::size_t> inter;
    for (int i = 0; i < n; ++i) {
      if (!truth[i]) continue;
      ++g_size[truth[i]];
      if (!pred[i]) continue;
      ++s_size[pred[i]];
      ++inter[{truth[i], pred[i]}];
      if (truth[i] == 1) ++s_bg[pred[i]];
    }
    std::vector<std::uint32_t> objects, kept;
    std::size_t object_points = 0;
    for (const auto& [g, sz] : g_size)
      if (g != 1) {
        objects.push_back(g);
        object_points += sz;
      }
    for (const auto& [s, sz] : s_size)
      if (2 * s_bg[s] <= sz) kept.push_back(s);
    double best = -1;
    std::set<std::size_t> best_matched;  // sum |S∩G| of the matchings reaching `best`
    std::vector<char> used(kept.size(), 0);
    std::function<void(std::size_t, double, std::size_t)> visit = [&](std::size_t i, double f,
                                                                      std::size_t m) {
      if (i == objects.size()) {
        if (f > best + 1e-12) {
          best = f;
          best_matched.clear();
        }
        if (f > best - 1e-12) best_matched.insert(m);
        return;
      }
      visit(i + 1, f, m);  // object i unmatched
      for (std::size_t j = 0; j < kept.size(); ++j) {
        if (used[j]) continue;
        const auto it = inter.find({objects[i], kept[j]});
        const std::size_t k = it == inter.end() ? 0 : it->second;
        used[j] = 1;
        visit(i + 1, f + 2.0 * k / (g_size[objects[i]] + s_size[kept[j]]), m + k);
        used[j] = 0;
      }
    };
    visit(0, 0, 0);
    const SegmentationScores s = score(truth, pred);
    const double matched = s.object_recall * object_points;
    bool found = false;
    for (const std::size_t m : best_matched) found |= std::abs(matched - m) < 1e-6;
    EXPECT_TRUE(found || (object_points == 0 && s.object_recall == 0))
        << "matched " << matched << ", best sum of F " << best;
    // Lost in the background, counted the slow way: each object's majority segment (ascending
    // ids, so a strict > keeps the smaller id on ties) is mostly background.
    int lost = 0, unassigned = 0;
    for (const std::uint32_t g : objects) {
      std::uint32_t majority = 0;
      std::size_t majority_n = 0;
      for (const auto& [key, k] : inter)
        if (key.first == g && k > majority_n) {
          majority = key.second;
          majority_n = k;
        }
      if (!majority_n)
        ++unassigned;
      else if (2 * s_bg[majority] > s_size[majority])
        ++lost;
    }
    EXPECT_EQ(s.lost_in_background, lost);
    EXPECT_EQ(s.unassigned_objects, unassigned);
  }
}

TEST(Metrics, PermutationInvariance) {
  // Renaming the predicted segments (0 stays "unassigned") or reordering the points changes no
  // score. (This scene has no ties in the matching; with ties the label order breaks them.)
  std::mt19937 rng(7);
  const int n = 200;
  Labels truth(n), pred(n);
  for (int i = 0; i < n; ++i) {
    truth[i] = rng() % 5;
    // Segments follow the truth with some noise, so that the scores are not trivial.
    pred[i] = rng() % 4 == 0 ? rng() % 7 : truth[i] + (i % 3 == 0 ? 3 : 0);
  }
  const SegmentationScores base = score(truth, pred);
  EXPECT_GT(base.object_f, 0.3);
  EXPECT_GT(base.over_segmented + base.under_segmented, 0);
  // Reverses the order of the non-zero ids and spreads them over the whole uint32 range.
  Labels renamed(n);
  for (int i = 0; i < n; ++i) renamed[i] = pred[i] ? kMax - 600000000u * pred[i] : 0;
  expect_scores(score(truth, renamed), base);
  // Points in reverse order.
  const Labels truth_rev(truth.rbegin(), truth.rend()), pred_rev(pred.rbegin(), pred.rend());
  expect_scores(score(truth_rev, pred_rev), base);
}

TEST(Metrics, SizeMismatchThrows) {
  EXPECT_THROW(proxseg::score_segmentation({1, 2}, {1}, {1}), std::invalid_argument);
  EXPECT_THROW(proxseg::score_segmentation({}, {1}, {1}), std::invalid_argument);
  EXPECT_THROW(proxseg::v_measure({1}, {}), std::invalid_argument);
}

TEST(Metrics, NoEvaluatedPointsScoresZero) {
  // Nothing to evaluate: every field 0 (no division by zero, no crash).
  const SegmentationScores zero;
  expect_scores(score({}, {}), zero);
  expect_scores(score({0, 0, 0}, {4, 0, 9}), zero);
  expect_scores(score({0, 0}, {1, 2}, {}), zero);
}

TEST(Metrics, OnlyBackground) {
  // No objects: the object scores are 0, the region scores still work.
  // Paper: 5 -> 1: P = 3/3, R = 3/4. V: one class -> h = 1; H(K|C) = H(K) -> c = 0, V = 0.
  SegmentationScores want = counts(4, 1, 0, 1);
  set_paper_scores(want, 1, 0.75);
  want.v = {1, 0, 0};
  expect_scores(score({1, 1, 1, 1}, {5, 5, 5, 0}), want);
}

TEST(Metrics, MosdSchemes) {
  const Labels raw = {0, 1, 2, 5, 9, 10, 19, 20, 21, 29, 30, 31, 42, 110, kMax};
  // Parts: table parts 1-9 -> 1, everything else unchanged.
  EXPECT_EQ(proxseg::mosd_parts(raw),
            (Labels{0, 1, 1, 1, 1, 10, 19, 20, 21, 29, 30, 31, 42, 110, kMax}));
  // Objects: label / 10 with the table parts -> 1.
  EXPECT_EQ(proxseg::mosd_objects(raw),
            (Labels{0, 1, 1, 1, 1, 1, 1, 2, 2, 2, 3, 3, 4, 11, kMax / 10}));
  EXPECT_TRUE(proxseg::mosd_parts({}).empty());
}

TEST(Metrics, RealMosdScene) {
  const std::string path = PROXSEG_DATA_DIR "/mosd/learn/learn0.pcd";
  // The real data must be there (CI has it): fail loudly rather than skip.
  ASSERT_TRUE(std::filesystem::exists(path)) << "missing real data: " << path;
  const proxseg::Frame f = proxseg::read_pcd(path);
  ASSERT_EQ(f.label.size(), f.size());
  // NaN points are not evaluated: zeroing their truth is the caller's job.
  auto evaluated = [&f](Labels truth) {
    for (std::size_t i = 0; i < f.size(); ++i)
      if (!f.valid(i)) truth[i] = 0;
    return truth;
  };
  const Labels truth = evaluated(proxseg::mosd_objects(f.label));
  std::map<std::uint32_t, std::size_t> size;
  for (const std::uint32_t t : truth)
    if (t) ++size[t];
  // learn0: table 1 and objects 2, 3.
  ASSERT_EQ(size.size(), 3u);
  ASSERT_EQ(size.begin()->first, 1u);
  std::size_t n = 0, objects = 0, squares = 0;
  for (const auto& [t, k] : size) {
    n += k;
    if (t != 1) {
      objects += k;
      squares += k * k;
    }
  }
  const std::size_t table = size[1];

  SegmentationScores perfect = counts(n, 3, 2, 3);
  perfect.paper_precision = perfect.paper_recall = 1;
  perfect.v = {1, 1, 1};
  perfect.weighted_overlap = 1;
  perfect.object_precision = perfect.object_recall = perfect.object_f = perfect.detected_075 = 1;
  expect_scores(score(truth, truth), perfect);
  // Parts against themselves: the same (learn0 has one part per object, 20 and 30).
  const Labels parts = evaluated(proxseg::mosd_parts(f.label));
  expect_scores(score(parts, parts), perfect);

  // One segment over everything, invalid points too (they are not evaluated).
  // Paper: the segment goes to the table (the largest region): P = (table / n) / 3, R = 1 / 3.
  // V: h = 0, c = 1, V = 0. Weighted overlap: IoU(G, S) = |G| / n -> sum |G|^2 / (n sum |G|).
  // Object: the segment is mostly table, so it is left out: no kept segment, P = R = F = 0,
  //   detected 0. Over: 0. Under: each object's largest segment is the one segment, >= 10% of
  //   it on the table -> 2. Lost: that segment is mostly table -> both objects lost, share 1.
  ASSERT_GT(2 * table, n);
  SegmentationScores one = counts(n, 3, 2, 1);
  set_paper_scores(one, static_cast<double>(table) / n / 3, 1.0 / 3);
  one.v = {0, 1, 0};
  one.weighted_overlap = static_cast<double>(squares) / (static_cast<double>(n) * objects);
  one.under_segmented = 2;
  one.lost_in_background = 2;
  one.lost_in_background_share = 1;
  expect_scores(score(truth, Labels(truth.size(), 1)), one);
}
