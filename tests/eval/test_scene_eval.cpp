// The scene recognition scoring (scene_eval.hpp) on small hand-built cases: the maximum-weight
// matching, the IoU floor, what counts as TP / FN / FP and as an unknown object named, ADD-S,
// and the re-thresholded curve.
#include <gtest/gtest.h>
#include <proxseg/eval/scene_eval.hpp>

#include <Eigen/Geometry>
#include <numeric>

using namespace proxseg;

namespace {

std::vector<int> range(int first, int last) {  // first, ..., last - 1
  std::vector<int> v(last - first);
  std::iota(v.begin(), v.end(), first);
  return v;
}

// The 8 corners and 6 face centres of a 10 cm cube centred on the origin: diameter 0.1 sqrt(3).
std::vector<Eigen::Vector3d> cube_points() {
  std::vector<Eigen::Vector3d> pts;
  for (int c = 0; c < 8; ++c)
    pts.emplace_back(c & 1 ? 0.05 : -0.05, c & 2 ? 0.05 : -0.05, c & 4 ? 0.05 : -0.05);
  for (int a = 0; a < 3; ++a)
    for (double s : {-0.05, 0.05}) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      p[a] = s;
      pts.push_back(p);
    }
  return pts;
}

// Two known entries (duck, ape) and one unknown (glue), all with the cube as their model.
SceneCatalogue small_catalogue() {
  SceneCatalogue c;
  for (const char* name : {"duck", "ape", "glue"}) {
    CatalogueObject e;
    e.name = name;
    c.entries.push_back(e);
    c.model_points.push_back(cube_points());
    c.diameters.push_back(0.1 * std::sqrt(3.0));
  }
  c.known = {1, 1, 0};
  return c;
}

TruthObject truth(const std::string& name, int catalogue, bool known, std::vector<int> points,
                  const Eigen::Matrix4d& pose = Eigen::Matrix4d::Identity()) {
  TruthObject t;
  t.name = name;
  t.catalogue = catalogue;
  t.known = known;
  t.points = std::move(points);
  t.camera_from_model = pose;
  return t;
}

Prediction prediction(const std::string& best, double score, std::vector<int> points,
                      double min_score = 0.5,
                      const Eigen::Matrix4d& pose = Eigen::Matrix4d::Identity()) {
  Prediction p;
  p.best = best;
  p.name = score >= min_score ? best : "unknown";
  p.score = score;
  p.points = std::move(points);
  p.pose = pose;
  return p;
}

Eigen::Matrix4d at(double x, double y, double z) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<3, 1>(0, 3) = Eigen::Vector3d(x, y, z);
  return m;
}

// A scene of four truths and four predictions (points 0-99 ... 400-499):
//   duck (known)  <- "duck" 0.9, right pose            TP, pose ok
//   glue (unknown) <- "duck" 0.6                       FP, unknown named
//   box (random, unknown) <- best "ape" at 0.3: unknown  nothing
//   ape (known)   <- nothing                           FN
//   (nothing)     <- "ape" 0.7 on points 400-499       FP
struct Case {
  SceneCatalogue catalogue = small_catalogue();
  std::vector<TruthObject> truths;
  std::vector<Prediction> predictions;
  Case() {
    const Eigen::Matrix4d pose = at(0.1, -0.05, 0.9);
    truths = {truth("duck", 0, true, range(0, 100), pose), truth("glue", 2, false, range(100, 200)),
              truth("box", -1, false, range(200, 300)), truth("ape", 1, true, range(300, 400))};
    predictions = {
        prediction("duck", 0.9, range(0, 100), 0.5, pose), prediction("duck", 0.6, range(100, 200)),
        prediction("ape", 0.3, range(200, 300)), prediction("ape", 0.7, range(400, 500))};
  }
};

}  // namespace

TEST(SceneEval, HungarianFindsTheGlobalBestWhereGreedyWouldNot) {
  // Greedy takes 0.9 first and is left with 0.1 (total 1.0); the best total is 0.8 + 0.85.
  Eigen::MatrixXd w(2, 2);
  w << 0.9, 0.8, 0.85, 0.1;
  EXPECT_EQ(max_weight_assignment(w), (std::vector<int>{1, 0}));
  // More columns than rows, more rows than columns, and weight 0 = no pair.
  Eigen::MatrixXd wide(2, 3);
  wide << 0.6, 0.7, 0.0, 0.0, 0.65, 0.0;
  EXPECT_EQ(max_weight_assignment(wide), (std::vector<int>{0, 1}));
  EXPECT_EQ(max_weight_assignment(Eigen::MatrixXd(wide.transpose())), (std::vector<int>{0, 1, -1}));
  Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(2, 2);
  zero(1, 0) = 0.5;
  EXPECT_EQ(max_weight_assignment(zero), (std::vector<int>{-1, 0}));
  EXPECT_TRUE(max_weight_assignment(Eigen::MatrixXd(0, 3)).empty());
  EXPECT_EQ(max_weight_assignment(Eigen::MatrixXd(2, 0)), (std::vector<int>{-1, -1}));
}

