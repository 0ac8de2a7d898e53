// Recognition [paper 3.4] on databases of the LINEMOD models and the milk carton: the shortlist,
// early reject, the acceptance run on the PCL milk scene, merging, unknown objects, visibility.
#include <gtest/gtest.h>
#include <unistd.h>
#include <proxseg/core/database.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/eval/occlusion.hpp>
#include <proxseg/eval/pose_error.hpp>
#include <proxseg/eval/ycb_frames.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/recognition/database_io.hpp>
#include <proxseg/recognition/model_view.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <sys/stat.h>
#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <numeric>

#include "support/fresh_dir.hpp"
#include "support/model_views.hpp"

namespace fs = std::filesystem;
using namespace proxseg;
using namespace proxseg::test;

TEST(Recognition, ShortlistKeepsTheNearestViewsOfTheAskedObjects) {
  const std::string dir = fresh_dir("db_shortlist");
  Database db = open_database(dir, DescriptorParams{});
  add_linemod(db, 4);
  const Mesh driller = read_mesh(kData + "/lmo/models/obj_000008.ply", 0.001);
  const Cloud c = seen_view(driller, dim).candidate;
  const std::vector<int> all = shortlist_views(c, db, 0);
  ASSERT_EQ(all.size(), db.views.size());
  for (std::size_t k = 0; k < all.size(); ++k) EXPECT_EQ(all[k], static_cast<int>(k));
  const std::vector<int> near = shortlist_views(c, db, 6);
  ASSERT_EQ(near.size(), 6u);
  EXPECT_EQ(db.views[near[0]].object, "driller");
  const auto distance = [&](int v) {  // view_distance() with the view's stored parts
    Signature s = db.views[v].signature;
    s.parts = db.views[v].part_signatures();
    return view_distance(c.signature, s);
  };
  for (std::size_t k = 1; k < near.size(); ++k) EXPECT_LE(distance(near[k - 1]), distance(near[k]));
  const std::vector<int> whole = shortlist_views(c, db, 6, {}, false);
  for (std::size_t k = 1; k < whole.size(); ++k)
    EXPECT_LE(signature_distance(c.signature, db.views[whole[k - 1]].signature),
              signature_distance(c.signature, db.views[whole[k]].signature));
  const std::vector<int> only = shortlist_views(c, db, 0, {"duck", "cat"});
  ASSERT_EQ(only.size(), 8u);
  for (int v : only) EXPECT_TRUE(db.views[v].object == "duck" || db.views[v].object == "cat");
  // A shortlisted recognition aligns only the shortlist, and still names the driller.
  RecognitionParams p;
  p.shortlist = 6;
  const Recognition r = recognize(c, db, p);
  EXPECT_EQ(r.views_aligned, 6);
  EXPECT_EQ(r.name, "driller");
}

// Early reject: a batch in which no view so far reached early_reject ends the alignment; one
// that reached it does not.
TEST(Recognition, EarlyRejectStopsWhenNothingFits) {
  Database db = open_database(fresh_dir("db_early_reject"), DescriptorParams{});
  add_linemod(db, 4);  // 32 views
  const Mesh driller = read_mesh(kData + "/lmo/models/obj_000008.ply", 0.001);
  const Cloud c = seen_view(driller, dim).candidate;
  RecognitionParams p;
  p.early_exit = 0;
  const Recognition all = recognize(c, db, p);
  EXPECT_EQ(all.views_aligned, p.shortlist);
  EXPECT_EQ(all.name, "driller");
  p.early_reject = 0.05;  // the driller's views fit far better
  const Recognition kept = recognize(c, db, p);
  EXPECT_EQ(kept.views_aligned, p.shortlist);
  EXPECT_EQ(kept.name, "driller");
  EXPECT_DOUBLE_EQ(kept.best.score, all.best.score);
  p.early_reject = 0.99;  // no view reaches it: the first batch only
  const Recognition rejected = recognize(c, db, p);
  EXPECT_EQ(rejected.views_aligned, 8);
  EXPECT_LT(rejected.best.rank, 0.99);
}

// Acceptance 1: a database of the milk carton and the 8 rendered LINEMOD objects; in the PCL
// scene the milk carton is named with fitness >= 0.9.
TEST(Recognition, NamesTheMilkCartonInTheRealScene) {
  const std::string dir = fresh_dir("db_milk");
  Database db = open_database(dir, DescriptorParams{});
  add_view(db, "milk", read_pcd(kData + "/pcl/milk.pcd"), Eigen::Vector3d::Zero(), "milk.pcd");
  add_linemod(db, 8);
  db = load_database(dir);
  ASSERT_EQ(db.objects().size(), 9u);
  ASSERT_EQ(db.views.size(), 65u);
  const Frame scene = read_pcd(kData + "/pcl/milk_cartoon_all_small_clorox.pcd");
  const SegmentResult seg = segment(scene, SegmentParams{});
  double best_milk = 0;
  int named_milk = 0;
  for (const SceneObject& o : recognize_scene(scene, seg.selection, db, {})) {
    const Recognition& r = o.recognition;
    if (r.name == "milk") {
      ++named_milk;
      best_milk = std::max(best_milk, r.best.fitness);
    }
  }
  EXPECT_EQ(named_milk, 1);  // the carton, and nothing else
  EXPECT_GE(best_milk, 0.9);
}

