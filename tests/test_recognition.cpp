// Recognition [paper 3.4]: model database round trip, registration of known poses, and the
// acceptance runs of the recognition issue on real data (PCL milk scene, YCB-Video frames).
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

#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Feature.h>
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

#include "fresh_dir.hpp"

namespace fs = std::filesystem;
using namespace proxseg;

namespace {

const std::string kData = PROXSEG_DATA_DIR;

using test::fresh_dir;
using test::made_dirs;

std::vector<Eigen::Vector3d> points_of(const Frame& f, const std::vector<int>& idx) {
  std::vector<Eigen::Vector3d> out;
  for (int i : idx) out.push_back(f.xyz[i].cast<double>());
  return out;
}

Frame frame_of(const std::vector<Eigen::Vector3d>& pts) {
  Frame f;
  for (const auto& p : pts) f.xyz.push_back(p.cast<float>());
  f.width = static_cast<int>(pts.size());
  f.height = 1;
  return f;
}

const std::map<std::string, std::string> kLinemod = {
    {"01", "ape"},  {"05", "can"},    {"06", "cat"},  {"08", "driller"},
    {"09", "duck"}, {"10", "eggbox"}, {"11", "glue"}, {"12", "holepuncher"}};

void add_linemod(Database& db, int views) {
  for (const auto& [id, name] : kLinemod) {
    const Mesh mesh = read_mesh(kData + "/lmo/models/obj_0000" + id + ".ply", 0.001);
    ViewSphereParams p;
    p.views = views;
    for (const auto& v : render_views(mesh, p)) add_view(db, name, v.points, v.eye, "render");
  }
}

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

// describe()'s FPFH (one neighbour search shared by the radii) must be Open3D's to the last bit:
// the stored views of existing databases were described by Open3D's ComputeFPFHFeature.
TEST(Descriptors, FpfhIsOpen3dsToTheLastBit) {
  const DescriptorParams params;
  std::vector<Cloud> clouds;
  for (const char* model : {"003_cracker_box", "025_mug", "040_large_marker"})
    clouds.push_back(describe(read_xyz(kData + "/ycbv/models/" + model + "/points.xyz"),
                              Eigen::Vector3d::Constant(std::nan("")), params));
  const Mesh duck = read_mesh(kData + "/lmo/models/obj_000009.ply", 0.001);
  ViewSphereParams views;
  views.views = 2;
  for (const auto& v : render_views(duck, views)) {
    std::vector<Eigen::Vector3d> xyz;
    for (const auto& p : v.points.xyz) xyz.push_back(p.cast<double>());
    clouds.push_back(describe(xyz, v.eye, params));
  }
  long compared = 0;
  for (const Cloud& c : clouds) {
    open3d::geometry::PointCloud pc;
    pc.points_ = c.points;
    pc.normals_ = c.normals;
    for (std::size_t r = 0; r < params.fpfh_radii.size(); ++r) {
      const auto f = open3d::pipelines::registration::ComputeFPFHFeature(
          pc, open3d::geometry::KDTreeSearchParamHybrid(params.fpfh_radii[r], 100));
      ASSERT_EQ(f->data_.cols(), c.features.cols());
      for (Eigen::Index j = 0; j < f->data_.cols(); ++j)
        for (int b = 0; b < 33; ++b, ++compared)
          ASSERT_EQ(static_cast<double>(static_cast<float>(f->data_(b, j))),
                    c.features(33 * static_cast<Eigen::Index>(r) + b, j))
              << "radius " << params.fpfh_radii[r] << ", point " << j << ", bin " << b;
    }
  }
  EXPECT_GT(compared, 100000);
}

// describe()'s normals and spacing (our own neighbour search and PCA) must be Open3D's
// EstimateNormals (hybrid search: the 30 nearest within the radius) and nearest-neighbour
// distances: the FPFH above, and every score after it, is computed from them.
TEST(Descriptors, NormalsAndSpacingAreOpen3ds) {
  const DescriptorParams params;
  long compared = 0;
  for (const char* model : {"003_cracker_box", "025_mug", "040_large_marker", "011_banana"}) {
    const Cloud c = describe(read_xyz(kData + "/ycbv/models/" + model + "/points.xyz"),
                             Eigen::Vector3d::Constant(std::nan("")), params);
    open3d::geometry::PointCloud pc;
    pc.points_ = c.points;
    pc.EstimateNormals(open3d::geometry::KDTreeSearchParamHybrid(params.normal_radius, 30), false);
    const open3d::geometry::KDTreeFlann tree(pc);
    std::vector<double> spacing;
    for (std::size_t i = 0; i < c.size(); ++i, ++compared) {
      Eigen::Vector3d n = pc.normals_[i];
      if (n.dot(c.points[i] - c.centroid) < 0) n = -n;  // a full model: away from the centroid
      ASSERT_EQ(n.cast<float>(), c.normals[i].cast<float>()) << model << ", point " << i;
      std::vector<int> index;
      std::vector<double> d2;
      ASSERT_EQ(tree.SearchKNN(c.points[i], 2, index, d2), 2);
      spacing.push_back(std::sqrt(d2[1]));
    }
    std::nth_element(spacing.begin(), spacing.begin() + spacing.size() / 2, spacing.end());
    EXPECT_EQ(spacing[spacing.size() / 2], c.spacing) << model;
  }
  EXPECT_GT(compared, 4000);
}

// Points, normals and FPFH are kept at float precision (the precision of a PCD file and of the
// database), every coordinate: GCC 12's vectoriser folded the round trip of x and y away. The
// check goes through a volatile float for the same reason.
TEST(Descriptors, AreAtFloatPrecision) {
  const Cloud c = describe(read_xyz(kData + "/ycbv/models/025_mug/points.xyz"),
                           Eigen::Vector3d::Constant(std::nan("")), DescriptorParams{});
  const auto at_float = [](double x) {
    volatile float f = static_cast<float>(x);
    return static_cast<double>(f) == x;
  };
  for (std::size_t i = 0; i < c.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      ASSERT_TRUE(at_float(c.points[i][k])) << "point " << i << ", coordinate " << k;
      ASSERT_TRUE(at_float(c.normals[i][k])) << "normal " << i << ", coordinate " << k;
    }
  for (Eigen::Index j = 0; j < c.features.size(); ++j)
    ASSERT_TRUE(at_float(c.features.data()[j])) << "feature value " << j;
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

// Colour in recognition [extension, docs/method.md "Colour in recognition"].
TEST(Colour, ChromaticityIgnoresBrightnessButNotHue) {
  const Rgb red{200, 40, 30}, dim_red{80, 16, 12}, orange{200, 110, 30}, black{12, 12, 14};
  EXPECT_DOUBLE_EQ(chromaticity_agreement(red, red), 1.0);
  EXPECT_GT(chromaticity_agreement(red, dim_red), 0.8);  // the same paint in shadow
  EXPECT_LT(chromaticity_agreement(red, orange), 0.3);
  EXPECT_LT(chromaticity_agreement(red, black), 0.01);
  EXPECT_GT(chromaticity_agreement(black, Rgb{8, 9, 6}), 0.8);  // sensor noise on black
}

namespace {
// A rendered view of a LINEMOD mesh (model frame) and the same view seen by a camera, with its
// colours passed through `paint`.
struct SeenView {
  Cloud view, candidate;
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();  // camera <- model
};
SeenView seen_view(const Mesh& mesh, const std::function<Rgb(const Rgb&)>& paint) {
  ViewSphereParams p;
  p.views = 4;
  const auto views = render_views(mesh, p);
  const Frame& f = views[1].points;
  std::vector<Eigen::Vector3d> model, seen;
  std::vector<Rgb> painted;
  SeenView s;
  s.truth.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 1).normalized()).matrix();
  s.truth.translation() = Eigen::Vector3d(0.02, 0.05, 0.9);
  for (std::size_t i = 0; i < f.size(); ++i) {
    model.push_back(f.xyz[i].cast<double>());
    seen.push_back(s.truth * model.back());
    painted.push_back(paint(f.rgb[i]));
  }
  s.view = describe(model, views[1].eye, DescriptorParams{}, &f.rgb);
  s.candidate = describe(seen, s.truth * views[1].eye, DescriptorParams{}, &painted);
  return s;
}
Rgb dim(const Rgb& c) {
  return {static_cast<std::uint8_t>(c[0] * 0.5), static_cast<std::uint8_t>(c[1] * 0.5),
          static_cast<std::uint8_t>(c[2] * 0.5)};
}
Rgb blue(const Rgb& c) {
  return {c[2], c[1], c[0]};
}
}  // namespace

