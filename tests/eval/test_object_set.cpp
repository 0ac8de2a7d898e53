// The object-varied development set (object_set.hpp): the pool, the object folds, the database
// capture, the generated shapes; and the regression guard of recognition on a few of its scenes
// with the defaults (floors set from what the object folds reach, docs/results.md).
#include <gtest/gtest.h>
#include <proxseg/core/colour.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/eval/object_set.hpp>
#include <proxseg/recognition/recognition.hpp>
#include <proxseg/recognition/visibility.hpp>

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>

using namespace proxseg;

namespace {

const std::string kData = PROXSEG_DATA_DIR;

ObjectPoolParams full_pool() {
  ObjectPoolParams p;
  p.linemod_dir = kData + "/lmo/models";
  p.ycbv_dir = kData + "/ycbv";
  p.textured_dir = kData + "/ycb_textured";
  return p;
}

const std::vector<PoolObject>& pool() {
  static const std::vector<PoolObject> objects = object_pool(full_pool());
  return objects;
}

// One scene object recognised again on its own under other parameters, as recognize_scene()
// recognised it (its points described with their colours, the frame's depths for free space).
Recognition recognize_again(const ClutterScene& scene, const SceneObject& o, const Database& db,
                            const RecognitionParams& params) {
  std::vector<Eigen::Vector3d> xyz;
  std::vector<Rgb> rgb;
  for (int i : o.points) {
    xyz.push_back(scene.frame.xyz[i].cast<double>());
    rgb.push_back(scene.frame.rgb[i]);
  }
  const DepthImage depths = depth_image(scene.frame);
  return recognize(describe_candidate(xyz, db, &rgb), db, params, {}, {&depths});
}

}  // namespace

TEST(ObjectSet, PoolHasManyKindsInTwoHalvesWithGroupsKeptTogether) {
  const std::vector<PoolObject>& p = pool();
  std::map<std::string, std::set<int>> group_halves;
  std::set<std::string> names, families;
  int halves[2] = {0, 0};
  for (const PoolObject& o : p) {
    EXPECT_TRUE(names.insert(o.entry.name).second) << "duplicate " << o.entry.name;
    families.insert(o.family);
    ASSERT_TRUE(o.half == 0 || o.half == 1);
    ++halves[o.half];
    if (!o.group.empty()) group_halves[o.group].insert(o.half);
    ASSERT_FALSE(o.entry.mesh.vertices.empty()) << o.entry.name;
    EXPECT_EQ(o.entry.mesh.colours.size(), o.entry.mesh.vertices.size()) << o.entry.name;
  }
  EXPECT_EQ(p.size(), 51u);
  EXPECT_EQ(families.size(), 4u);  // linemod, ycb, scan, generated
  EXPECT_GE(halves[0], 13);
  EXPECT_GE(halves[1], 13);
  for (const auto& [group, in] : group_halves) EXPECT_EQ(in.size(), 1u) << group;
}

// The YCB-Video shapes come without colour and are painted by generated_paint(): a base colour of
// saturation 0.35-0.9 and value 0.3-0.95, so each must come out coloured and unlike the others
// (until 2026-12 they were all near white: the paint's 0..1 -> 0..255 scale was applied twice).
TEST(ObjectSet, YcbShapesArePaintedInColoursOfTheirOwn) {
  std::vector<Eigen::Vector3d> means;
  for (const PoolObject& o : pool()) {
    if (o.family != "ycb") continue;
    Eigen::Vector3d hsv_sum = Eigen::Vector3d::Zero(), rgb_sum = Eigen::Vector3d::Zero();
    for (const Rgb& c : o.entry.mesh.colours) {
      hsv_sum += rgb_to_hsv(c);
      rgb_sum += Eigen::Vector3d(c[0], c[1], c[2]);
    }
    const double n = static_cast<double>(o.entry.mesh.colours.size());
    EXPECT_GT(hsv_sum[1] / n, 0.1) << o.entry.name << ": grey or white";
    means.push_back(rgb_sum / n);
  }
  ASSERT_EQ(means.size(), 19u);
  int alike = 0;
  for (std::size_t a = 0; a < means.size(); ++a)
    for (std::size_t b = a + 1; b < means.size(); ++b) alike += (means[a] - means[b]).norm() < 20;
  EXPECT_LE(alike, 3);  // of 171 pairs
}