// Merge (RecognitionParams::merge_unnamed): the driller cut by the selection into two strips,
// each too little of it to be named, whose best views both show the driller; together they are.
TEST(Recognition, MergeJoinsTwoUnnamedPiecesOfOneObject) {
  Database db = open_database(fresh_dir("db_merge"), DescriptorParams{});
  add_linemod(db, 4);
  const Mesh driller = read_mesh(kData + "/lmo/models/obj_000008.ply", 0.001);
  RenderParams rp;
  rp.camera_from_world = look_at({0.1, -0.45, 0.55}, {0, 0, 0});
  const Frame frame = render({driller}, rp);
  // Two strips of columns side by side, each 20 % of the driller's points; the rest of it
  // belongs to no candidate.
  std::vector<int> valid;
  for (std::size_t i = 0; i < frame.size(); ++i)
    if (frame.valid(i)) valid.push_back(static_cast<int>(i));
  std::stable_sort(valid.begin(), valid.end(),
                   [&](int a, int b) { return a % frame.width < b % frame.width; });
  Selection selection;
  selection.instance.assign(frame.size(), 0);
  const std::size_t strip = valid.size() / 5;
  for (int c = 0; c < 2; ++c) {
    Candidate k;
    k.instance = c + 1;
    k.points.assign(valid.begin() + (2 + c) * strip, valid.begin() + (3 + c) * strip);
    std::sort(k.points.begin(), k.points.end());
    for (int i : k.points) selection.instance[i] = k.instance;
    selection.components.push_back(k);
  }
  // Without the lone match, which names a strip on its own (0.4-0.45, runner-up far below), so
  // that the strips are the unnamed pieces this is about.
  RecognitionParams apart;
  apart.lone_score = 0;
  apart.merge_unnamed = false;
  const std::vector<SceneObject> pieces = recognize_scene(frame, selection, db, apart);
  ASSERT_EQ(pieces.size(), 2u);
  for (const SceneObject& o : pieces) {
    EXPECT_EQ(o.recognition.name, "unknown") << o.recognition.best.score;
    EXPECT_EQ(o.recognition.best.object, "driller");
  }
  RecognitionParams together;
  together.lone_score = 0;
  const std::vector<SceneObject> joined = recognize_scene(frame, selection, db, together);
  ASSERT_EQ(joined.size(), 1u);
  EXPECT_EQ(joined[0].origin, SceneObject::Origin::kMerged);
  EXPECT_EQ(joined[0].recognition.name, "driller") << joined[0].recognition.best.score;
  EXPECT_EQ(joined[0].points.size(), 2 * strip);
}

// Unknown objects: with a database of the milk carton alone, the carton is named and every other
// candidate of the scene (the detergent bottle among them, which a geometry-only score named
// "milk" at 0.57) is "unknown".
TEST(Recognition, MilkOnlyDatabaseNamesTheCartonAndNothingElse) {
  const std::string dir = fresh_dir("db_milk_only");
  Database db = open_database(dir, DescriptorParams{});
  add_view(db, "milk", read_pcd(kData + "/pcl/milk.pcd"), Eigen::Vector3d::Zero(), "milk.pcd");
  const Frame scene = read_pcd(kData + "/pcl/milk_cartoon_all_small_clorox.pcd");
  const SegmentResult seg = segment(scene, SegmentParams{});
  int named = 0, unknown = 0, id = 0;
  for (const SceneObject& o : recognize_scene(scene, seg.selection, db, {})) {
    const Recognition& r = o.recognition;
    std::cout << o.points.size() << " points: " << r.name << " " << r.best.score << "\n";
    EXPECT_EQ(o.id, ++id);  // 1.. in order
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int i : o.points) mean += scene.xyz[i].cast<double>();
    EXPECT_LT((o.centroid - mean / o.points.size()).norm(), 1e-9);
    if (r.name == "milk") {
      ++named;
      EXPECT_GE(r.best.fitness, 0.9);
      EXPECT_GT(o.points.size(), 10000u);  // the whole carton, not a part of it
    } else {
      EXPECT_EQ(r.name, "unknown");
      ++unknown;
    }
  }
  EXPECT_EQ(named, 1);
  EXPECT_GE(unknown, 5);
}

