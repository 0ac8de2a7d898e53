// Colour in recognition [extension, docs/method.md "Colour in recognition"]: chromaticity, the
// colour agreement of aligned views, objects of one shape told apart, look-alikes.
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

// Colour in recognition [extension, docs/method.md "Colour in recognition"].
TEST(Colour, ChromaticityIgnoresBrightnessButNotHue) {
  const Rgb red{200, 40, 30}, dim_red{80, 16, 12}, orange{200, 110, 30}, black{12, 12, 14};
  EXPECT_DOUBLE_EQ(chromaticity_agreement(red, red), 1.0);
  EXPECT_GT(chromaticity_agreement(red, dim_red), 0.8);  // the same paint in shadow
  EXPECT_LT(chromaticity_agreement(red, orange), 0.3);
  EXPECT_LT(chromaticity_agreement(red, black), 0.01);
  EXPECT_GT(chromaticity_agreement(black, Rgb{8, 9, 6}), 0.8);  // sensor noise on black
}

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