TEST(ObjectSet, EveryObjectIsUnknownInOneFoldOfItsHalf) {
  ObjectFoldParams fp;
  fp.known = 9;
  fp.unknown = 4;
  const std::vector<ObjectFold> folds = object_folds(pool(), fp);
  std::map<int, int> unknown_count;
  for (const ObjectFold& f : folds) {
    EXPECT_EQ(f.known.size(), 9u);
    EXPECT_EQ(f.unknown.size(), 4u);
    std::set<int> all(f.known.begin(), f.known.end());
    for (int u : f.unknown) EXPECT_TRUE(all.insert(u).second) << f.name << ": known and unknown";
    for (int i : all) EXPECT_EQ(pool()[i].half, f.half) << f.name;
    for (int u : f.unknown) ++unknown_count[u];
    const SceneCatalogue c = fold_catalogue(pool(), f);
    ASSERT_EQ(c.entries.size(), 13u);
    EXPECT_EQ(std::count(c.known.begin(), c.known.end(), 1), 9);
    EXPECT_EQ(c.entries[0].name, pool()[f.known[0]].entry.name);  // known entries first
  }
  for (std::size_t i = 0; i < pool().size(); ++i)
    EXPECT_GE(unknown_count[static_cast<int>(i)], 1) << pool()[i].entry.name;
  fp.known = 100;
  EXPECT_THROW(object_folds(pool(), fp), InputError);
}

TEST(ObjectSet, DatabaseViewsAreCapturedUnlikeTheMesh) {
  ObjectFold f;
  f.known = {0, 1};
  const SceneCatalogue c = fold_catalogue(pool(), f);
  CaptureParams cp;
  cp.views = 3;
  const Database db = captured_database(c, cp, DescriptorParams{});
  ASSERT_EQ(db.views.size(), 6u);
  EXPECT_EQ(db.views[0].object, c.entries[0].name);
  EXPECT_EQ(db.views[5].object, c.entries[1].name);
  for (const ModelView& v : db.views) {
    EXPECT_GT(v.cloud().size(), 100u);
    EXPECT_EQ(v.cloud().colours.size(), v.cloud().size());
  }
  // Seeded: the same capture twice is the same database.
  const Database again = captured_database(c, cp, DescriptorParams{});
  EXPECT_EQ(again.views[4].cloud().points, db.views[4].cloud().points);
  EXPECT_EQ(again.views[4].cloud().colours, db.views[4].cloud().colours);
}

TEST(ObjectSet, LatheShapesAreClosedAndCupsOpen) {
  // A fruit seen from anywhere shows no hole; a cup seen from above shows its inside, lower
  // than its rim.
  const auto find = [](const std::string& name) {
    for (const PoolObject& o : pool())
      if (o.entry.name == name) return o.entry.mesh;
    ADD_FAILURE() << name;
    return Mesh{};
  };
  ViewSphereParams vp;
  vp.views = 6;
  vp.distance = 0.5;
  for (const RenderedView& v : render_views(find("apple"), vp)) EXPECT_GT(v.points.size(), 1500u);
  const Mesh cup = find("cup-white");
  RenderParams rp;
  rp.camera_from_world = look_at({0, 0, 0.6}, {0, 0, 0.045});
  const Frame top = render({cup}, rp);
  float lowest = 1e9f, highest = -1e9f;
  const Eigen::Isometry3d world = rp.camera_from_world.inverse();
  for (std::size_t i = 0; i < top.size(); ++i)
    if (top.valid(i)) {
      const float z = static_cast<float>((world * top.xyz[i].cast<double>()).z());
      lowest = std::min(lowest, z), highest = std::max(highest, z);
    }
  EXPECT_NEAR(highest, 0.09, 0.003);  // the rim
  EXPECT_LT(lowest, 0.01);            // the inside bottom, seen through the opening
}

