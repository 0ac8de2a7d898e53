// The initial clustering [paper Algorithm 1]: the chi-square test, the centroids it finds, the
// visits of every voxel, and k-means after it.
#include <proxseg/core/clustering.hpp>

#include <gtest/gtest.h>

#include <numeric>
#include <random>

using namespace proxseg;

namespace {
// A chain graph 0 - 1 - 2 - ... - (n-1).
std::vector<std::vector<int>> chain(int n) {
  std::vector<std::vector<int>> g(n);
  for (int i = 0; i + 1 < n; ++i) {
    g[i].push_back(i + 1);
    g[i + 1].push_back(i);
  }
  return g;
}
}  // namespace

TEST(ChiSquare, KnownQuantiles) {
  EXPECT_NEAR(chi_square_quantile(0.85, 1), 2.0723, 1e-3);
  EXPECT_NEAR(chi_square_quantile(0.85, 2), 3.7942, 1e-3);
  EXPECT_NEAR(chi_square_quantile(0.95, 10), 18.307, 1e-3);
  EXPECT_THROW(chi_square_quantile(1.5, 3), std::invalid_argument);
}

TEST(Algorithm1, TwoRegionsOnAChainGiveTwoCentroids) {
  // 40 voxels along a chain: the first 20 have features near (0, 0), the next 20 near (6, 0).
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.3);
  Eigen::MatrixXd x(40, 2);
  for (int i = 0; i < 40; ++i) x.row(i) << (i < 20 ? 0.0 : 6.0) + noise(rng), noise(rng);
  const Eigen::VectorXd global = Eigen::Vector2d(9.0, 1.0);  // variance of the whole set
  ClusteringParams p;
  p.prior_weight = 5;
  const auto c = initial_centroids(x, chain(40), global, p);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0].n, 20);
  EXPECT_EQ(c[1].n, 20);
  EXPECT_NEAR(c[0].mu(0), 0.0, 0.3);
  EXPECT_NEAR(c[1].mu(0), 6.0, 0.3);
  // Line 14's running covariance equals the sample (population) covariance of the members.
  const Eigen::MatrixXd first = x.topRows(20);
  const Eigen::MatrixXd centred = first.rowwise() - first.colwise().mean();
  const Eigen::MatrixXd cov = centred.transpose() * centred / 20.0;
  EXPECT_NEAR((c[0].sigma - cov).cwiseAbs().maxCoeff(), 0.0, 1e-9);
}

TEST(Algorithm1, EveryVoxelVisitedOnceAcrossComponents) {
  // Three disconnected components with the same features: one centroid holds every voxel, so
  // the walk restarted at each component and visited each voxel exactly once.
  std::vector<std::vector<int>> g(30);
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 9; ++i) {
      g[c * 10 + i].push_back(c * 10 + i + 1);
      g[c * 10 + i + 1].push_back(c * 10 + i);
    }
  std::mt19937 rng(2);
  std::normal_distribution<double> noise(0.0, 0.1);
  Eigen::MatrixXd x(30, 3);
  for (int i = 0; i < 30; ++i) x.row(i) << noise(rng), noise(rng), noise(rng);
  // The prior covariance is wide compared with the noise, so no voxel fails the test.
  const auto c = initial_centroids(x, g, Eigen::Vector3d::Constant(1.0), ClusteringParams{});
  int total = 0;
  for (const auto& ci : c) total += ci.n;
  EXPECT_EQ(total, 30);
  EXPECT_EQ(c.size(), 1u);
}

TEST(Algorithm1, ThreeColoursOnAGridAndTheTestThreshold) {
  // A 12x12 grid in three vertical bands with distinct features: three centroids.
  const int w = 12;
  std::vector<std::vector<int>> g(w * w);
  for (int v = 0; v < w; ++v)
    for (int u = 0; u < w; ++u) {
      if (u + 1 < w) g[v * w + u].push_back(v * w + u + 1), g[v * w + u + 1].push_back(v * w + u);
      if (v + 1 < w)
        g[v * w + u].push_back((v + 1) * w + u), g[(v + 1) * w + u].push_back(v * w + u);
    }
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.2);
  Eigen::MatrixXd x(w * w, 2);
  for (int i = 0; i < w * w; ++i) {
    const int band = (i % w) / 4;
    x.row(i) << 5.0 * band + noise(rng), (band == 1 ? 3.0 : 0.0) + noise(rng);
  }
  const auto c = initial_centroids(x, g, Eigen::Vector2d(16.0, 2.0), ClusteringParams{});
  ASSERT_EQ(c.size(), 3u);
  for (const auto& ci : c) EXPECT_EQ(ci.n, 48);
  // A confidence so strict that nothing ever matches gives one centroid per voxel.
  ClusteringParams strict;
  strict.alpha = 1e-9;
  EXPECT_EQ(initial_centroids(x, g, Eigen::Vector2d(16.0, 2.0), strict).size(),
            static_cast<std::size_t>(w * w));
}

