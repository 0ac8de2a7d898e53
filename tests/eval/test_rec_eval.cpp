// Recognition evaluation [paper 4]: the test set, the occluded test set and the measures.
#include <proxseg/core/errors.hpp>
#include <proxseg/eval/rec_eval.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace {

const std::string kModels = std::string(PROXSEG_DATA_DIR) + "/lmo/models";

const std::vector<proxseg::TestObject>& objects() {
  static const std::vector<proxseg::TestObject> o = proxseg::read_test_objects(kModels, 0.001);
  return o;
}

std::vector<Eigen::Vector3d> database_directions() {
  std::vector<Eigen::Vector3d> d;
  for (int n : {8, 4, 2})
    for (const auto& v : proxseg::view_sphere(n)) d.push_back(v);
  return d;
}

}  // namespace

TEST(RecEval, ReadsTheLinemodMeshesWithTheirNames) {
  ASSERT_EQ(objects().size(), 8u);
  EXPECT_EQ(objects()[0].name, "ape");
  EXPECT_EQ(objects()[7].name, "holepuncher");
  for (const auto& o : objects()) {
    EXPECT_FALSE(o.symmetries.empty()) << o.name;  // the identity at least
    // BOP models are in mm: every LINEMOD object is 5-30 cm across once scaled.
    Eigen::Vector3d lo = o.mesh.vertices[0].cast<double>(), hi = lo;
    for (const auto& v : o.mesh.vertices)
      lo = lo.cwiseMin(v.cast<double>()), hi = hi.cwiseMax(v.cast<double>());
    EXPECT_GT((hi - lo).norm(), 0.05) << o.name;
    EXPECT_LT((hi - lo).norm(), 0.40) << o.name;
  }
  EXPECT_THROW(proxseg::read_test_objects("/nonexistent", 0.001), proxseg::InputError);
}

TEST(RecEval, TestViewsAreSeededFarFromTheDatabaseViewpointsAndKinectLike) {
  proxseg::TestSetParams p;
  p.tests = 24;
  p.seed = 7;
  const auto dirs = database_directions();
  const auto a = proxseg::make_test_views(objects(), p, dirs);
  const auto b = proxseg::make_test_views(objects(), p, dirs);
  ASSERT_EQ(a.size(), 24u);
  std::set<double> distances;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const proxseg::TestView& t = a[k];
    EXPECT_EQ(t.object, static_cast<int>(k % 8));
    EXPECT_GE(t.distance, p.min_distance);
    EXPECT_LE(t.distance, p.max_distance);
    EXPECT_GE(t.nearest_view_deg, p.min_angle_to_view_deg);
    EXPECT_GT(t.points.size(), 100u) << k;
    // The LINEMOD meshes have vertex colours: one rendered colour per point.
    EXPECT_EQ(t.colours.size(), t.points.size()) << k;
    distances.insert(t.distance);
    // Same seed, same test, point for point.
    ASSERT_EQ(t.points.size(), b[k].points.size());
    EXPECT_EQ(t.points.front(), b[k].points.front());
    EXPECT_TRUE(t.truth.isApprox(b[k].truth));
    // The direction the camera sees the object from is at least 10 degrees from every
    // database viewpoint: check it from the pose, not from the recorded angle.
    const Eigen::Matrix4d model_from_camera = t.truth.inverse();
    const Eigen::Vector3d eye = model_from_camera.block<3, 1>(0, 3);
    const Eigen::Vector3d dir = (eye - objects()[t.object].centre).normalized();
    for (const auto& d : dirs)
      EXPECT_LT(dir.dot(d), std::cos(p.min_angle_to_view_deg * M_PI / 180) + 1e-9);
    // Depths lie on the disparity steps: 1/z is a whole number of steps.
    for (std::size_t i = 0; i < t.points.size(); i += 97) {
      const double steps = 1.0 / (t.points[i].z() * p.disparity_step);
      EXPECT_NEAR(steps, std::round(steps), 1e-4) << t.points[i].z();
    }
  }
  EXPECT_EQ(distances.size(), a.size());  // the distances are drawn, not fixed
  p.seed = 8;
  const auto c = proxseg::make_test_views(objects(), p, dirs);
  EXPECT_NE(c[0].distance, a[0].distance);
}

