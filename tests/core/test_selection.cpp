// Selection [paper 3.3]: clusters, weak links, Euclidean split, candidates, background, boxes.
#include <proxseg/core/render.hpp>
#include <proxseg/core/selection.hpp>
#include "core/image_selection_detail.hpp"

#include "util/nearest_points.hpp"
#include "util/parallel_for.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <algorithm>
#include <atomic>
#include <map>
#include <set>
#include <stdexcept>

namespace {

using proxseg::Frame;
using proxseg::SelectionParams;

// A cloud of sampled surfaces; label per point. Unorganized, so densities are not range-scaled.
struct Builder {
  Frame frame;
  std::vector<std::uint32_t> labels;
  void add(const Eigen::Vector3f& p, std::uint32_t label) {
    frame.xyz.push_back(p);
    frame.rgb.push_back({128, 128, 128});
    labels.push_back(label);
  }
  // A rectangle origin + s*u + t*v, s in [0, su], t in [0, sv], sampled every `step`.
  void patch(const Eigen::Vector3f& origin, const Eigen::Vector3f& u, const Eigen::Vector3f& v,
             float su, float sv, float step, std::uint32_t label) {
    for (float s = 0; s <= su + 1e-6f; s += step)
      for (float t = 0; t <= sv + 1e-6f; t += step) add(origin + s * u + t * v, label);
  }
  // The outside of an axis-aligned box [lo, hi], seen from every side.
  void box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, float step, std::uint32_t label) {
    const Eigen::Vector3f d = hi - lo, x = Eigen::Vector3f::UnitX(), y = Eigen::Vector3f::UnitY(),
                          z = Eigen::Vector3f::UnitZ();
    patch(lo, x, y, d.x(), d.y(), step, label);
    patch(Eigen::Vector3f(lo.x(), lo.y(), hi.z()), x, y, d.x(), d.y(), step, label);
    patch(lo, x, z, d.x(), d.z(), step, label);
    patch(Eigen::Vector3f(lo.x(), hi.y(), lo.z()), x, z, d.x(), d.z(), step, label);
    patch(lo, y, z, d.y(), d.z(), step, label);
    patch(Eigen::Vector3f(hi.x(), lo.y(), lo.z()), y, z, d.y(), d.z(), step, label);
  }
  proxseg::Selection select(const SelectionParams& params = {}) {
    frame.width = static_cast<int>(frame.xyz.size());
    frame.height = 1;
    const proxseg::VoxelGrid grid = proxseg::build_voxels(frame, 0.02);
    // As in the pipeline, every point of a voxel has one label: the label of its first point.
    std::vector<std::uint32_t> voxel_labels(frame.size());
    for (std::size_t v = 0; v < grid.size(); ++v)
      for (int p : grid.points[v]) voxel_labels[p] = labels[grid.points[v][0]];
    return proxseg::select_candidates(frame, grid, voxel_labels, params);
  }
};

SelectionParams small_objects() {
  SelectionParams p;
  p.min_candidate_points = 50;
  p.split_concave = p.voxels.merge_convex = p.cut_support_plane = p.absorb_small = true;
  return p;
}

}  // namespace

TEST(Selection, SameLabelApartBecomesTwoCandidates) {
  Builder b;
  b.box({0, 0, 1}, {0.1f, 0.1f, 1.1f}, 0.004f, 1);
  b.box({0.3f, 0, 1}, {0.4f, 0.1f, 1.1f}, 0.004f, 1);
  const auto s = b.select(small_objects());
  ASSERT_EQ(s.components.size(), 2u);
  EXPECT_EQ(s.clusters, 2);
  for (const auto& c : s.components) EXPECT_FALSE(c.background);
  // Instances are numbered by smallest point index: the first box is instance 1.
  EXPECT_EQ(s.instance.front(), 1u);
  EXPECT_EQ(s.instance.back(), 2u);
}