TEST(KMeans, ConvergesDropsEmptyAndLabelsAgree) {
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0.0, 0.5);
  Eigen::MatrixXd x(300, 2);
  const double cx[3] = {0, 10, 0}, cy[3] = {0, 0, 10};
  for (int i = 0; i < 300; ++i) x.row(i) << cx[i % 3] + noise(rng), cy[i % 3] + noise(rng);
  Eigen::MatrixXd init(4, 2);
  init << 1, 1, 9, 1, 1, 9, 500, 500;  // the last one attracts no point: dropped
  const KMeansResult r = kmeans(x, init, KMeansParams{});
  ASSERT_EQ(r.centroids.rows(), 3);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(r.centroids(c, 0), cx[c], 0.2);
    EXPECT_NEAR(r.centroids(c, 1), cy[c], 0.2);
  }
  for (int i = 0; i < 300; ++i) {
    EXPECT_EQ(r.labels[i], i % 3);
    Eigen::Index arg;
    (r.centroids.rowwise() - x.row(i)).rowwise().squaredNorm().minCoeff(&arg);
    EXPECT_EQ(r.labels[i], arg);
  }
  EXPECT_LT(r.iterations, 20);
  // Centroids are the means of their members.
  for (int c = 0; c < 3; ++c) {
    Eigen::RowVector2d mean = Eigen::RowVector2d::Zero();
    for (int i = c; i < 300; i += 3) mean += x.row(i);
    EXPECT_NEAR((mean / 100 - r.centroids.row(c)).norm(), 0, 1e-9);
  }
}

TEST(KMeans, IterationCapAndSingleCluster) {
  Eigen::MatrixXd x = Eigen::MatrixXd::Random(50, 3);
  KMeansParams p;
  p.max_iterations = 1;
  Eigen::MatrixXd init = x.topRows(5);
  EXPECT_EQ(kmeans(x, init, p).iterations, 1);
  const KMeansResult one = kmeans(x, x.topRows(1), KMeansParams{});
  ASSERT_EQ(one.centroids.rows(), 1);
  EXPECT_NEAR((one.centroids.row(0) - x.colwise().mean()).norm(), 0, 1e-12);
}

TEST(PrincipalAxes, RecoversTheDominantDirection) {
  std::mt19937 rng(6);
  std::normal_distribution<float> n(0.f, 1.f);
  Eigen::MatrixXf f(500, 5);
  for (int i = 0; i < 500; ++i) {
    const float t = 3 * n(rng);
    f.row(i) << t, t, 0.1f * n(rng), 0.1f * n(rng), 0.f;  // last column constant
  }
  const FeatureSpace s = principal_axes(f, 10);
  // (1, -1, 0, 0, 0) and the constant column carry no variance: dropped.
  EXPECT_EQ(s.axes.cols(), 3);
  EXPECT_NEAR(std::abs(s.axes(0, 0)), std::sqrt(0.5), 1e-2);
  EXPECT_NEAR(s.variances(0), 18.0, 2.0);
  const Eigen::MatrixXd x = project(s, f);
  EXPECT_NEAR(x.col(0).mean(), 0.0, 1e-4);
}

TEST(BalanceBlocks, EqualVarianceThenTheBlockWeights) {
  std::mt19937 rng(8);
  std::normal_distribution<float> n(0.f, 1.f);
  Eigen::MatrixXf f(400, 5);
  for (int i = 0; i < 400; ++i)
    f.row(i) << 10 * n(rng), 10 * n(rng), 0.1f * n(rng), 0.1f * n(rng), 0.1f * n(rng);
  auto variance = [&](int start, int size) {
    const Eigen::MatrixXf b = f.middleCols(start, size);
    return (b.rowwise() - b.colwise().mean()).squaredNorm() / (f.rows() - 1.0);
  };
  balance_blocks(f, {{0, 2, 1.0}, {2, 3, 2.0}});
  EXPECT_NEAR(variance(0, 2), 1.0, 1e-4);
  EXPECT_NEAR(variance(2, 3), 4.0, 1e-3);  // the weight survives the balancing
}
