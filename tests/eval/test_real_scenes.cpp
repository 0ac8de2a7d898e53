// The real YCB-Video scenes as folds (real_eval.hpp, `make bench-real`): a regression guard with
// floors at what the default reaches, the sensor's measured figures, and the scene rules that
// real frames asked for (hidden points left out of the coverage, the score distance at range).
#include <proxseg/eval/real_eval.hpp>
#include <proxseg/eval/sensor_figures.hpp>
#include <proxseg/recognition/recognition.hpp>
#include <proxseg/recognition/registration.hpp>
#include <proxseg/recognition/visibility.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "support/fresh_dir.hpp"

namespace proxseg {
namespace {

const std::string kYcbv = std::string(PROXSEG_DATA_DIR) + "/ycbv";

class RealScenes : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    models_ = read_ycb_models(kYcbv);
    db_ = ycb_database(models_, test::fresh_dir("real_scenes_db"));
  }
  // Every frame of a fold with the default parameters, leave-one-out included.
  static RealCounts run(const std::string& fold) {
    RealCounts counts;
    const std::string dir = kYcbv + "/" + fold;
    for (const std::string& stem : ycb_frame_stems(dir)) {
      const YcbFrame y = read_ycb_frame(dir, stem, models_.classes);
      const RealFrameResult r =
          evaluate_real_frame(y, stem, proxseg_recognizer({}, {}), db_, models_);
      for (const std::string& n : r.notes) std::printf("  %s: %s\n", fold.c_str(), n.c_str());
      counts += r.counts;
    }
    std::printf(
        "%s: named %d/%d, pose %d, other names %d, left out unknown %d/%d, others named "
        "%d/%d\n",
        fold.c_str(), counts.named, counts.objects, counts.pose_ok, counts.other_names,
        counts.loo_missing_unknown, counts.loo_cases, counts.loo_others_named, counts.loo_others);
    return counts;
  }
  static YcbModels models_;
  static Database db_;
};
YcbModels RealScenes::models_;
Database RealScenes::db_;

// Floors at the default's figures of 2026-12-06 (docs/results.md "Real scenes"): the scene
// developed on names all 30; the other 19 of 20 (8 before explain_fitness, 14 before the
// support rule, occlusion and 3 ICP starts), issue 51's 95 %.
TEST_F(RealScenes, FramesFold) {
  const RealCounts c = run("frames");
  EXPECT_EQ(c.objects, 30);
  EXPECT_EQ(c.segmented, 30);
  EXPECT_EQ(c.named, 30);
  EXPECT_EQ(c.pose_ok, 30);
  EXPECT_EQ(c.other_names, 0);
  EXPECT_GE(c.loo_missing_unknown, 29);
  EXPECT_EQ(c.loo_others_named, c.loo_others);
}

TEST_F(RealScenes, Video0001Fold) {
  const RealCounts c = run("video0001");
  EXPECT_EQ(c.objects, 20);
  EXPECT_EQ(c.segmented, 20);
  EXPECT_GE(c.named, 19);
  EXPECT_EQ(c.pose_ok, c.named);
  EXPECT_EQ(c.other_names, 0);
  EXPECT_GE(c.loo_missing_unknown, 19);
  EXPECT_GE(c.loo_others_named, 57);
}

// The sensor as measured (docs/method.md "Real sensors"): points within 5-8 mm per metre of
// range of their model at the true pose (90 %), planar noise under 1.5 mm to 1.2 m, and missing
// returns gathered at object borders.
TEST_F(RealScenes, SensorFigures) {
  for (const std::string fold : {"frames", "video0001"}) {
    SensorFigures s;
    const std::string dir = kYcbv + "/" + fold;
    for (const std::string& stem : ycb_frame_stems(dir))
      s += measure_sensor(read_ycb_frame(dir, stem, models_.classes), models_);
    ASSERT_FALSE(s.residuals.empty());
    for (const auto& r : s.residuals) {
      EXPECT_GT(r.range, 0.4) << fold << " " << r.object;
      EXPECT_GT(r.p90 / r.range, 0.005) << fold << " " << r.object;
      EXPECT_LT(r.p90 / r.range, 0.009) << fold << " " << r.object;
    }
    for (std::size_t b = 0; b < s.patches.size() && b < 12; ++b) {
      if (s.patches[b] < 20) continue;
      EXPECT_LT(s.patch_rms[b], 0.0015) << fold << " bin " << b;
    }
    EXPECT_GT(double(s.border_missing) / s.border, 3.0 * s.inside_missing / s.inside) << fold;
  }
}