TEST(Selection, DifferentLabelsTouchingStayApartWithoutMerging) {
  Builder b;
  b.patch({0, 0, 1}, Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitY(), 0.1f, 0.1f, 0.004f, 1);
  b.patch({0.104f, 0, 1}, Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitY(), 0.1f, 0.1f, 0.004f,
          2);
  SelectionParams p = small_objects();
  p.voxels.merge_convex = false;
  const auto s = b.select(p);
  EXPECT_EQ(s.components.size(), 2u);
  // Coplanar neighbours meet in a flat boundary: with merging they become one component.
  p.voxels.merge_convex = true;
  EXPECT_EQ(b.select(p).components.size(), 1u);
}

TEST(Selection, WeakBridgeIsCutAndItsPointsGiveBack) {
  // Two dense patches joined by a sparse line of points (one every 6 mm): the line is weak, the
  // patches come apart, and the line's points join the nearest patch instead of being lost.
  Builder b;
  b.patch({0, 0, 1}, Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitY(), 0.1f, 0.1f, 0.002f, 1);
  b.patch({0.16f, 0, 1}, Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitY(), 0.1f, 0.1f, 0.002f, 1);
  for (float x = 0.106f; x < 0.157f; x += 0.006f) b.add({x, 0.05f, 1}, 1);
  SelectionParams p = small_objects();
  p.cluster_tolerance = 0.008;  // the bridge spacing (6 mm) would connect without the density cut
  p.voxels.merge_convex = p.cut_support_plane = p.split_concave = false;
  const auto s = b.select(p);
  EXPECT_EQ(s.clusters, 1);
  ASSERT_EQ(s.components.size(), 2u);
  EXPECT_GT(s.weak_points, 0u);
  std::size_t assigned = 0;
  for (std::uint32_t i : s.instance) assigned += i != 0;
  EXPECT_EQ(assigned, b.frame.size());
  // Without the density test the bridge keeps them together.
  p.weak_density_ratio = 0;
  EXPECT_EQ(b.select(p).components.size(), 1u);
}

TEST(Selection, SmallComponentsAreNotCandidates) {
  Builder b;
  b.box({0, 0, 1}, {0.1f, 0.1f, 1.1f}, 0.004f, 1);
  b.patch({0.5f, 0, 1}, Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitY(), 0.02f, 0.02f, 0.004f,
          1);  // 36 points
  SelectionParams p = small_objects();
  p.absorb_small = false;
  const auto s = b.select(p);
  ASSERT_EQ(s.components.size(), 1u);
  EXPECT_EQ(s.instance.back(), 0u);
}

TEST(Selection, TableIsBackgroundAndObjectsComeOffIt) {
  // The sensor at the origin looks along +z at a 60 x 60 cm table 40 cm below it (plane y = 0.4,
  // y pointing down) with a 10 cm box standing on it, everything one label and only the surfaces
  // the sensor sees: the support plane is cut out, so the box is a candidate and the table the
  // background.
  Builder b;
  const Eigen::Vector3f x = Eigen::Vector3f::UnitX(), y = Eigen::Vector3f::UnitY(),
                        z = Eigen::Vector3f::UnitZ();
  for (float s = 0; s <= 0.6f; s += 0.005f)
    for (float t = 0; t <= 0.6f; t += 0.005f) {
      const Eigen::Vector3f p(-0.3f + s, 0.4f, 0.7f + t);
      if (std::abs(p.x()) > 0.05f || p.z() < 0.95f || p.z() > 1.05f) b.add(p, 1);
    }
  b.patch({-0.05f, 0.3f, 0.95f}, x, y, 0.1f, 0.1f, 0.004f, 1);  // front face
  b.patch({-0.05f, 0.3f, 0.95f}, x, z, 0.1f, 0.1f, 0.004f, 1);  // top face
  const auto s = b.select(small_objects());
  int background = 0, objects = 0;
  for (const auto& c : s.components) {
    if (c.background) {
      ++background;
      EXPECT_NEAR(c.box.extent[0], 0.6, 0.05);
      EXPECT_NEAR(c.box.extent[2], 0.0, 0.01);
    } else {
      ++objects;
      EXPECT_NEAR(c.centroid.y(), 0.33, 0.03) << c.points.size() << " " << c.centroid.transpose();
    }
  }
  EXPECT_EQ(background, 1);
  EXPECT_EQ(objects, 1);
  // Without the plane cut and the concavity split (the paper's selection), they are one cluster.
  SelectionParams p = small_objects();
  p.cut_support_plane = false;
  p.split_concave = false;
  EXPECT_EQ(b.select(p).components.size(), 1u);
}