TEST(Colour, AgreementOfAnAlignedViewDropsForAnotherPaint) {
  const Mesh duck = read_mesh(kData + "/lmo/models/obj_000009.ply", 0.001);
  const RegistrationParams r;
  const SeenView same = seen_view(duck, dim);
  EXPECT_GT(colour_agreement(same.candidate, same.view, same.truth.matrix(), r.score_distance),
            0.9);
  const SeenView other = seen_view(duck, blue);  // the yellow duck painted blue
  EXPECT_LT(colour_agreement(other.candidate, other.view, other.truth.matrix(), r.score_distance),
            0.2);
  // Without colour on one side, the term stays out of the way.
  Cloud colourless = other.candidate;
  colourless.colours.clear();
  EXPECT_EQ(colour_agreement(colourless, other.view, other.truth.matrix(), r.score_distance), 1.0);
  // And it shows in the alignment's scores.
  const Alignment a = score_pose(other.candidate, other.view, other.truth.matrix(), r);
  EXPECT_GT(score_of(a, Score::kSymmetric), 0.8);
  EXPECT_LT(score_of(a, Score::kColour), 0.2);
}

TEST(Recognition, ColourTellsApartTwoObjectsOfOneShape) {
  const Mesh duck = read_mesh(kData + "/lmo/models/obj_000009.ply", 0.001);
  Mesh blue_duck = duck;
  for (auto& c : blue_duck.colours) c = blue(c);
  Database db;
  db.descriptor = DescriptorParams{};
  ViewSphereParams vp;
  vp.views = 4;
  const std::vector<std::pair<std::string, const Mesh*>> meshes = {{"duck", &duck},
                                                                   {"blue duck", &blue_duck}};
  for (const auto& [name, mesh] : meshes)
    for (const auto& v : render_views(*mesh, vp)) {
      std::vector<Eigen::Vector3d> pts;
      for (const auto& q : v.points.xyz) pts.push_back(q.cast<double>());
      db.views.push_back(
          make_model_view(name, describe(pts, v.eye, db.descriptor, &v.points.rgb), "render"));
    }
  // Chromaticity alone: a quarter of the brightness (a darker paint, in deep shadow) still agrees.
  RecognitionParams colour, shape;
  colour.registration.brightness_sigma = 0;
  shape.score = Score::kSymmetric;
  const std::vector<std::pair<std::string, Rgb (*)(const Rgb&)>> paints = {{"duck", &dim},
                                                                           {"blue duck", &blue}};
  for (const auto& [name, paint] : paints) {
    // Seen in shadow, from between the database's viewpoints.
    const Cloud c = seen_view(duck, [p = paint](const Rgb& x) { return dim(p(x)); }).candidate;
    const Recognition r = recognize(c, db, colour);
    EXPECT_EQ(r.name, name);
    EXPECT_GT(r.best.score - r.runner_up.score, 0.3) << name;
    // Geometry alone cannot tell them apart: the two best scores are close.
    const Recognition g = recognize(c, db, shape);
    EXPECT_LT(std::abs(g.best.score - g.runner_up.score), 0.1) << name;
    // With the default brightness term a shadow (half the brightness) still names it.
    const Cloud shade = seen_view(duck, paint).candidate;
    const Recognition d = recognize(shade, db, RecognitionParams{});
    EXPECT_EQ(d.name, name);
    EXPECT_GT(d.best.score - d.runner_up.score, 0.3) << name;
  }
}