TEST(SceneEval, MatchingNeedsAnIouOfAHalf) {
  EXPECT_DOUBLE_EQ(point_iou(range(0, 100), range(0, 60)), 0.6);
  EXPECT_DOUBLE_EQ(point_iou(range(0, 10), range(20, 30)), 0);
  EXPECT_DOUBLE_EQ(point_iou({}, {}), 0);
  const std::vector<TruthObject> t = {truth("a", -1, false, range(0, 100)),
                                      truth("b", -1, false, range(100, 200))};
  // 0.6 with a; 41 / 100 = 0.41 with b; a prediction over both halves is under 0.5 with each.
  const std::vector<Prediction> p = {prediction("x", 1, range(0, 60)),
                                     prediction("x", 1, range(100, 141)),
                                     prediction("x", 1, range(50, 150))};
  std::vector<double> iou;
  EXPECT_EQ(match_objects(t, p, 0.5, &iou), (std::vector<int>{0, -1}));
  EXPECT_DOUBLE_EQ(iou[0], 0.6);
  EXPECT_DOUBLE_EQ(iou[1], 0);
  // Overlapping predictions (floor 0.3 here): greedy would give a the larger 0.5 and leave b
  // without; the matching maximises the total IoU (0.45 + 0.33).
  const std::vector<Prediction> q = {prediction("x", 1, range(20, 160)),  // a 80/160, b 60/180
                                     prediction("x", 1, range(0, 45))};   // a 45/100
  EXPECT_EQ(match_objects(t, q, 0.3, nullptr), (std::vector<int>{1, 0}));
}

TEST(SceneEval, NamedUnknownsAndUnmatchedNamesAreFalsePositives) {
  const Case c;
  const SceneEvaluation e = evaluate_scene(7, c.truths, c.predictions, c.catalogue);
  EXPECT_EQ(e.match, (std::vector<int>{0, 1, 2, -1}));
  const SceneCounts& n = e.counts;
  EXPECT_EQ(n.truths, 4);
  EXPECT_EQ(n.known, 2);
  EXPECT_EQ(n.unknown, 2);
  EXPECT_EQ(n.predictions, 4);
  EXPECT_EQ(n.detected, 3);
  EXPECT_EQ(n.tp, 1);
  EXPECT_EQ(n.fn, 1);
  EXPECT_EQ(n.fp, 2);  // the named glue and the "ape" on nothing
  EXPECT_EQ(n.unknown_named, 1);
  EXPECT_EQ(n.pose_ok, 1);
  EXPECT_DOUBLE_EQ(n.precision(), 1.0 / 3);
  EXPECT_DOUBLE_EQ(n.recall(), 0.5);
  EXPECT_DOUBLE_EQ(n.f1(), 0.4);
  EXPECT_DOUBLE_EQ(n.unknown_named_share(), 0.5);
  EXPECT_DOUBLE_EQ(n.detection(), 0.75);
  ASSERT_EQ(e.rows.size(), 4u);
  EXPECT_EQ(e.rows[1].scene, 7u);
  EXPECT_EQ(e.rows[1].truth, 1);
  EXPECT_EQ(e.rows[1].truth_name, "glue");
  EXPECT_FALSE(e.rows[1].truth_known);
  EXPECT_EQ(e.rows[3].truth, -1);
  EXPECT_EQ(e.rows[3].truth_name, "");
  EXPECT_DOUBLE_EQ(e.rows[0].iou, 1.0);
  // A wrong name on a known object: FN and FP.
  Case wrong;
  wrong.predictions[0].name = wrong.predictions[0].best = "ape";
  const SceneCounts w = evaluate_scene(7, wrong.truths, wrong.predictions, wrong.catalogue).counts;
  EXPECT_EQ(w.tp, 0);
  EXPECT_EQ(w.fn, 2);
  EXPECT_EQ(w.fp, 3);
  SceneCounts sum = n;
  sum += w;
  EXPECT_EQ(sum.scenes, 2);
  EXPECT_EQ(sum.fp, 5);
}