TEST(Selection, OrientedBoxOfABox) {
  Builder b;
  b.box({0, 0, 1}, {0.2f, 0.1f, 1.05f}, 0.005f, 1);
  b.frame.width = static_cast<int>(b.frame.size());
  b.frame.height = 1;
  std::vector<int> all(b.frame.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  const auto box = proxseg::oriented_box(b.frame, all);
  EXPECT_NEAR(box.extent[0], 0.2, 1e-4);
  EXPECT_NEAR(box.extent[1], 0.1, 1e-4);
  EXPECT_NEAR(box.extent[2], 0.05, 1e-4);
  EXPECT_NEAR((box.centre - Eigen::Vector3d(0.1, 0.05, 1.025)).norm(), 0, 1e-4);
  EXPECT_NEAR(box.axes.determinant(), 1.0, 1e-9);
  EXPECT_NEAR(std::abs(box.axes.col(0).x()), 1.0, 1e-6);
}

TEST(Selection, InvalidAndUnlabelledPointsStayZero) {
  Builder b;
  b.box({0, 0, 1}, {0.1f, 0.1f, 1.1f}, 0.004f, 1);
  b.add({NAN, NAN, NAN}, 0);
  const auto s = b.select(small_objects());
  EXPECT_EQ(s.instance.back(), 0u);
  EXPECT_EQ(s.components.size(), 1u);
}

// ---- Selection on the image grid (SelectionParams::Geometry::kImage) ----

namespace {

// A rendered tabletop (the built-in synthetic scene: a table, a red box, a striped box touching a
// checked box face to face, a can, a bottle), with one segmentation label for every valid point:
// the image-grid selection must find the objects from the geometry alone.
struct RenderedTable {
  Frame frame = proxseg::synth_scene({});
  std::vector<std::uint32_t> labels;
  RenderedTable() {
    labels.assign(frame.size(), 0);
    for (std::size_t p = 0; p < frame.size(); ++p) labels[p] = frame.valid(p) ? 1 : 0;
  }
};

// The share of truth label t's points in its majority instance, and that instance.
std::pair<double, std::uint32_t> majority(const Frame& f, const proxseg::Selection& s,
                                          std::uint32_t t) {
  std::map<std::uint32_t, int> count;
  int total = 0;
  for (std::size_t p = 0; p < f.size(); ++p)
    if (f.valid(p) && f.label[p] == t) ++count[s.instance[p]], ++total;
  auto best = std::max_element(count.begin(), count.end(),
                               [](const auto& a, const auto& b) { return a.second < b.second; });
  return {double(best->second) / total, best->first};
}

}  // namespace

TEST(ImageSelection, FindsEveryObjectOfARenderedTableByGeometry) {
  RenderedTable t;
  const proxseg::Selection s = proxseg::select_candidates_on_image(t.frame, t.labels, {});
  const auto [table_share, table] = majority(t.frame, s, 1);
  EXPECT_GT(table_share, 0.97);
  ASSERT_GT(table, 0u);
  EXPECT_TRUE(s.components[table - 1].background);
  std::map<std::uint32_t, std::uint32_t> instance_of;
  for (std::uint32_t label = 2; label <= 6; ++label) {
    const auto [share, instance] = majority(t.frame, s, label);
    EXPECT_GT(share, 0.9) << "object " << label;
    EXPECT_NE(instance, 0u) << "object " << label;
    EXPECT_NE(instance, table) << "object " << label;
    EXPECT_FALSE(s.components[instance - 1].background) << "object " << label;
    instance_of[label] = instance;
  }
  // The two boxes that touch face to face (3 and 4: front faces 5 mm apart, no crease, no depth
  // step) are one surface to the geometry; only their colours tell them apart. Every other pair is
  // apart.
  for (std::uint32_t a = 2; a <= 6; ++a)
    for (std::uint32_t b = a + 1; b <= 6; ++b) {
      if (a == 3 && b == 4) continue;
      EXPECT_NE(instance_of[a], instance_of[b]) << a << " and " << b;
    }
}

TEST(ImageSelection, SameInstancesWhenTheCloudLooksDownMinusZ) {
  // PCL's sample scenes look down -z: turning the frame half a turn about x changes nothing.
  RenderedTable t;
  Frame flipped = t.frame;
  for (auto& p : flipped.xyz) p = Eigen::Vector3f(p.x(), -p.y(), -p.z());
  const auto a = proxseg::select_candidates_on_image(t.frame, t.labels, {});
  const auto b = proxseg::select_candidates_on_image(flipped, t.labels, {});
  EXPECT_EQ(a.instance, b.instance);
}

TEST(ImageSelection, ObjectsLyingFlatStayOffTheTable) {
  // A 1.5 cm thick board lying on the table, seen from 1 m: within a fixed 1.5 cm band it would
  // be table; within the sensor's noise at its range it is an object.
  RenderedTable t;
  const auto meshes = proxseg::synth_meshes({});
  std::vector<proxseg::Mesh> scene = {meshes.front()};  // the table
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(0.0, 0.0, 0.0075);
  proxseg::Mesh board = proxseg::make_box(pose, {0.12, 0.04, 0.015}, [](const Eigen::Vector3d&) {
    return proxseg::Rgb{200, 40, 40};
  });
  board.label = 2;
  scene.push_back(board);
  const Frame f = proxseg::render(scene, proxseg::synth_render_params({}));
  std::vector<std::uint32_t> labels(f.size(), 0);
  for (std::size_t p = 0; p < f.size(); ++p) labels[p] = f.valid(p) ? 1 : 0;
  const proxseg::Selection s = proxseg::select_candidates_on_image(f, labels, {});
  const auto [share, instance] = majority(f, s, 2);
  EXPECT_GT(share, 0.8);
  ASSERT_NE(instance, 0u);
  EXPECT_FALSE(s.components[instance - 1].background);
}

TEST(ImageSelection, AMarkerLyingOnTheTableComesWithoutTheTableAroundIt) {
  // A marker (9.5 mm radius) lying on the table: the table's normals beside it are bent by it over
  // image.normal_step pixels; without image.plane_flat_sigmas that ring of table stays with the
  // marker (0.3 of its instance; around a pen it is half).
  const auto meshes = proxseg::synth_meshes({});
  std::vector<proxseg::Mesh> scene = {meshes.front()};  // the table
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.0, 0.0, 0.0095);
  proxseg::Mesh marker = proxseg::make_cylinder(
      pose, 0.0095, 0.125,
      [](const Eigen::Vector3d&) {
        return proxseg::Rgb{30, 60, 170};
      },
      0.002);
  marker.label = 2;
  scene.push_back(marker);
  const Frame f = proxseg::render(scene, proxseg::synth_render_params({}));
  std::vector<std::uint32_t> labels(f.size(), 0);
  for (std::size_t p = 0; p < f.size(); ++p) labels[p] = f.valid(p) ? 1 : 0;
  // The share of an instance that is table.
  auto table_share = [&f](const proxseg::Selection& s, std::uint32_t instance) {
    int table = 0, all = 0;
    for (std::size_t p = 0; p < f.size(); ++p)
      if (s.instance[p] == instance) ++all, table += f.label[p] == 1;
    return double(table) / all;
  };
  for (const double flat : {1.0, 0.0}) {
    proxseg::SelectionParams params;
    params.image.plane_flat_sigmas = flat;
    const proxseg::Selection s = proxseg::select_candidates_on_image(f, labels, params);
    const auto [share, instance] = majority(f, s, 2);
    EXPECT_GT(share, 0.95) << flat;
    ASSERT_NE(instance, 0u) << flat;
    EXPECT_FALSE(s.components[instance - 1].background) << flat;
    if (flat > 0)
      EXPECT_LT(table_share(s, instance), 0.1);
    else
      EXPECT_GT(table_share(s, instance), 0.2);
  }
}

