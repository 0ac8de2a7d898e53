// Registration [paper 3.4]: rendered model views, the paper's occlusion generator, known poses
// recovered, and occluded views ranked and judged on the whole view.
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

TEST(Render, ViewsOfAMeshAreInItsFrameAndSeenFromTheEye) {
  const Mesh mesh = read_mesh(kData + "/lmo/models/obj_000001.ply", 0.001);  // ape, ~8 cm
  ViewSphereParams p;
  p.views = 6;
  const auto views = render_views(mesh, p);
  ASSERT_EQ(views.size(), 6u);
  Eigen::Vector3d lo = mesh.vertices[0].cast<double>(), hi = lo;
  for (const auto& v : mesh.vertices) {
    lo = lo.cwiseMin(v.cast<double>());
    hi = hi.cwiseMax(v.cast<double>());
  }
  for (const auto& v : views) {
    EXPECT_GT(v.points.size(), 500u);
    EXPECT_NEAR((v.eye - (lo + hi) / 2).norm(), 0.6, 1e-9);  // max(0.6, 3 x diameter)
    for (const auto& q : v.points.xyz) {
      ASSERT_TRUE((q.cast<double>().array() >= lo.array() - 1e-4).all());
      ASSERT_TRUE((q.cast<double>().array() <= hi.array() + 1e-4).all());
    }
  }
}

// The paper's occlusion generator on a rendered LINEMOD view: a ball around a point of the view
// is removed, reproducibly, and random radii up to the object's size reach every bin of Table 3.
TEST(Evaluation, OcclusionGeneratorRemovesABallAroundAPointOfTheView) {
  const Mesh mesh = read_mesh(kData + "/lmo/models/obj_000005.ply", 0.001);  // can
  ViewSphereParams vp;
  vp.views = 1;
  const auto rendered = render_views(mesh, vp);
  std::vector<Eigen::Vector3d> view;
  for (const auto& q : rendered.at(0).points.xyz) view.push_back(q.cast<double>());
  ASSERT_GT(view.size(), 1000u);
  std::vector<int> bins(10, 0);
  for (std::uint64_t seed = 1; seed <= 300; ++seed) {
    const Occlusion o = occlude(view, 0.1, seed);
    ASSERT_GE(o.radius, 0);
    ASSERT_LE(o.radius, 0.1);
    // Exactly the points within the radius are gone.
    std::size_t inside = 0;
    for (const auto& p : view) inside += (p - o.centre).norm() <= o.radius;
    EXPECT_EQ(o.points.size(), view.size() - inside);
    for (const auto& p : o.points) ASSERT_GT((p - o.centre).norm(), o.radius);
    EXPECT_NEAR(o.removed_share, double(inside) / view.size(), 1e-12);
    ++bins[std::min(9, static_cast<int>(o.removed_share * 10))];
    if (seed <= 3) {
      const Occlusion again = occlude(view, 0.1, seed);
      EXPECT_EQ(again.points, o.points);
      EXPECT_EQ(again.centre, o.centre);
    }
  }
  for (int b = 1; b < 7; ++b)
    EXPECT_GT(bins[b], 0) << "no occlusion of " << b * 10 << "-" << b * 10 + 10 << " %";
  EXPECT_THROW(occlude({}, 0.1, 1), InputError);
  EXPECT_THROW(occlude(view, -1, 1), InputError);
}