TEST(RecEval, OccludedTestsFillThePaperBinsEvenly) {
  proxseg::TestSetParams p;
  p.tests = 36;
  const auto clean = proxseg::make_test_views(objects(), p, database_directions());
  const auto bins = proxseg::paper_occlusion_bins();
  ASSERT_EQ(bins.size(), 6u);
  EXPECT_DOUBLE_EQ(bins.front().lo, 0.1);
  EXPECT_DOUBLE_EQ(bins.back().hi, 0.7);
  const auto occluded = proxseg::occluded_test_views(clean, 36, bins, 1);
  ASSERT_EQ(occluded.size(), 36u);
  std::vector<int> per_bin(6, 0);
  for (const auto& t : occluded) {
    ASSERT_GE(t.bin, 0);
    ++per_bin[t.bin];
    EXPECT_GE(t.occlusion, bins[t.bin].lo);
    EXPECT_LT(t.occlusion, bins[t.bin].hi);
    const auto& source = clean[t.index];
    EXPECT_NEAR(1.0 - double(t.points.size()) / source.points.size(), t.occlusion, 1e-12);
    // The kept points keep their colours, in order: the first kept point is some source point.
    ASSERT_EQ(t.colours.size(), t.points.size());
    for (std::size_t p = 0; p < source.points.size(); ++p)
      if (source.points[p] == t.points.front()) {
        EXPECT_EQ(source.colours[p], t.colours.front());
        break;
      }
    EXPECT_EQ(t.object, source.object);
  }
  for (int n : per_bin) EXPECT_EQ(n, 6);
  const auto again = proxseg::occluded_test_views(clean, 36, bins, 1);
  for (std::size_t i = 0; i < occluded.size(); ++i)
    EXPECT_EQ(again[i].points.size(), occluded[i].points.size());
}

TEST(RecEval, RatesAndCurvesCountRightWrongAndRejected) {
  // Four tests of objects 0, 1, 0, 1: right at 0.9, wrong at 0.7, right at 0.4, no answer.
  std::vector<proxseg::TestView> tests(4);
  for (int i = 0; i < 4; ++i) tests[i].object = i % 2, tests[i].index = i;
  std::vector<proxseg::Answer> answers(4);
  answers[0] = {objects()[0].name, 0.9, tests[0].truth, 10};
  answers[1] = {objects()[0].name, 0.7, tests[1].truth, 20};
  answers[2] = {objects()[0].name, 0.4, tests[2].truth, 30};
  answers[3] = {"", 0, tests[3].truth, 40};
  const proxseg::Rates r = proxseg::rates(tests, answers, objects(), 0.5);
  EXPECT_EQ(r.tests, 4);
  EXPECT_EQ(r.right, 1);
  EXPECT_EQ(r.wrong, 1);
  EXPECT_EQ(r.unknown, 2);
  EXPECT_EQ(r.pose_ok, 1);  // at the true pose
  EXPECT_DOUBLE_EQ(r.tp_rate(), 0.25);
  EXPECT_DOUBLE_EQ(r.fp_rate(), 0.25);
  EXPECT_DOUBLE_EQ(r.mean_ms, 25);
  const proxseg::Rates evens = proxseg::rates(
      tests, answers, objects(), 0.0, [](const proxseg::TestView& t) { return t.object == 0; });
  EXPECT_EQ(evens.tests, 2);
  EXPECT_EQ(evens.right, 2);

  const auto curve = proxseg::score_curve(tests, answers, objects());
  ASSERT_EQ(curve.size(), 4u);  // above every score, then 0.9, 0.7, 0.4
  EXPECT_EQ(curve[0].tp_rate, 0);
  EXPECT_EQ(curve[0].fp_rate, 0);
  EXPECT_DOUBLE_EQ(curve[1].min_score, 0.9);
  EXPECT_DOUBLE_EQ(curve[1].tp_rate, 0.25);
  EXPECT_DOUBLE_EQ(curve[1].precision, 1.0);
  EXPECT_DOUBLE_EQ(curve[2].fp_rate, 0.25);
  EXPECT_DOUBLE_EQ(curve[2].precision, 0.5);
  EXPECT_DOUBLE_EQ(curve[3].tp_rate, 0.5);  // the test without an answer is never counted
  EXPECT_NEAR(curve[3].precision, 2.0 / 3, 1e-12);
}