// The loop the image-grid selection runs on: every index exactly once, in static blocks or
// dynamic chunks, at any thread count; an exception reaches the caller after all threads end.
TEST(ParallelFor, EveryIndexOnceAndExceptionsReachTheCaller) {
  for (int threads : {1, 2, 3, 8})
    for (int chunk : {0, 1, 7}) {
      std::vector<int> seen(1001, 0);
      proxseg::detail::parallel_for(
          static_cast<int>(seen.size()), threads, [&](int i) { ++seen[i]; }, chunk);
      EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), 1001) << threads << " " << chunk;
    }
  int ran = 0;
  proxseg::detail::parallel_for(0, 4, [&](int) { ++ran; });
  EXPECT_EQ(ran, 0);
  std::atomic<int> done{0};
  EXPECT_THROW(proxseg::detail::parallel_for(100, 2,
                                             [&](int i) {
                                               ++done;
                                               if (i == 70) throw std::runtime_error("x");
                                             }),
               std::runtime_error);
  EXPECT_GE(done.load(), 51);  // the other block ran to its end
}

// The exact k-nearest search of the segmentation path (weak points, sparse voxels, unorganized
// normals) against brute force: same indices in the same order, ties to the smaller index, for
// queries inside and far outside the points' box, k above the point count, a flat cloud and
// duplicated points.
TEST(NearestPoints, EqualsBruteForceWithTiesToTheSmallerIndex) {
  auto brute = [](const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& q, int k) {
    std::vector<std::pair<int, double>> all;
    for (int i = 0; i < static_cast<int>(pts.size()); ++i)
      all.emplace_back(i, (pts[i] - q).squaredNorm());
    std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) {
      return a.second < b.second || (a.second == b.second && a.first < b.first);
    });
    if (static_cast<int>(all.size()) > k) all.resize(k);
    return all;
  };
  std::uint64_t state = 7;
  auto uniform = [&] {  // a fixed LCG: the same clouds everywhere
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  std::vector<std::vector<Eigen::Vector3d>> clouds(3);
  for (int i = 0; i < 2000; ++i) clouds[0].emplace_back(uniform(), uniform(), 0.3 * uniform());
  for (int i = 0; i < 500; ++i) clouds[1].emplace_back(uniform(), uniform(), 0.0);  // flat
  // A lattice with duplicates: many exact ties.
  for (int rep = 0; rep < 2; ++rep)
    for (int x = 0; x < 6; ++x)
      for (int y = 0; y < 6; ++y)
        for (int z = 0; z < 3; ++z) clouds[2].emplace_back(0.01 * x, 0.01 * y, 0.01 * z);
  for (const auto& pts : clouds) {
    const proxseg::detail::NearestPoints index(pts);
    std::vector<Eigen::Vector3d> queries = {
        pts[0], pts[pts.size() / 2], {5, -3, 2}, {-0.2, 0.5, 0}};
    for (int i = 0; i < 40; ++i) queries.emplace_back(uniform(), uniform(), 0.3 * uniform());
    for (const auto& q : queries)
      for (int k : {1, 7, 20, 5000}) {
        const auto got = index.nearest(q, k), want = brute(pts, q, k);
        ASSERT_EQ(got.size(), want.size()) << k;
        for (std::size_t j = 0; j < got.size(); ++j) {
          EXPECT_EQ(got[j].first, want[j].first) << "k " << k << " rank " << j;
          EXPECT_DOUBLE_EQ(got[j].second, want[j].second);
        }
      }
  }
  EXPECT_TRUE(proxseg::detail::NearestPoints({}).nearest({0, 0, 0}, 3).empty());
}