TEST(Registration, RecoversAKnownPoseOfARenderedView) {
  const Mesh mesh = read_mesh(kData + "/lmo/models/obj_000008.ply", 0.001);  // driller
  ViewSphereParams p;
  p.views = 4;
  const auto views = render_views(mesh, p);
  DescriptorParams d;
  const Cloud view = describe(points_of(views[1].points,
                                        [&] {
                                          std::vector<int> all(views[1].points.size());
                                          std::iota(all.begin(), all.end(), 0);
                                          return all;
                                        }()),
                              views[1].eye, d);
  // The candidate: the same surface seen from a camera 0.8 m away, in the camera frame.
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.linear() =
      (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  truth.translation() = Eigen::Vector3d(0.05, -0.1, 0.8);
  std::vector<Eigen::Vector3d> seen;
  for (const auto& q : views[1].points.xyz) seen.push_back(truth * q.cast<double>());
  const Cloud candidate = describe(seen, truth * views[1].eye, d);
  const Alignment a = align(candidate, view, RegistrationParams{}, 7);
  const Eigen::Matrix4d err = a.pose.inverse() * truth.matrix();
  const Eigen::Vector3d shift = err.topRightCorner(3, 1);
  EXPECT_LT(shift.norm(), 0.005);
  const Eigen::Matrix3d rot = err.topLeftCorner(3, 3);
  EXPECT_LT(Eigen::AngleAxisd(rot).angle() * 180 / M_PI, 2.0);
  EXPECT_GT(a.fitness, 0.97);
  EXPECT_GT(a.coverage, 0.9);
  // Same inputs and seed, same answer.
  const Alignment b = align(candidate, view, RegistrationParams{}, 7);
  EXPECT_EQ(a.pose, b.pose);
}

// Occlusion [extension, docs/method.md "A database that scales"]: a driller view seen by a camera,
// whole and with 30-50 % of its points removed by the paper's occlusion generator, at its true
// pose.
namespace {
struct OccludedView {
  Cloud view, whole, occluded;
  Eigen::Matrix4d truth = Eigen::Matrix4d::Identity();  // camera <- model
  double removed = 0;
};
OccludedView occluded_driller() {
  const Mesh mesh = read_mesh(kData + "/lmo/models/obj_000008.ply", 0.001);
  ViewSphereParams p;
  p.views = 4;
  const auto views = render_views(mesh, p);
  OccludedView o;
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d(2, -1, 1).normalized()).matrix();
  truth.translation() = Eigen::Vector3d(-0.03, 0.02, 0.9);
  o.truth = truth.matrix();
  std::vector<Eigen::Vector3d> model, seen;
  for (const auto& q : views[1].points.xyz) {
    model.push_back(q.cast<double>());
    seen.push_back(truth * model.back());
  }
  o.view = describe(model, views[1].eye, DescriptorParams{});
  add_part_signatures(o.view);
  o.whole = describe(seen, Eigen::Vector3d::Zero(), DescriptorParams{});
  for (std::uint64_t seed = 1;; ++seed) {
    const Occlusion c = occlude(seen, 0.2, seed);
    if (c.removed_share < 0.3 || c.removed_share >= 0.5) continue;
    o.occluded = describe(c.points, Eigen::Vector3d::Zero(), DescriptorParams{});
    o.removed = c.removed_share;
    return o;
  }
}
}  // namespace