// Look-alikes (lookalike.hpp): the duck and a duck painted blue on one side only, as a pair of
// look-alikes that agree on most of what is seen. The points of the blue side vote.
TEST(Recognition, LookalikeVoteGoesByWhereTheColoursDiffer) {
  const Mesh duck = read_mesh(kData + "/lmo/models/obj_000009.ply", 0.001);
  const SeenView seen = seen_view(duck, dim);
  Cloud half_blue = seen.view;
  double mid = 0;
  for (const auto& q : half_blue.points) mid += q.x() / half_blue.size();
  int painted = 0;
  for (std::size_t i = 0; i < half_blue.size(); ++i)
    if (half_blue.points[i].x() > mid + 0.01)
      half_blue.colours[i] = blue(half_blue.colours[i]), ++painted;
  ASSERT_GT(painted, 50);
  const RegistrationParams r;
  const Eigen::Matrix4d pose = seen.truth.matrix();
  const LookalikeVote v = lookalike_vote(seen.candidate, seen.view, pose, half_blue, pose, r);
  EXPECT_GT(v.compared, 0.8 * seen.candidate.size());
  EXPECT_GT(v.differing, 40);
  EXPECT_LT(v.differing, 0.8 * v.compared);  // the side left yellow does not vote
  EXPECT_GT(v.first, 0.9 * v.differing);
  EXPECT_EQ(v.second, 0);
  EXPECT_GT(v.first_agreement, 0.8);
  EXPECT_EQ(lookalike_winner(v, 0.8, 0.6, 10), 1);
  // The other way round, and for a candidate painted like the second view.
  const LookalikeVote w = lookalike_vote(seen.candidate, half_blue, pose, seen.view, pose, r);
  EXPECT_EQ(lookalike_winner(w, 0.8, 0.6, 10), 2);
  Cloud blue_candidate = seen.candidate;
  const std::vector<int> near =
      nearest_view_points(seen.candidate, half_blue, pose, r.score_distance);
  for (std::size_t i = 0; i < near.size(); ++i)
    if (near[i] >= 0) blue_candidate.colours[i] = dim(half_blue.colours[near[i]]);
  EXPECT_EQ(lookalike_winner(lookalike_vote(blue_candidate, seen.view, pose, half_blue, pose, r),
                             0.8, 0.6, 10),
            2);
  // A candidate of a third colour where the two differ leans to neither well enough.
  Cloud red_candidate = blue_candidate;
  for (std::size_t i = 0; i < near.size(); ++i)
    if (near[i] >= 0 && half_blue.colours[near[i]] != seen.view.colours[near[i]])
      red_candidate.colours[i] = Rgb{200, 30, 30};
  EXPECT_EQ(lookalike_winner(lookalike_vote(red_candidate, seen.view, pose, half_blue, pose, r),
                             0.8, 0.6, 10),
            0);
  // Without colour there is no vote.
  Cloud colourless = seen.candidate;
  colourless.colours.clear();
  EXPECT_EQ(lookalike_vote(colourless, seen.view, pose, half_blue, pose, r).compared, 0);
}

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

