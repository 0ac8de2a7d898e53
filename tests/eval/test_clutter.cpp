// The seeded cluttered tabletop generator (proxseg::clutter_layout_scene, `proxseg synth
// --clutter`): determinism, the mOSD label convention, the ranges of docs/clutter.md, the
// physical invariants of the layout (resting on the support, no interpenetration, touching gaps,
// leaning tilts) and the variety over the 30 first seeds.
#include <gtest/gtest.h>
#include <proxseg/core/errors.hpp>
#include <proxseg/eval/clutter.hpp>
#include <proxseg/eval/scene_eval.hpp>
#include <proxseg/io/cloud_io.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>

#include "support/cli_util.hpp"

using namespace proxseg;

namespace {

namespace fs = std::filesystem;
const std::string kModels = std::string(PROXSEG_DATA_DIR) + "/lmo/models";
const fs::path kTmp = fs::path(PROXSEG_TEST_TMP) / "clutter";

ClutterParams params(std::uint32_t seed) {
  if (!fs::is_directory(kModels)) ADD_FAILURE() << "missing real data: " << kModels;
  ClutterParams p;
  p.seed = seed;
  p.models_dir = kModels;
  return p;
}

bool same_frame(const Frame& a, const Frame& b) {
  return a.width == b.width && a.height == b.height && a.size() == b.size() &&
         std::memcmp(a.xyz.data(), b.xyz.data(), a.size() * sizeof(Eigen::Vector3f)) == 0 &&
         a.rgb == b.rgb && a.label == b.label;
}

// Signed separation of two convex polygons along the edge normals of both: the negated
// penetration depth when they overlap, a lower bound of their distance otherwise.
double separation(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b) {
  double best = -1e300;
  for (int pass = 0; pass < 2; ++pass) {
    const auto& p = pass ? b : a;
    const auto& q = pass ? a : b;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Eigen::Vector2d e = p[(i + 1) % p.size()] - p[i];
      const Eigen::Vector2d n = Eigen::Vector2d(e.y(), -e.x()).normalized();  // outward (CCW)
      double pmax = -1e300, qmin = 1e300;
      for (const auto& v : p) pmax = std::max(pmax, n.dot(v));
      for (const auto& v : q) qmin = std::min(qmin, n.dot(v));
      best = std::max(best, qmin - pmax);
    }
  }
  return best;
}

// Distance of v outside the convex counter-clockwise polygon (<= 0 inside).
double outside(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& v) {
  double d = -1e300;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector2d e = poly[(i + 1) % poly.size()] - poly[i];
    const Eigen::Vector2d n = Eigen::Vector2d(e.y(), -e.x()).normalized();
    d = std::max(d, n.dot(v - poly[i]));
  }
  return d;
}

// Surface points of a box (its corners) or a cylinder (its rims), in the world.
std::vector<Eigen::Vector3d> hull_points(const ClutterObject& o) {
  std::vector<Eigen::Vector3d> pts;
  if (o.kind == ClutterKind::box) {
    for (int c = 0; c < 8; ++c)
      pts.push_back(o.world_from_object * Eigen::Vector3d((c & 1 ? 0.5 : -0.5) * o.size.x(),
                                                          (c & 2 ? 0.5 : -0.5) * o.size.y(),
                                                          (c & 4 ? 0.5 : -0.5) * o.size.z()));
  } else if (o.kind == ClutterKind::cylinder) {
    const double r = o.size.x() / 2, h = o.size.z();
    for (int k = 0; k < 128; ++k) {
      const double a = 2 * M_PI * k / 128;
      for (double z : {-h / 2, h / 2})
        pts.push_back(o.world_from_object * Eigen::Vector3d(r * std::cos(a), r * std::sin(a), z));
    }
  }
  return pts;
}

}  // namespace

TEST(Clutter, SameSeedGivesTheSameSceneBitForBit) {
  const ClutterScene a = clutter_layout_scene(params(5)), b = clutter_layout_scene(params(5));
  EXPECT_TRUE(same_frame(a.frame, b.frame));
  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (std::size_t i = 0; i < a.objects.size(); ++i) {
    EXPECT_EQ(a.objects[i].name, b.objects[i].name);
    EXPECT_EQ(a.objects[i].pose, b.objects[i].pose);
    EXPECT_TRUE(a.objects[i].world_from_object.isApprox(b.objects[i].world_from_object, 0));
  }
  EXPECT_EQ(a.table, b.table);
  EXPECT_EQ(a.layout, b.layout);
  // clutter_scene is the frame of clutter_layout_scene.
  EXPECT_TRUE(same_frame(clutter_scene(params(5)), a.frame));
}