// The regression guard: segment() + recognize_scene() with the defaults on the first fold of
// each half, two scenes each (dev seeds), scored like scene_bench --set objects. The floors are
// below what these scenes reach (docs/results.md, "Recognition on the object folds").
TEST(ObjectSet, DefaultsRecognizeTheFirstFoldOfEachHalf) {
  const std::vector<PoolObject>& objects = pool();
  const std::vector<ObjectFold> folds = object_folds(objects, ObjectFoldParams{});
  SceneCounts total;
  for (int half = 0; half < 2; ++half) {
    const auto fold = std::find_if(folds.begin(), folds.end(),
                                   [&](const ObjectFold& f) { return f.half == half; });
    ASSERT_NE(fold, folds.end());
    const SceneCatalogue catalogue = fold_catalogue(objects, *fold);
    const Database db = captured_database(catalogue, CaptureParams{}, DescriptorParams{});
    for (std::uint32_t seed : {1u, 2u}) {
      const ClutterScene scene =
          clutter_layout_scene(scene_set_params(seed, catalogue, SceneSetParams{}));
      const SegmentResult s = segment(scene.frame, SegmentParams{});
      const std::vector<SceneObject> found =
          recognize_scene(scene.frame, s.selection, db, RecognitionParams{});
      const SceneEvaluation e =
          evaluate_scene(seed, scene_truth(scene, catalogue), predictions_of(found), catalogue);
      std::printf(
          "%s seed %u: %d/%d known named, %d FP, %d/%d unknown named, %d known "
          "called unknown\n",
          fold->name.c_str(), seed, e.counts.tp, e.counts.known, e.counts.fp,
          e.counts.unknown_named, e.counts.unknown, e.counts.known_unknown);
      total += e.counts;
    }
  }
  std::printf("F1 %.3f, unknown named %.3f, known called unknown %.3f, pose %.3f\n", total.f1(),
              total.unknown_named_share(), total.known_unknown_share(), total.pose_rate());
  // Reached with the defaults (docs/method.md "Recognition that generalises"): F1 1.0 (17 of 17
  // known named, no FP), no unknown named (0 of 21), every pose right. Floors a step below.
  EXPECT_GE(total.f1(), 0.94);
  EXPECT_LE(total.unknown_named_share(), 0.05);
  EXPECT_LE(total.known_unknown_share(), 0.1);
  EXPECT_GE(total.pose_rate(), 0.9);
}

// The lone match (RecognitionParams::lone_score) on the first scene of fold A1: the banana's
// candidate scores under the minimum score (its textured skin agrees at ~0.75 with the database's
// differently lit views) while no other object's view comes near it; the lone match names it,
// and without the rule it is "unknown".
TEST(ObjectSet, LoneMatchNamesTheBananaOfTheFirstScene) {
  const std::vector<PoolObject>& objects = pool();
  const std::vector<ObjectFold> folds = object_folds(objects, ObjectFoldParams{});
  const SceneCatalogue catalogue = fold_catalogue(objects, folds.front());
  const Database db = captured_database(catalogue, CaptureParams{}, DescriptorParams{});
  const ClutterScene scene = clutter_layout_scene(scene_set_params(1, catalogue, SceneSetParams{}));
  const SegmentResult s = segment(scene.frame, SegmentParams{});
  const RecognitionParams p;
  int lone = 0;
  for (const SceneObject& o : recognize_scene(scene.frame, s.selection, db, p)) {
    const Recognition& r = o.recognition;
    if (r.best.object != "banana") continue;
    std::printf("banana: %s at %.3f, runner-up %.3f\n", r.name.c_str(), r.best.score,
                r.runner_up.score);
    if (r.best.score >= p.min_score) continue;
    EXPECT_EQ(r.name, "banana");
    EXPECT_GE(r.best.score, p.lone_score);
    EXPECT_LE(r.runner_up.score, p.lone_ratio * r.best.score);
    ++lone;
    // The same candidate without the rule: the same alignments (one seed), "unknown".
    RecognitionParams off = p;
    off.lone_score = 0;
    const Recognition without = recognize_again(scene, o, db, off);
    EXPECT_EQ(without.best.object, "banana");
    EXPECT_NEAR(without.best.score, r.best.score, 1e-9);
    EXPECT_EQ(without.name, "unknown");
  }
  EXPECT_EQ(lone, 1);
}