// ---- Acceptance 2: YCB-Video, 10 frames x 3 objects, database of the 21 models ----

struct YcbCase {
  std::string truth, named;
  bool pose_ok = false;
  PoseError error;
};

class Ycb : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    classes_ = read_lines(kData + "/ycbv/classes.txt");
    ASSERT_EQ(classes_.size(), 21u);
    const std::string dir = fresh_dir("db_ycbv");
    Database db = open_database(dir, DescriptorParams{});
    for (const auto& c : classes_) {
      const auto pts = read_xyz(kData + "/ycbv/models/" + c + "/points.xyz");
      add_view(db, c, frame_of(pts), Eigen::Vector3d::Constant(std::nan("")), c);
      models_[c] = pts;
      symmetries_[c] = box_symmetries(pts, 0.005);
    }
    db_ = load_database(dir);
  }

  // Right pose: within 2 cm and 10 degrees of meta.json's, allowing for the box symmetries; the
  // mug counts as turn-symmetric about its axis in frames where its handle is hidden.
  static YcbCase judge(const YcbFrame& y, const ObjectTruth& o, const Recognition& r) {
    YcbCase c{o.name, r.name, false, {}};
    c.error = pose_error(r.best.pose, o.pose, symmetries_[o.name]);
    if (o.name == "025_mug" && !handle_visible(y, o))
      c.error = axial_pose_error(r.best.pose, o.pose, Eigen::Vector3d(-0.0031, 0.0007, 0),
                                 Eigen::Vector3d::UnitZ());
    c.pose_ok = r.name == o.name && c.error.translation < 0.02 && c.error.rotation_deg < 10;
    return c;
  }

  // The handle (model x > 5 cm) is visible when some of its points, put in the camera by the
  // true pose, land on mug pixels at their own depth.
  static bool handle_visible(const YcbFrame& y, const ObjectTruth& o) {
    const Intrinsics& k = y.intrinsics;
    int seen = 0;
    for (const auto& p : models_.at(o.name)) {
      if (p.x() < 0.05) continue;
      const Eigen::Vector3d q = o.pose.topLeftCorner<3, 3>() * p + o.pose.topRightCorner<3, 1>();
      const int u = static_cast<int>(std::lround(k.fx * q.x() / q.z() + k.cx));
      const int v = static_cast<int>(std::lround(k.fy * q.y() / q.z() + k.cy));
      if (u < 0 || v < 0 || u >= y.frame.width || v >= y.frame.height) continue;
      const int i = v * y.frame.width + u;
      seen += y.frame.valid(i) && std::abs(y.frame.xyz[i].z() - q.z()) < 0.01 &&
              std::binary_search(o.points.begin(), o.points.end(), i);
    }
    return seen >= 5;
  }

  static void report(const char* what, const std::vector<YcbCase>& cases, double& named,
                     double& posed) {
    int n = 0, p = 0;
    for (const auto& c : cases) {
      n += c.named == c.truth;
      p += c.pose_ok;
      std::printf("  %-16s -> %-22s %6.3f m %6.1f deg %s\n", c.truth.c_str(), c.named.c_str(),
                  c.error.translation, c.error.rotation_deg, c.pose_ok ? "pose ok" : "");
    }
    named = double(n) / cases.size();
    posed = double(p) / cases.size();
    std::printf("%s: named %d/%zu, pose %d/%zu\n", what, n, cases.size(), p, cases.size());
  }

  static std::vector<std::string> classes_;
  static std::map<std::string, std::vector<Eigen::Vector3d>> models_;
  static std::map<std::string, std::vector<Eigen::Matrix4d>> symmetries_;
  // Frame k (1..10) of the YCB-Video sample.
  static YcbFrame frame(int k) {
    char stem[16];
    std::snprintf(stem, sizeof stem, "%06d", k);
    return read_ycb_frame(kData + "/ycbv/frames", stem, classes_);
  }

  static Database db_;
};
std::vector<std::string> Ycb::classes_;
std::map<std::string, std::vector<Eigen::Vector3d>> Ycb::models_;
std::map<std::string, std::vector<Eigen::Matrix4d>> Ycb::symmetries_;
Database Ycb::db_;