TEST(Clutter, DifferentSeedsGiveDifferentScenes) {
  const Frame a = clutter_scene(params(1)), b = clutter_scene(params(2));
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    differ += a.label[i] != b.label[i] || a.rgb[i] != b.rgb[i];
  EXPECT_GT(differ, a.size() / 4);
}

// The 30 first seeds (the development set's start): every convention and invariant per scene,
// and the variety over them.
TEST(Clutter, ThirtySeedsFollowTheConventionsAndShowEveryKindOfClutter) {
  std::map<std::string, int> tables, kinds, poses, names;
  int touching_pairs = 0;
  double total_s = 0, max_s = 0;
  for (std::uint32_t seed = 1; seed <= 30; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const auto start = std::chrono::steady_clock::now();
    const ClutterScene s = clutter_layout_scene(params(seed));
    const double sec =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    total_s += sec;
    max_s = std::max(max_s, sec);
    const Frame& f = s.frame;
    ASSERT_EQ(f.width, 640);
    ASSERT_EQ(f.height, 480);
    ASSERT_EQ(f.label.size(), f.size());
    const std::size_t n = s.objects.size();
    EXPECT_GE(n, 5u);
    EXPECT_LE(n, 15u);
    ++tables[s.table];

    // Labels: 0 = no return, 1 = table, 10 * (i + 1) for object i = 1..n; counted per object.
    std::map<std::uint32_t, std::size_t> count;
    for (std::size_t i = 0; i < f.size(); ++i) {
      EXPECT_EQ(f.valid(i), f.label[i] != 0) << "pixel " << i;
      if (f.valid(i)) ++count[f.label[i]];
    }
    EXPECT_GT(count[1], f.size() / 4) << "the table fills most of the view";
    std::set<std::uint32_t> labels = {0, 1};
    for (std::size_t i = 0; i < n; ++i) {
      const ClutterObject& o = s.objects[i];
      EXPECT_EQ(o.label, 10 * (i + 2));
      labels.insert(o.label);
      EXPECT_GE(o.visible_points, 400u) << o.label;
      EXPECT_EQ(o.visible_points, count[o.label]) << o.label;
    }
    for (const auto& [label, c] : count)
      EXPECT_TRUE(labels.count(label)) << "stray label " << label;

    // Camera ranges.
    EXPECT_GE((s.eye - s.target).norm(), 0.6 - 1e-9);
    EXPECT_LE((s.eye - s.target).norm(), 1.3 + 1e-9);
    EXPECT_GE(s.elevation_deg, 30 - 1e-9);
    EXPECT_LE(s.elevation_deg, 70 + 1e-9);

    std::map<std::uint32_t, const ClutterObject*> by_label;
    for (const ClutterObject& o : s.objects) by_label[o.label] = &o;
    for (const ClutterObject& o : s.objects) {
      SCOPED_TRACE("object " + std::to_string(o.label) + " " + o.name + " " + to_string(o.pose));
      ++kinds[to_string(o.kind)];
      ++poses[to_string(o.pose)];
      ++names[o.name];
      EXPECT_LE(o.size.maxCoeff(), 0.30 + 1e-9);
      EXPECT_GE(o.size.minCoeff(), 0.012 - 1e-9);
      // The lowest point rests on the support: the table (z = 0) or the top of the box below,
      // with the footprint inside the box's top face.
      if (o.support == 1) {
        EXPECT_NEAR(o.z_min, 0, 1e-5);
      } else {
        ASSERT_TRUE(by_label.count(o.support));
        const ClutterObject& base = *by_label[o.support];
        EXPECT_EQ(o.pose, ClutterPose::stacked);
        EXPECT_EQ(base.kind, ClutterKind::box);
        EXPECT_NE(base.pose, ClutterPose::leaning);
        EXPECT_NEAR(o.z_min, base.z_max, 1e-5);
        for (const auto& v : o.footprint) EXPECT_LE(outside(base.footprint, v), -0.002);
      }
      // Boxes and cylinders: the footprint holds the shape and z_min is its lowest point.
      const auto pts = hull_points(o);
      if (!pts.empty()) {
        double zmin = 1e300;
        for (const auto& p : pts) {
          EXPECT_LE(outside(o.footprint, p.head<2>()), 0.0015);
          zmin = std::min(zmin, p.z());
        }
        EXPECT_NEAR(zmin, o.z_min, 0.0015);
      }
      // Touching is symmetric and within 5 mm.
      for (std::uint32_t t : o.touching) {
        ASSERT_TRUE(by_label.count(t));
        const ClutterObject& other = *by_label[t];
        EXPECT_TRUE(std::count(other.touching.begin(), other.touching.end(), o.label));
        const double sep = separation(o.footprint, other.footprint);
        EXPECT_GE(sep, -1e-6);
        EXPECT_LE(sep, 0.005 + 1e-6);
        touching_pairs += o.label < t;
      }
      if (o.pose == ClutterPose::leaning) {
        EXPECT_GE(o.tilt_deg, 10 - 1e-9);
        EXPECT_LE(o.tilt_deg, 30 + 1e-9);
        const double axis_tilt = std::acos(
            std::clamp((o.world_from_object.linear() * Eigen::Vector3d::UnitZ()).z(), -1.0, 1.0));
        EXPECT_NEAR(axis_tilt * 180 / M_PI, o.tilt_deg, 0.01);
        ASSERT_TRUE(by_label.count(o.neighbour));
        const ClutterObject& nb = *by_label[o.neighbour];
        EXPECT_EQ(nb.kind, ClutterKind::box);
        EXPECT_EQ(nb.support, 1u);
        EXPECT_GE(o.gap, 0);
        EXPECT_LE(o.gap, 0.001 + 1e-9);
        EXPECT_LE(o.z_max, nb.z_max + 0.05) << "rests against the side, below the top";
      } else if (o.neighbour != 0) {  // placed touching
        EXPECT_GE(o.gap, 0);
        EXPECT_LE(o.gap, 0.005 + 1e-9);
        EXPECT_TRUE(std::count(o.touching.begin(), o.touching.end(), o.neighbour));
      }
    }
    // No interpenetration beyond a millimetre: footprints of objects at overlapping heights.
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = i + 1; j < n; ++j) {
        const ClutterObject &a = s.objects[i], &b = s.objects[j];
        if (std::min(a.z_max, b.z_max) - std::max(a.z_min, b.z_min) <= 0.001) continue;
        EXPECT_GE(separation(a.footprint, b.footprint), -0.001) << a.label << " and " << b.label;
      }
  }
  for (const char* t : {"wood", "cloth", "plain"}) EXPECT_EQ(tables[t], 10) << t;  // seed % 3
  for (const char* k : {"mesh", "box", "cylinder"}) EXPECT_GE(kinds[k], 5) << k;
  for (const char* p : {"standing", "lying", "stacked", "leaning"}) EXPECT_GE(poses[p], 1) << p;
  EXPECT_GE(touching_pairs, 1);
  EXPECT_GE(names["marker"] + names["soap bar"], 1);
  std::cout << "30 scenes: mean " << total_s / 30 << " s, max " << max_s << " s; tables";
  for (const auto& [t, c] : tables) std::cout << " " << t << " " << c;
  std::cout << "; poses";
  for (const auto& [p, c] : poses) std::cout << " " << p << " " << c;
  std::cout << "; touching pairs " << touching_pairs << "\n";
