// Physical support (support.hpp): the support plane of a selection, the other objects' surfaces
// over it, and how a posed model stands: on the plane, on another object, in the air, through
// the plane.
#include <proxseg/recognition/support.hpp>

#include <gtest/gtest.h>

#include <cmath>

namespace proxseg {
namespace {

// A sensor at the origin looking along +z at a table 1 m away (height over it: 1 - z), a box top
// 10 cm over the table (x, y in [0, 0.1]) and a candidate: a patch 10-15 cm over the table at
// x, y in [-0.2, -0.1].
struct TableScene {
  Frame frame;
  Selection selection;
  std::vector<int> candidate;
  TableScene() {
    const auto add = [&](Candidate& c, const Eigen::Vector3f& p) {
      c.points.push_back(static_cast<int>(frame.xyz.size()));
      frame.xyz.push_back(p);
    };
    Candidate table, box, patch;
    table.background = true;
    for (float x = -0.3f; x <= 0.3f; x += 0.005f)
      for (float y = -0.3f; y <= 0.3f; y += 0.005f) add(table, {x, y, 1.0f});
    for (float x = 0.f; x <= 0.1f; x += 0.005f)
      for (float y = 0.f; y <= 0.1f; y += 0.005f) add(box, {x, y, 0.9f});
    for (float x = -0.2f; x <= -0.1f; x += 0.005f)
      for (float y = -0.2f; y <= -0.1f; y += 0.005f) add(patch, {x, y, 0.9f - 0.5f * (x + 0.2f)});
    candidate = patch.points;
    selection.components = {table, box, patch};
    frame.width = static_cast<int>(frame.xyz.size());
    frame.height = 1;
  }
};

// A 4 cm cube's corners and face centres, its bottom (the face towards +z, away from the
// sensor) at `bottom` over the table, centred at (x, y).
Cloud cube() {
  Cloud c;
  for (double a : {-0.02, 0.0, 0.02})
    for (double b : {-0.02, 0.0, 0.02})
      for (double h : {0.0, 0.04}) c.points.emplace_back(a, b, -h);
  return c;
}
Eigen::Matrix4d at(double x, double y, double bottom) {
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  pose.topRightCorner<3, 1>() = Eigen::Vector3d(x, y, 1.0 - bottom);
  return pose;
}

TEST(Support, PlaneOfTheLargestBackground) {
  const TableScene s;
  const SupportPlane plane = support_plane(s.frame, s.selection);
  ASSERT_FALSE(plane.empty());
  EXPECT_NEAR(plane.normal.z(), -1.0, 1e-9);  // towards the sensor
  EXPECT_NEAR(plane.height(Eigen::Vector3d(0, 0, 0.9)), 0.1, 1e-6);
  Selection none = s.selection;
  none.components[0].background = false;
  EXPECT_TRUE(support_plane(s.frame, none).empty());
}

TEST(Support, StandsFloatsSinksOrRestsOnAnotherObject) {
  const TableScene s;
  const SupportScene scene =
      support_scene(s.frame, s.selection, support_plane(s.frame, s.selection));
  const std::vector<float> others = surfaces_around(scene, s.candidate);
  Cloud candidate;
  for (int p : s.candidate) candidate.points.push_back(s.frame.xyz[p].cast<double>());
  const Cloud model = cube();
  const auto stance_at = [&](double x, double y, double bottom) {
    return stance(scene, others, candidate, model, at(x, y, bottom), 0.03);
  };
  EXPECT_EQ(stance_at(-0.15, -0.15, 0.01).stance, Stance::kStands);  // on the table
  EXPECT_NEAR(stance_at(-0.15, -0.15, 0.01).bottom, 0.01, 1e-6);
  EXPECT_EQ(stance_at(-0.15, -0.15, -0.02).stance, Stance::kStands);  // within the gap
  EXPECT_EQ(stance_at(-0.15, -0.15, 0.06).stance, Stance::kFloats);   // over the bare table
  EXPECT_EQ(stance_at(-0.15, -0.15, -0.06).stance, Stance::kSinks);   // through it
  EXPECT_EQ(stance_at(0.05, 0.05, 0.11).stance, Stance::kStands);     // on the box
  EXPECT_EQ(stance_at(0.05, 0.05, 0.20).stance, Stance::kFloats);     // high over the box
  // The candidate's own points hold nothing up: a model over them floats.
  EXPECT_EQ(stance_at(-0.15, -0.15, 0.12).stance, Stance::kFloats);
  const std::vector<float> all = surfaces_around(scene, {});
  EXPECT_EQ(stance(scene, all, candidate, model, at(-0.15, -0.15, 0.12), 0.03).stance,
            Stance::kStands);
}

TEST(Support, NotJudgedOffTheTableOrWithoutOne) {
  const TableScene s;
  const SupportScene scene =
      support_scene(s.frame, s.selection, support_plane(s.frame, s.selection));
  const Cloud model = cube();
  Cloud below;  // a candidate beyond the table's edge, lower than its plane
  below.points.emplace_back(0.5, 0.5, 1.2);
  EXPECT_EQ(stance(scene, {}, below, model, at(0.5, 0.5, 0.1), 0.03).stance, Stance::kStands);
  Cloud candidate;
  candidate.points.emplace_back(-0.15, -0.15, 0.9);
  EXPECT_EQ(stance(SupportScene{}, {}, candidate, model, at(-0.15, -0.15, 0.3), 0.03).stance,
            Stance::kStands);
  EXPECT_TRUE(std::isnan(stance(SupportScene{}, {}, candidate, model, at(0, 0, 0.3), 0.03).bottom));
}

}  // namespace
}  // namespace proxseg