// A box whose lower half an occluder hides: with the depth image, its hidden points leave the
// coverage (the visible half is all there), without it they count as missing.
TEST(SceneCoverage, HiddenPointsLeaveTheCoverage) {
  // The box's front face: 10 x 10 cm at 1 m, 5 mm grid; the candidate is its upper half.
  std::vector<Eigen::Vector3d> face, upper;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      const Eigen::Vector3d p(-0.05 + 0.005 * i, -0.05 + 0.005 * j, 1.0);
      face.push_back(p);
      if (p.y() < 0) upper.push_back(p);
    }
  const DescriptorParams d;
  const Cloud view = describe(face, Eigen::Vector3d::Zero(), d);
  const Cloud candidate = describe(upper, Eigen::Vector3d::Zero(), d);
  // The depth image: an occluder at 0.8 m in front of the lower half (y > 0), nothing else.
  DepthImage scene;
  scene.width = scene.height = 200;
  scene.fx = scene.fy = 500;
  scene.cx = scene.cy = 100;
  scene.z.assign(200 * 200, std::nanf(""));
  for (int v = 100; v < 200; ++v)
    for (int u = 0; u < 200; ++u) scene.z[v * 200 + u] = 0.8f;
  const Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  const CoverageCounts plain = coverage_counts(candidate, view, pose, 0.005);
  const CoverageCounts hidden = coverage_counts(candidate, view, pose, 0.005, scene, 0.01);
  EXPECT_GT(plain.outside, plain.inside / 2);  // the lower half: outside, not explained
  EXPECT_EQ(hidden.outside, 0);
  EXPECT_EQ(hidden.hidden, plain.outside);
  EXPECT_EQ(hidden.explained, plain.explained);
  EXPECT_GT(double(hidden.explained) / (hidden.inside + hidden.outside), 0.85);
  EXPECT_LT(double(plain.explained) / (plain.inside + plain.outside), 0.6);
  // An occluder nearer by less than the hidden depth (0.2 m here) hides nothing: the model
  // would be inside it (RecognitionParams::hidden_depth).
  EXPECT_EQ(coverage_counts(candidate, view, pose, 0.005, scene, 0.25).hidden, 0);
  // Without a return there (NaN) the points are not hidden: a missing return is no occluder.
  std::fill(scene.z.begin(), scene.z.end(), std::nanf(""));
  EXPECT_EQ(coverage_counts(candidate, view, pose, 0.005, scene, 0.01).hidden, 0);
}

// The score distance at a candidate's range: max(score_distance, slope x range).
TEST(SceneCoverage, ScoreDistanceGrowsWithRange) {
  RecognitionParams p;
  p.registration.score_distance_slope = 0.0066;
  Cloud near, far;
  near.centroid = Eigen::Vector3d(0, 0, 0.5);
  far.centroid = Eigen::Vector3d(0, 0.2, 1.5);
  EXPECT_DOUBLE_EQ(at_range(p, near).registration.score_distance, 0.005);
  EXPECT_NEAR(at_range(p, far).registration.score_distance, 0.0066 * far.centroid.norm(), 1e-12);
  p.registration.score_distance_slope = 0;
  EXPECT_DOUBLE_EQ(at_range(p, far).registration.score_distance, 0.005);
}

}  // namespace
}  // namespace proxseg