#ifndef PROXSEG_SANITIZE
  EXPECT_LT(total_s / 30, 1.0) << "one scene must take well under 1 s";
#endif
}

TEST(Clutter, ObjectCountRangeIsHonouredAtBothEnds) {
  for (int n : {5, 15}) {
    ClutterParams p = params(11);
    p.min_objects = p.max_objects = n;
    const ClutterScene s = clutter_layout_scene(p);
    EXPECT_EQ(s.objects.size(), static_cast<std::size_t>(n));
    for (const ClutterObject& o : s.objects) EXPECT_GE(o.visible_points, 400u);
  }
}

TEST(Clutter, WithoutModelsOnlyBoxesAndCylinders) {
  for (std::uint32_t seed : {1u, 2u, 3u}) {
    ClutterParams p;
    p.seed = seed;
    const ClutterScene s = clutter_layout_scene(p);
    EXPECT_GE(s.objects.size(), 5u);
    for (const ClutterObject& o : s.objects) {
      EXPECT_NE(o.kind, ClutterKind::mesh);
      EXPECT_GE(o.visible_points, 400u);
    }
  }
}

// The scene set's catalogue (scene_eval.hpp): the scene is a pure function of its params, its
// catalogue objects carry their entry (index, name, kind; markers lying, at most 2 of each), and
// world_from_object puts the entry's mesh exactly where the object's points are.
TEST(Clutter, CatalogueObjectsAreTheEntriesInPlace) {
  const SceneCatalogue cat = scene_catalogue(kModels);
  int catalogue_objects = 0, random_objects = 0;
  for (std::uint32_t seed : {3u, 8u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    ClutterParams p = scene_set_params(seed, cat);
    // Exact depths: what is left of the distances below is the mesh's tessellation.
    p.depth_noise = 0;
    p.disparity_step = 0;
    const ClutterScene a = clutter_layout_scene(p), b = clutter_layout_scene(p);
    EXPECT_TRUE(same_frame(a.frame, b.frame));
    ASSERT_EQ(a.objects.size(), b.objects.size());
    EXPECT_GE(a.objects.size(), 8u);
    EXPECT_LE(a.objects.size(), 14u);
    std::map<int, int> instances;
    const Eigen::Isometry3d world_from_camera = a.render.camera_from_world.inverse();
    for (std::size_t i = 0; i < a.objects.size(); ++i) {
      const ClutterObject& o = a.objects[i];
      EXPECT_EQ(o.catalogue, b.objects[i].catalogue);
      if (o.catalogue < 0) {
        ++random_objects;
        EXPECT_NE(o.kind, ClutterKind::mesh) << "mesh_share 0: meshes come from the catalogue";
        continue;
      }
      ++catalogue_objects;
      ASSERT_LT(o.catalogue, static_cast<int>(cat.entries.size()));
      const CatalogueObject& e = cat.entries[static_cast<std::size_t>(o.catalogue)];
      ++instances[o.catalogue];
      EXPECT_EQ(o.name, e.name);
      EXPECT_EQ(o.kind, e.kind);
      EXPECT_EQ(o.texture, "catalogue");
      if (e.lies) {
        EXPECT_EQ(o.pose, ClutterPose::lying) << e.name;
      }
      // Distance of (a sample of) the object's rendered points to the nearest vertex of the mesh
      // put in place, and to the mesh put 2 cm further from the camera (which must be far worse:
      // along the view, no surface slides into itself).
      const Eigen::Vector3d away = (o.world_from_object.translation() - a.eye).normalized() * 0.02;
      std::vector<Eigen::Vector3d> placed, shifted;
      for (const auto& v : e.mesh.vertices) {
        placed.push_back(o.world_from_object * v.cast<double>());
        shifted.push_back(placed.back() + away);
      }
      std::vector<int> pts;
      for (std::size_t k = 0; k < a.frame.size(); ++k)
        if (a.frame.valid(k) && a.frame.label[k] == o.label) pts.push_back(static_cast<int>(k));
      ASSERT_EQ(pts.size(), o.visible_points);
      std::vector<double> d, d_off;
      for (std::size_t s = 0; s < pts.size(); s += std::max<std::size_t>(1, pts.size() / 200)) {
        const Eigen::Vector3d w = world_from_camera * a.frame.xyz[pts[s]].cast<double>();
        double best = 1e300, best_off = 1e300;
        for (std::size_t v = 0; v < placed.size(); ++v) {
          best = std::min(best, (placed[v] - w).squaredNorm());
          best_off = std::min(best_off, (shifted[v] - w).squaredNorm());
        }
        d.push_back(std::sqrt(best));
        d_off.push_back(std::sqrt(best_off));
      }
      std::sort(d.begin(), d.end());
      std::sort(d_off.begin(), d_off.end());
      EXPECT_LT(d[d.size() / 2], 0.002) << e.name;
      EXPECT_LT(d[d.size() * 95 / 100], 0.004) << e.name;
      EXPECT_GT(d_off[d_off.size() / 2], 0.005) << e.name;
    }
    for (const auto& [entry, n] : instances) EXPECT_LE(n, 2) << cat.entries[entry].name;
  }
  EXPECT_GE(catalogue_objects, 8);
  EXPECT_GE(random_objects, 1);
}

TEST(Clutter, BadModelsFolderOrParamsAreRejected) {
  ClutterParams p;
  p.models_dir = "/nonexistent/lmo/models";
  EXPECT_THROW(clutter_layout_scene(p), InputError);
  fs::create_directories(kTmp / "empty");
  p.models_dir = (kTmp / "empty").string();
  EXPECT_THROW(clutter_layout_scene(p), InputError);
  ClutterParams q;
  q.min_objects = 9;
  q.max_objects = 8;
  EXPECT_THROW(clutter_layout_scene(q), proxseg::InputError);
}

// The kinds of the development sets: piles put boxes face to face (turned by a multiple of 90
// degrees from the box beside them, within a footprint gap of 2 mm); the occlusion kind looks
// from low (12-30 degrees) and puts objects in front of others, so that some are seen in pieces.
TEST(Clutter, PilesAndOcclusionKinds) {
  int flush = 0, low = 0, in_front = 0;
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    ClutterParams piles = clutter_kind("piles");
    piles.seed = seed;
    piles.models_dir = kModels;
    const ClutterScene a = clutter_layout_scene(piles);
    for (const ClutterObject& o : a.objects) {
      if (o.kind != ClutterKind::box || o.neighbour == 0 || o.pose == ClutterPose::leaning)
        continue;
      const ClutterObject& nb = a.objects[o.neighbour / 10 - 2];
      if (nb.kind != ClutterKind::box || o.gap > 0.002 + 1e-9) continue;
      const Eigen::Vector3d x = o.world_from_object.linear().col(0),
                            y = nb.world_from_object.linear().col(0);
      const double turn = std::atan2(x.y(), x.x()) - std::atan2(y.y(), y.x());
      const double off = std::remainder(turn, M_PI / 2) * 180 / M_PI;
      flush += std::abs(off) <= 1.0 + 1e-6;
    }
    ClutterParams occlusion = clutter_kind("occlusion");
    occlusion.seed = seed;
    occlusion.models_dir = kModels;
    const ClutterScene b = clutter_layout_scene(occlusion);
    low += b.elevation_deg >= 12 && b.elevation_deg <= 30;
    for (const ClutterObject& o : b.objects) in_front += o.neighbour != 0 && o.gap >= 0.02 - 1e-9;
  }
  EXPECT_GE(flush, 6);
  EXPECT_EQ(low, 6);
  EXPECT_GE(in_front, 6);
  EXPECT_THROW(clutter_kind("heap"), InputError);
  // The default kind is the generator's defaults: the development set is unchanged.
  ClutterParams plain = clutter_kind("clutter");
  plain.seed = 3;
  plain.models_dir = kModels;
  EXPECT_EQ(clutter_scene(plain).label, clutter_scene(params(3)).label);
}