// Under ASan + UBSan (make test-sanitize) every third frame (1, 4, 7, 10): the same code paths and
// floors in a quarter of the time.
#ifdef PROXSEG_SANITIZE
constexpr int kFrameStep = 3;
#else
constexpr int kFrameStep = 1;
#endif

TEST_F(Ycb, GroundTruthMasks) {
  std::vector<YcbCase> cases;
  for (int k = 1; k <= 10; k += kFrameStep) {
    const YcbFrame y = frame(k);
    ASSERT_EQ(y.objects.size(), 3u);
    for (const auto& o : y.objects) {
      const Recognition r =
          recognize(describe_candidate(points_of(y.frame, o.points), db_), db_, {});
      cases.push_back(judge(y, o, r));
    }
  }
  double named = 0, posed = 0;
  report("ground-truth masks", cases, named, posed);
  EXPECT_GE(named, 0.9);
  EXPECT_GE(posed, 0.8);
}

TEST_F(Ycb, ProxsegCandidates) {
  std::vector<YcbCase> cases;
  std::vector<std::string> stray;
  int split = 0, merged = 0;
  for (int k = 1; k <= 10; k += kFrameStep) {
    const YcbFrame y = frame(k);
    const SegmentResult seg = segment(y.frame, SegmentParams{});
    const std::vector<SceneObject> objects = recognize_scene(y.frame, seg.selection, db_, {});
    for (const auto& s : objects) {
      split += s.origin == SceneObject::Origin::kSplit;
      merged += s.origin == SceneObject::Origin::kMerged;
    }
    // A named object that is no truth's best match (IoU >= 0.5) under that truth's name.
    std::vector<const SceneObject*> matched;
    for (const auto& o : y.objects) {
      const SceneObject* best = nullptr;
      double best_iou = 0;
      for (const SceneObject& s : objects) {
        std::vector<int> inter;
        std::set_intersection(s.points.begin(), s.points.end(), o.points.begin(), o.points.end(),
                              std::back_inserter(inter));
        const double iou =
            double(inter.size()) / (s.points.size() + o.points.size() - inter.size());
        if (iou > best_iou) best_iou = iou, best = &s;
      }
      if (!best || best_iou < 0.5) {
        cases.push_back({o.name, "(no candidate)", false, {}});
        continue;
      }
      if (best->recognition.name == o.name) matched.push_back(best);
      cases.push_back(judge(y, o, best->recognition));
    }
    for (const SceneObject& s : objects)
      if (s.recognition.name != "unknown" &&
          std::find(matched.begin(), matched.end(), &s) == matched.end())
        stray.push_back("frame " + std::to_string(k) + ": " + s.recognition.name + " " +
                        std::to_string(s.recognition.best.score) + " on " +
                        std::to_string(s.points.size()) + " points");
  }
  double named = 0, posed = 0;
  report("proxseg candidates", cases, named, posed);
  std::printf("objects split %d, merged %d; names on no object of the frame: %d\n", split, merged,
              static_cast<int>(stray.size()));
  for (const auto& s : stray) std::printf("  %s\n", s.c_str());
  EXPECT_GE(named, 0.9);
  EXPECT_GE(posed, 0.8);
  // Nothing but the frame's objects is named (the desk's edge was named 040_large_marker).
  EXPECT_EQ(stray.size(), 0u);
}