// The look-alike vote (RecognitionParams::lookalike_share) on fold B4's second dev scene: the
// yellow bowl seen from above shows its white inside, which the green bowl shares, and the green
// bowl's view scores a little higher (0.86 against 0.84: without the vote it would be named, as
// that is over the confident score). On the sliver of outer wall that shows, where the two
// models' colours differ, the candidate's points vote for the yellow bowl. The candidate is the
// one the selection cut before the edge-aware normals (5 px normals and creases, plain box
// filter): with today's default the bowl's candidate has 50 more points of its surroundings, the
// yellow bowl's view is not shortlisted and the green one is named without a vote (noted in
// docs/method.md, "Steps after the edge-aware smoothing"); this test is about the vote.
TEST(ObjectSet, LookalikeVoteTellsTheYellowBowlFromTheGreen) {
  const std::vector<PoolObject>& objects = pool();
  const std::vector<ObjectFold> folds = object_folds(objects, ObjectFoldParams{});
  const auto b4 =
      std::find_if(folds.begin(), folds.end(), [](const ObjectFold& f) { return f.name == "B4"; });
  ASSERT_NE(b4, folds.end());
  const SceneCatalogue catalogue = fold_catalogue(objects, *b4);
  const Database db = captured_database(catalogue, CaptureParams{}, DescriptorParams{});
  const ClutterScene scene =
      clutter_layout_scene(scene_set_params(9002, catalogue, SceneSetParams{}));
  std::uint32_t yellow = 0;
  for (const auto& t : scene.objects)
    if (t.name == "bowl-yellow") yellow = t.label;
  ASSERT_NE(yellow, 0u);
  SegmentParams before;
  before.selection.image.normal_step = before.selection.image.concavity_step = 5;
  before.selection.image.edge_aware_normals = false;
  const SegmentResult s = segment(scene.frame, before);
  // The vote as it was measured, before the occlusion rule: with hidden_depth at its default
  // (3 cm) the green bowl ranks first here (0.88 against 0.86), the vote finds under its 10 votes
  // and the yellow bowl is named bowl-green (issue 51's closing note).
  RecognitionParams p;
  p.hidden_depth = 0;
  int voted = 0;
  for (const SceneObject& o : recognize_scene(scene.frame, s.selection, db, p)) {
    const Recognition& r = o.recognition;
    if (!r.lookalike_decided) continue;
    ++voted;
    std::printf("%s at %.3f, runner-up %s %.3f, votes %d : %d\n", r.name.c_str(), r.best.score,
                r.runner_up.object.c_str(), r.runner_up.score, r.lookalike.first,
                r.lookalike.second);
    const auto on_yellow = std::count_if(o.points.begin(), o.points.end(),
                                         [&](int i) { return scene.frame.label[i] == yellow; });
    EXPECT_GT(on_yellow, 0.8 * o.points.size());
    EXPECT_EQ(r.name, "bowl-yellow");
    EXPECT_EQ(r.runner_up.object, "bowl-green");
    EXPECT_LT(r.best.score, r.runner_up.score);  // the vote, not the score, chose it
    EXPECT_GE(r.lookalike.first, p.lookalike_share * (r.lookalike.first + r.lookalike.second));
    // Without the vote: the green bowl, named by its confident score.
    RecognitionParams off = p;
    off.lookalike_share = 0;
    const Recognition without = recognize_again(scene, o, db, off);
    EXPECT_EQ(without.name, "bowl-green");
  }
  EXPECT_EQ(voted, 1);
}