TEST(ClutterCli, WritesOneSceneOrANumberedFolder) {
  using namespace cli_test;
  const fs::path one = kTmp / "one.pcd", dir = kTmp / "batch";
  fs::remove_all(dir);
  CliRun r = run_in(kTmp, "synth --clutter --seed 4 --models " + kModels + " -o " + one.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("objects"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("valid points"), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  const Frame read = read_pcd(one.string());
  const Frame made = clutter_scene(params(4));
  EXPECT_EQ(read.width, 640);
  EXPECT_EQ(read.height, 480);
  EXPECT_EQ(read.label, made.label);
  EXPECT_EQ(read.rgb, made.rgb);

  r = run_in(
      kTmp, "synth --clutter --count 3 --first-seed 9 --models " + kModels + " -o " + dir.string());
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* name : {"clutter-009.pcd", "clutter-010.pcd", "clutter-011.pcd"})
    EXPECT_TRUE(fs::exists(dir / name)) << name;
  EXPECT_FALSE(fs::exists(dir / "clutter-012.pcd"));
  EXPECT_NE(r.err.find("3/3"), std::string::npos) << r.err;  // progress on stderr
  EXPECT_EQ(read_pcd((dir / "clutter-010.pcd").string()).label, clutter_scene(params(10)).label);

  // --kind names the files after the kind and draws its scenes.
  r = run_in(kTmp, "synth --clutter --kind piles --count 1 --first-seed 2 --models " + kModels +
                       " -o " + dir.string());
  ASSERT_EQ(r.code, 0) << r.err;
  ClutterParams piles = clutter_kind("piles");
  piles.seed = 2;
  piles.models_dir = kModels;
  EXPECT_EQ(read_pcd((dir / "piles-002.pcd").string()).label, clutter_scene(piles).label);
  EXPECT_EQ(run_in(kTmp, "synth --clutter --kind heap -o " + one.string()).code, 2);
}

TEST(ClutterCli, BadArgumentsExitWithUsageOrInputErrors) {
  using namespace cli_test;
  const fs::path out = kTmp / "bad.pcd";
  fs::remove(out);
  EXPECT_EQ(run_in(kTmp, "synth --count 2 -o " + out.string()).code, 2);  // needs --clutter
  EXPECT_EQ(run_in(kTmp, "synth --clutter --count 0 -o " + out.string()).code, 2);
  EXPECT_EQ(run_in(kTmp, "synth --clutter --count 2 --seed 3 -o " + out.string()).code, 2);
  EXPECT_EQ(run_in(kTmp, "synth --clutter --first-seed 3 -o " + out.string()).code, 2);
  EXPECT_EQ(run_in(kTmp, "synth --models " + kModels + " -o " + out.string()).code, 2);
  EXPECT_EQ(run_in(kTmp, "synth --clutter --seed x -o " + out.string()).code, 2);
  const CliRun r = run_in(kTmp, "synth --clutter --models /nonexistent/models -o " + out.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("/nonexistent/models"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out));
}