// Leave-one-out over the database: with the frame's object X removed from the 21 models, X
// (its ground-truth mask) must come out unknown and the frame's other two objects still be named.
TEST_F(Ycb, LeaveOneOutRejectsTheMissingObject) {
  int rejected = 0, cases = 0, named = 0, others = 0;
  for (const std::string& left_out :
       {std::string("009_gelatin_box"), std::string("025_mug"), std::string("061_foam_brick")}) {
    Database db = db_;
    db.views.erase(std::remove_if(db.views.begin(), db.views.end(),
                                  [&](const ModelView& v) { return v.object == left_out; }),
                   db.views.end());
    for (int k = 1; k <= 10; k += kFrameStep) {
      const YcbFrame y = frame(k);
      for (const auto& o : y.objects) {
        const Recognition r =
            recognize(describe_candidate(points_of(y.frame, o.points), db), db, {});
        if (o.name == left_out) {
          ++cases;
          rejected += r.name == "unknown";
          if (r.name != "unknown")
            std::printf("  frame %d: %s left out, named %s (%.3f)\n", k, o.name.c_str(),
                        r.name.c_str(), r.best.score);
        } else {
          ++others;
          named += r.name == o.name;
          if (r.name != o.name)
            std::printf("  frame %d: %s (without %s) named %s (%.3f)\n", k, o.name.c_str(),
                        left_out.c_str(), r.name.c_str(), r.best.score);
        }
      }
    }
  }
  std::printf("left out: %d/%d rejected; the others: %d/%d named\n", rejected, cases, named,
              others);
  EXPECT_EQ(rejected, cases);
  EXPECT_EQ(named, others);
}

// The judge's symmetries: a box's are found whatever its orientation in the model frame,
// including a square prism's, whose principal axes are arbitrary in the square.
std::vector<Eigen::Vector3d> box_surface(const Eigen::Vector3d& size, const Eigen::Matrix3d& turn) {
  std::vector<Eigen::Vector3d> out;
  const double step = 0.002;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (double side : {-0.5, 0.5})
      for (double u = -size[b] / 2; u <= size[b] / 2; u += step)
        for (double v = -size[c] / 2; v <= size[c] / 2; v += step) {
          Eigen::Vector3d p;
          p[a] = side * size[a], p[b] = u, p[c] = v;
          out.push_back(turn * p + Eigen::Vector3d(0.01, -0.02, 0.03));
        }
  }
  return out;
}

TEST(Evaluation, BoxSymmetriesWhateverTheBoxOrientation) {
  const Eigen::Matrix3d turn = (Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX()) *
                                Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitY()))
                                   .toRotationMatrix();
  // A brick with a square cross-section: the 8 turns of a square prism.
  const auto brick = box_surface({0.05, 0.075, 0.05}, turn);
  const auto s8 = box_symmetries(brick, 0.002);
  EXPECT_EQ(s8.size(), 8u);
  // Every one maps the box onto itself: its centre stays, its turn is one of the prism's.
  for (const auto& s : s8) {
    const Eigen::Vector3d centre(0.01, -0.02, 0.03);
    EXPECT_LT((s.topLeftCorner<3, 3>() * centre + s.topRightCorner<3, 1>() - centre).norm(), 1e-3);
  }
  // Three different sides: the identity and the three half turns.
  EXPECT_EQ(box_symmetries(box_surface({0.04, 0.06, 0.08}, turn), 0.002).size(), 4u);
  // A cube: the 24 turns.
  EXPECT_EQ(box_symmetries(box_surface({0.05, 0.05, 0.05}, turn), 0.002).size(), 24u);
}

}  // namespace

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