TEST(Registration, CoverageDiscountsWhatAnOcclusionHid) {
  const OccludedView o = occluded_driller();
  const double delta = RegistrationParams{}.score_distance;
  // The whole view: its model lies inside its silhouette, and the weight changes nothing.
  const CoverageCounts whole = coverage_counts(o.whole, o.view, o.truth, delta);
  EXPECT_LT(whole.outside, 0.02 * (whole.inside + whole.outside));
  EXPECT_NEAR(coverage(o.whole, o.view, o.truth, delta, 0.2),
              coverage(o.whole, o.view, o.truth, delta), 0.02);
  EXPECT_GT(coverage(o.whole, o.view, o.truth, delta), 0.9);
  // The occluded view: what the model predicts in the hidden region lies outside the silhouette.
  const CoverageCounts hid = coverage_counts(o.occluded, o.view, o.truth, delta);
  const int visible = hid.inside + hid.outside;
  EXPECT_GT(hid.outside, 0.2 * visible) << "removed " << o.removed;
  EXPECT_DOUBLE_EQ(coverage(o.occluded, o.view, o.truth, delta), double(hid.explained) / visible);
  EXPECT_LT(coverage(o.occluded, o.view, o.truth, delta), 0.75);
  EXPECT_GT(coverage(o.occluded, o.view, o.truth, delta, 0.2),
            coverage(o.occluded, o.view, o.truth, delta) + 0.15);
  EXPECT_GT(coverage(o.occluded, o.view, o.truth, delta, 0), 0.9);
  // score_pose(): the coverage that ranks allows for the occlusion, the score's does not.
  RegistrationParams r;
  const Alignment a = score_pose(o.occluded, o.view, o.truth, r);
  EXPECT_DOUBLE_EQ(a.coverage, coverage(o.occluded, o.view, o.truth, delta));
  EXPECT_DOUBLE_EQ(a.occluded_coverage,
                   coverage(o.occluded, o.view, o.truth, delta, r.coverage_outside_weight));
  EXPECT_GT(a.occluded_coverage, a.coverage + 0.1);
  EXPECT_GT(rank_of(a, Score::kSymmetric), score_of(a, Score::kSymmetric));
  r.coverage_outside_weight = 1;
  const Alignment none = score_pose(o.occluded, o.view, o.truth, r);
  EXPECT_EQ(none.occluded_coverage, none.coverage);
  EXPECT_EQ(none.coverage, a.coverage);
  EXPECT_EQ(rank_of(none, Score::kColour), score_of(none, Score::kColour));
}

TEST(Recognition, PartSignaturesBringAnOccludedViewNearItsOwn) {
  const OccludedView o = occluded_driller();
  ASSERT_EQ(o.view.signature.parts.size(), 24u);  // 8 centres x 3 shares removed
  for (const Signature& part : o.view.signature.parts) {
    EXPECT_TRUE(part.parts.empty());
    EXPECT_NEAR(part.shape.sum(), 2.0f, 1e-4);  // two FPFH radii, each block sums to 1
    EXPECT_GT(part.spread, 0);
  }
  // The nearest part is nearer than the whole view; for the whole candidate the whole view is
  // about as near as any part.
  const double d_whole = signature_distance(o.occluded.signature, o.view.signature);
  const double d_parts = view_distance(o.occluded.signature, o.view.signature);
  EXPECT_LT(d_parts, 0.8 * d_whole) << d_parts << " " << d_whole;
  EXPECT_LE(view_distance(o.whole.signature, o.view.signature),
            signature_distance(o.whole.signature, o.view.signature));
  // Candidates have no parts (only database views do), and views get them again on demand.
  EXPECT_TRUE(o.occluded.signature.parts.empty());
  Cloud again = o.view;
  add_part_signatures(again);
  ASSERT_EQ(again.signature.parts.size(), 24u);
  EXPECT_EQ(again.signature.parts[5].shape, o.view.signature.parts[5].shape);
}

// Views are ranked allowing for the occlusion (Match::rank) and the answer judged on the score.
TEST(Recognition, RanksAllowingForOcclusionAndJudgesOnTheWholeView) {
  const OccludedView o = occluded_driller();
  Database db = open_database(fresh_dir("db_occluded"), DescriptorParams{});
  add_linemod(db, 4);
  const Recognition r = recognize(o.occluded, db, {});
  EXPECT_EQ(r.name, "driller");
  EXPECT_GT(r.best.rank, r.best.score + 0.05);
  EXPECT_EQ(r.best.score, score_of(r.alignments[r.best.view], Score::kColour));
  EXPECT_EQ(r.runner_up.score, [&] {
    double best = 0;
    for (std::size_t v = 0; v < db.views.size(); ++v)
      if (db.views[v].object != "driller")
        best = std::max(best, score_of(r.alignments[v], Score::kColour));
    return best;
  }());
  RecognitionParams whole;
  whole.registration.coverage_outside_weight = 1;
  const Recognition w = recognize(o.occluded, db, whole);
  EXPECT_EQ(w.best.rank, w.best.score);
  EXPECT_EQ(w.name, "driller");
}