TEST(SceneEval, AddSIsZeroAtTheTruthAndFailsFiveCentimetresOff) {
  const std::vector<Eigen::Vector3d> cube = cube_points();
  const Eigen::Matrix4d truth_pose = at(0.1, -0.05, 0.9);
  EXPECT_NEAR(add_s(cube, truth_pose, truth_pose), 0, 1e-12);
  // A quarter turn about z maps the cube onto itself: ADD-S does not tell them apart.
  Eigen::Matrix4d turned = truth_pose;
  turned.block<3, 3>(0, 0) =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR(add_s(cube, turned, truth_pose), 0, 1e-12);
  // 5 cm along x: each point's nearest is 5 cm off or on a neighbour (which is 5 cm off too).
  const double off = add_s(cube, at(0.15, -0.05, 0.9), truth_pose);
  EXPECT_GT(off, 0.03);
  Case c;
  c.predictions[0].pose = at(0.15, -0.05, 0.9);
  const SceneEvaluation e = evaluate_scene(1, c.truths, c.predictions, c.catalogue);
  EXPECT_EQ(e.counts.tp, 1);
  EXPECT_EQ(e.counts.pose_ok, 0);  // 10 % of the diameter is 1.7 cm
  EXPECT_NEAR(e.rows[0].add_s, off, 1e-12);
  EXPECT_FALSE(e.rows[0].pose_ok);
}

TEST(SceneEval, CurveRethresholdsTheAnswers) {
  const Case c;
  const SceneEvaluation e = evaluate_scene(1, c.truths, c.predictions, c.catalogue);
  // At the run's own minimum score the point is the scene's counts.
  const SceneCurvePoint at_run = scene_point(e.rows, 2, 2, 0.5);
  EXPECT_EQ(at_run.tp, e.counts.tp);
  EXPECT_EQ(at_run.fp, e.counts.fp);
  EXPECT_EQ(at_run.unknown_named, e.counts.unknown_named);
  EXPECT_DOUBLE_EQ(at_run.f1, e.counts.f1());
  // 0.8: only the duck is named. 0.2: the box's "ape" is named too (an unknown named, an FP).
  const SceneCurvePoint high = scene_point(e.rows, 2, 2, 0.8);
  EXPECT_EQ(high.tp, 1);
  EXPECT_EQ(high.fp, 0);
  EXPECT_EQ(high.unknown_named, 0);
  EXPECT_DOUBLE_EQ(high.tpr, 0.5);
  EXPECT_DOUBLE_EQ(high.precision, 1);
  const SceneCurvePoint low = scene_point(e.rows, 2, 2, 0.2);
  EXPECT_EQ(low.tp, 1);
  EXPECT_EQ(low.fp, 3);
  EXPECT_EQ(low.unknown_named, 2);
  EXPECT_DOUBLE_EQ(low.unknown_named_share, 1);
  // Above every score, then one point per distinct score (0.9, 0.7, 0.6, 0.3).
  const std::vector<SceneCurvePoint> curve = scene_curve(e.rows, 2, 2);
  ASSERT_EQ(curve.size(), 5u);
  EXPECT_EQ(curve[0].tp + curve[0].fp, 0);
  EXPECT_DOUBLE_EQ(curve[1].min_score, 0.9);
  EXPECT_DOUBLE_EQ(curve[4].min_score, 0.3);
  EXPECT_EQ(curve[4].fp, 3);
  // Best F1 with at most 10 % of the unknowns named: only the duck named (F1 2/3).
  const SceneCurvePoint best = best_threshold(curve, 0.1);
  EXPECT_DOUBLE_EQ(best.min_score, 0.9);
  EXPECT_NEAR(best.f1, 2.0 / 3, 1e-12);
}

TEST(SceneEval, CurveKeepsTheMarginRule) {
  const Case c;
  SceneEvaluation e = evaluate_scene(1, c.truths, c.predictions, c.catalogue);
  // Every answer has a runner-up 0.1 behind it: a margin of 0.15 leaves all "unknown" ...
  for (PredictionRow& r : e.rows) r.runner_up = r.score - 0.1;
  // The rule of recognize(): a margin and a confident score.
  auto rule = [](double margin, double confident = 1) {
    proxseg::RecognitionParams r = proxseg::threshold_rule();
    r.min_margin = margin;
    r.confident_score = confident;
    return r;
  };
  const SceneCurvePoint strict = scene_point(e.rows, 2, 2, 0.2, rule(0.15));
  EXPECT_EQ(strict.tp + strict.fp, 0);
  // ... unless the score reaches the confident score (the duck's 0.9 and the 0.7 answer).
  const SceneCurvePoint confident = scene_point(e.rows, 2, 2, 0.2, rule(0.15, 0.7));
  EXPECT_EQ(confident.tp, 1);
  EXPECT_EQ(confident.tp + confident.fp, 2);
  // A margin the runner-ups leave: the same as without one.
  const SceneCurvePoint loose = scene_point(e.rows, 2, 2, 0.2, rule(0.05));
  const SceneCurvePoint none = scene_point(e.rows, 2, 2, 0.2);
  EXPECT_EQ(loose.tp, none.tp);
  EXPECT_EQ(loose.fp, none.fp);
}
