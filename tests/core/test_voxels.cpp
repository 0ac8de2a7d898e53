// Voxels [paper 3.1]: points into cells, the 26-neighbourhood, adjacency and the dense graph.
#include <proxseg/core/voxels.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

using namespace proxseg;

namespace {
Frame cloud(const std::vector<Eigen::Vector3f>& pts) {
  Frame f;
  f.width = static_cast<int>(pts.size());
  f.height = 1;
  f.xyz = pts;
  f.rgb.assign(pts.size(), Rgb{100, 100, 100});
  return f;
}
}  // namespace

TEST(Voxels, PointsGoToTheirCell) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  Frame f = cloud({{0.001f, 0.001f, 0.001f},
                   {0.019f, 0.019f, 0.019f},
                   {0.021f, 0.f, 0.f},
                   {nan, nan, nan},
                   {-0.001f, 0.f, 0.f}});
  const VoxelGrid g = build_voxels(f, 0.02);
  ASSERT_EQ(g.size(), 3u);
  EXPECT_EQ(g.voxel_of_point[0], g.voxel_of_point[1]);
  EXPECT_NE(g.voxel_of_point[0], g.voxel_of_point[2]);
  EXPECT_EQ(g.voxel_of_point[3], -1);                   // invalid point
  EXPECT_NE(g.voxel_of_point[4], g.voxel_of_point[0]);  // floor, not truncation, at negative x
  const int v0 = g.voxel_of_point[0];
  EXPECT_EQ(g.keys[v0], Eigen::Vector3i(0, 0, 0));
  EXPECT_EQ(g.points[v0], (std::vector<int>{0, 1}));
  EXPECT_EQ(g.keys[g.voxel_of_point[4]], Eigen::Vector3i(-1, 0, 0));
}

TEST(Voxels, TwentySixNeighboursOfAFullCube) {
  std::vector<Eigen::Vector3f> pts;
  for (int z = 0; z < 3; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 3; ++x)
        pts.emplace_back(0.01f + 0.02f * x, 0.01f + 0.02f * y, 0.01f + 0.02f * z);
  const VoxelGrid g = build_voxels(cloud(pts), 0.02);
  ASSERT_EQ(g.size(), 27u);
  const int centre = g.voxel_of_point[13];
  EXPECT_EQ(g.neighbours[centre].size(), 26u);
  const int corner = g.voxel_of_point[0];
  EXPECT_EQ(g.neighbours[corner].size(), 7u);  // a corner touches 7 cells of a 3x3x3 block
  const int edge = g.voxel_of_point[1];
  EXPECT_EQ(g.neighbours[edge].size(), 11u);
}

TEST(Voxels, AdjacencyIsSymmetricAndOnlyTouchingCells) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.2f, 0.2f);
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 3000; ++i) pts.emplace_back(u(rng), u(rng), 1.0f + u(rng));
  const VoxelGrid g = build_voxels(cloud(pts), 0.03);
  std::size_t pairs = 0;
  for (std::size_t v = 0; v < g.size(); ++v) {
    EXPECT_TRUE(std::is_sorted(g.neighbours[v].begin(), g.neighbours[v].end()));
    for (int n : g.neighbours[v]) {
      EXPECT_NE(n, static_cast<int>(v));
      const Eigen::Vector3i d = (g.keys[n] - g.keys[v]).cwiseAbs();
      EXPECT_LE(d.maxCoeff(), 1);
      EXPECT_TRUE(
          std::binary_search(g.neighbours[n].begin(), g.neighbours[n].end(), static_cast<int>(v)))
          << "asymmetric " << v << " -> " << n;
      ++pairs;
    }
  }
  // Brute force: every touching pair of occupied cells is listed.
  std::size_t brute = 0;
  for (std::size_t a = 0; a < g.size(); ++a)
    for (std::size_t b = 0; b < g.size(); ++b)
      if (a != b && (g.keys[a] - g.keys[b]).cwiseAbs().maxCoeff() <= 1) ++brute;
  EXPECT_EQ(pairs, brute);
  // Each point is in exactly one voxel.
  std::size_t total = 0;
  for (const auto& p : g.points) total += p.size();
  EXPECT_EQ(total, pts.size());
}

TEST(Voxels, DenseVoxelsAndInducedGraph) {
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 12; ++i) pts.emplace_back(0.005f, 0.005f, 0.005f);  // cell (0,0,0): 12 points
  for (int i = 0; i < 3; ++i) pts.emplace_back(0.025f, 0.005f, 0.005f);   // cell (1,0,0): 3 points
  for (int i = 0; i < 11; ++i) pts.emplace_back(0.045f, 0.005f, 0.005f);  // cell (2,0,0): 11 points
  const VoxelGrid g = build_voxels(cloud(pts), 0.02);
  const std::vector<int> dense = dense_voxels(g, 10);
  ASSERT_EQ(dense.size(), 2u);
  const auto graph = induced_neighbours(g, dense);
  // The two dense cells are not adjacent (the sparse one between them is left out).
  EXPECT_TRUE(graph[0].empty());
  EXPECT_TRUE(graph[1].empty());
  const auto full = induced_neighbours(g, dense_voxels(g, 1));
  EXPECT_EQ(full[1].size(), 2u);
}

TEST(Voxels, NumberingDoesNotDependOnPointOrder) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.f, 0.3f);
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 500; ++i) pts.emplace_back(u(rng), u(rng), u(rng));
  std::vector<Eigen::Vector3f> shuffled = pts;
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  const VoxelGrid a = build_voxels(cloud(pts), 0.05), b = build_voxels(cloud(shuffled), 0.05);
  ASSERT_EQ(a.keys, b.keys);
  EXPECT_EQ(a.neighbours, b.neighbours);
}