// recognize_object(): one object as a cloud of its own (`recognize --object`): the milk carton's
// cloud is named against the milk-only database, with id 0, its valid points (an invalid one
// left out), their centroid and the times.
TEST(Recognition, RecognizeObjectNamesOneCloud) {
  const std::string dir = fresh_dir("db_milk_object");
  Database db = open_database(dir, DescriptorParams{});
  add_view(db, "milk", read_pcd(kData + "/pcl/milk.pcd"), Eigen::Vector3d::Zero(), "milk.pcd");
  Frame milk = read_pcd(kData + "/pcl/milk.pcd");
  milk.xyz[0] = Eigen::Vector3f::Constant(NAN);  // an invalid point is left out
  const SceneObject o = recognize_object(milk, db, RecognitionParams{});
  EXPECT_EQ(o.recognition.name, "milk");
  EXPECT_GE(o.recognition.best.fitness, 0.9);
  EXPECT_EQ(o.id, 0);
  EXPECT_EQ(o.points.size(), milk.valid_count());
  EXPECT_EQ(o.points.front(), 1);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i : o.points) mean += milk.xyz[i].cast<double>();
  EXPECT_LT((o.centroid - mean / o.points.size()).norm(), 1e-9);
  EXPECT_TRUE(o.instances.empty());
  EXPECT_GT(o.recognition.describe_ms, 0);
  EXPECT_GT(o.recognition.views_aligned, 0);
}

// The free-space check: a view put where the sensor saw the object agrees with the depths; put
// in front of them (where the sensor saw through) it does not; put behind them it is hidden,
// which says nothing against it.
TEST(Visibility, ViewInFrontOfTheMeasuredDepthViolatesFreeSpace) {
  const Eigen::Isometry3d pose(Eigen::Translation3d(0.02, -0.01, 0.8) *
                               Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()));
  const Mesh box = make_box(pose, {0.12, 0.08, 0.1}, [](const Eigen::Vector3d&) {
    return Rgb{200, 40, 40};
  });
  RenderParams rp;  // camera at the origin: the mesh is in the camera frame
  const Frame frame = render({box}, rp);
  const DepthImage image = depth_image(frame);
  ASSERT_FALSE(image.empty());
  EXPECT_NEAR(image.fx, rp.camera.fx, 0.5);
  EXPECT_NEAR(image.cy, rp.camera.cy, 0.5);
  std::vector<Eigen::Vector3d> points;
  for (std::size_t i = 0; i < frame.size(); ++i)
    if (frame.valid(i)) points.push_back(frame.xyz[i].cast<double>());
  const Cloud view = describe(points, Eigen::Vector3d::Zero(), DescriptorParams{});
  Eigen::Matrix4d in_place = Eigen::Matrix4d::Identity(), nearer = in_place, farther = in_place;
  nearer(2, 3) = -0.05;
  farther(2, 3) = 0.05;
  EXPECT_LT(free_space_violation(image, view, in_place, 0.01), 0.02);
  EXPECT_GT(free_space_violation(image, view, nearer, 0.01), 0.95);
  EXPECT_LT(free_space_violation(image, view, farther, 0.01), 0.02);
  // An unorganized frame has no depth image: the check says nothing.
  EXPECT_TRUE(depth_image(frame_of(points)).empty());
}

// A candidate cut by the image's border goes on past it: a model that ends inside the image is
// not what it is, one that explains it up to the border may be (border_unexplained()).
TEST(Visibility, CandidateCutByTheBorderMustBeExplainedUpToIt) {
  // A plank 60 cm long at 0.8 m, its left end past the image's left border.
  const Eigen::Isometry3d pose(Eigen::Translation3d(-0.4, 0.05, 0.8));
  const Mesh plank = make_box(pose, {0.6, 0.03, 0.02}, [](const Eigen::Vector3d&) {
    return Rgb{40, 40, 45};
  });
  RenderParams rp;
  const Frame frame = render({plank}, rp);
  const DepthImage image = depth_image(frame);
  ASSERT_FALSE(image.empty());
  std::vector<Eigen::Vector3d> points, inner;
  for (std::size_t i = 0; i < frame.size(); ++i)
    if (frame.valid(i)) {
      points.push_back(frame.xyz[i].cast<double>());
      if (points.back().x() > -0.3) inner.push_back(points.back());
    }
  const Cloud candidate = describe(points, Eigen::Vector3d::Zero(), DescriptorParams{});
  const Cloud piece = describe(inner, Eigen::Vector3d::Zero(), DescriptorParams{});
  const Eigen::Matrix4d in_place = Eigen::Matrix4d::Identity();
  const double delta = RegistrationParams{}.fitness_distance;
  // The whole plank explains its border points; a 20 cm piece of it in the middle does not.
  EXPECT_LT(border_unexplained(image, candidate, candidate, in_place, delta), 0.05);
  EXPECT_GT(border_unexplained(image, candidate, piece, in_place, delta), 0.95);
  // A candidate away from the border: nothing to check.
  EXPECT_EQ(border_unexplained(image, piece, candidate, in_place, delta), 0.0);
  EXPECT_EQ(border_unexplained(DepthImage{}, candidate, piece, in_place, delta), 0.0);
}
