// The per-voxel features [paper 3.1]: colour histograms, Gabor texture (against a reference
// implementation), the shape block and the point normals it uses.
#include <proxseg/core/features.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/core/voxels.hpp>

#include "core/gabor_reference.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>

using namespace proxseg;

namespace {
constexpr double kPi = 3.14159265358979323846;

// An organized frame of a plane z = z0 + a x seen by a 525 px pinhole camera, grey colour.
Frame plane_frame(int w, int h, float z0, float slope) {
  Frame f;
  f.width = w;
  f.height = h;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const double rx = (u - w / 2.0) / 525.0, ry = (v - h / 2.0) / 525.0;
      const double z = z0 / (1 - slope * rx);  // ray-plane intersection of z = z0 + slope x
      f.xyz.emplace_back(rx * z, ry * z, z);
      f.rgb.push_back({128, 128, 128});
    }
  return f;
}
}  // namespace

TEST(ColourFeature, PureColoursFallInTheirBins) {
  const Eigen::VectorXf red = colour_feature(std::vector<Rgb>(5, Rgb{255, 0, 0}));
  ASSERT_EQ(red.size(), kColourDims);
  EXPECT_FLOAT_EQ(red(0 * 10 + 9), 1.f);  // hue bin 0, saturation bin 9
  EXPECT_FLOAT_EQ(red(100 + 9), 1.f);     // value bin 9
  EXPECT_FLOAT_EQ(red.head(100).sum(), 1.f);
  EXPECT_FLOAT_EQ(red.tail(10).sum(), 1.f);

  // Half pure blue (hue 240 deg -> bin 6), half dark grey (hue 0, saturation 0, value 0.25).
  std::vector<Rgb> mix(4, Rgb{0, 0, 255});
  mix.insert(mix.end(), 4, Rgb{64, 64, 64});
  const Eigen::VectorXf m = colour_feature(mix);
  EXPECT_FLOAT_EQ(m(6 * 10 + 9), 0.5f);
  EXPECT_FLOAT_EQ(m(0), 0.5f);
  EXPECT_FLOAT_EQ(m(100 + 9), 0.5f);
  EXPECT_FLOAT_EQ(m(100 + 2), 0.5f);

  EXPECT_EQ(colour_feature({}).norm(), 0.f);  // no points: empty histograms
}

TEST(ShapeFeature, PlaneLineAndBlob) {
  std::vector<Eigen::Vector3f> plane, line, blob;
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-0.01f, 0.01f);
  for (int i = 0; i < 400; ++i) {
    plane.emplace_back(u(rng), u(rng), 1.f);
    line.emplace_back(u(rng), 0.f, 1.f);
    blob.emplace_back(u(rng), u(rng), 1.f + u(rng));
  }
  const std::vector<Eigen::Vector3f> normals(400, Eigen::Vector3f(0, 0, -1));
  const Eigen::VectorXf p = shape_feature(plane, normals);
  ASSERT_EQ(p.size(), kShapeDims);
  EXPECT_NEAR(p(0), 0.5, 0.05);
  EXPECT_NEAR(p(1), 0.5, 0.05);
  EXPECT_NEAR(p(2), 0.0, 1e-6);
  EXPECT_NEAR(p(3), 0.0, 1e-6);  // curvature of a plane
  EXPECT_NEAR(p.head(3).sum(), 1.0, 1e-5);
  // Normals facing the sensor: inclination pi (bin 9), azimuth atan2(0, 0) = 0 (bin 5).
  EXPECT_FLOAT_EQ(p(4 + 9 * 10 + 5), 1.f);
  EXPECT_NEAR(p.tail(100).sum(), 1.0, 1e-6);

  const Eigen::VectorXf l = shape_feature(line, normals);
  EXPECT_NEAR(l(0), 1.0, 1e-4);
  const Eigen::VectorXf b = shape_feature(blob, normals);
  EXPECT_NEAR(b(0), 1.0 / 3, 0.06);
  EXPECT_NEAR(b(2), 1.0 / 3, 0.06);
  EXPECT_GT(b(3), 0.25);  // high curvature index
  EXPECT_GE(b(0), b(1));
  EXPECT_GE(b(1), b(2));
}

TEST(ShapeFeature, NormalAnglesSpreadOverBins) {
  std::vector<Eigen::Vector3f> pts(4, Eigen::Vector3f::Zero()), normals;
  normals.emplace_back(1, 0, 0);              // theta pi/2 (bin 5), phi 0 (bin 5)
  normals.emplace_back(0, 1, 0);              // theta pi/2, phi pi/2 (bin 7)
  normals.emplace_back(0, 0, -1);             // theta pi (bin 9), phi 0
  normals.emplace_back(std::nanf(""), 0, 0);  // ignored
  const Eigen::VectorXf f = shape_feature(pts, normals);
  EXPECT_NEAR(f(4 + 5 * 10 + 5), 1.0 / 3, 1e-6);
  EXPECT_NEAR(f(4 + 5 * 10 + 7), 1.0 / 3, 1e-6);
  EXPECT_NEAR(f(4 + 9 * 10 + 5), 1.0 / 3, 1e-6);
}

TEST(PointNormals, OrganizedPlaneNormalsFaceTheSensor) {
  const Frame f = plane_frame(80, 60, 1.0f, 0.5f);
  const auto n = point_normals(f, FeatureParams{});
  // The plane z = 1 + 0.5 x has normal (0.5, 0, -1)/|.| towards the sensor.
  const Eigen::Vector3f expected = Eigen::Vector3f(0.5f, 0.f, -1.f).normalized();
  int checked = 0;
  for (int v = 5; v < 55; ++v)
    for (int u = 5; u < 75; ++u) {
      ASSERT_TRUE(n[v * 80 + u].allFinite());
      EXPECT_NEAR(n[v * 80 + u].dot(expected), 1.0, 1e-3);
      ++checked;
    }
  EXPECT_GT(checked, 3000);
}

// A slanted board 8 cm in front of a wall, its edge a silhouette: with the smoothing kept to each
// pixel's surface (normal_edge_ratio) the board's normals up to its edge are the board's; the
// plain box filter mixes the wall into the last pixels and bends them by tens of degrees.
TEST(PointNormals, EdgeAwareSmoothingKeepsASilhouettesNormals) {
  const int w = 80, h = 60;
  Frame f = plane_frame(w, h, 1.0f, 0.5f);
  for (int v = 0; v < h; ++v)
    for (int u = w / 2; u < w; ++u) f.xyz[v * w + u] *= 1.08f / f.xyz[v * w + u].z();  // wall
  const Eigen::Vector3f board = Eigen::Vector3f(0.5f, 0.f, -1.f).normalized();
  FeatureParams plain, aware;
  plain.normal_step = aware.normal_step = 5;
  aware.normal_edge_ratio = 0.01;
  const auto a = point_normals(f, aware), b = point_normals(f, plain);
  double worst_aware = 1, worst_plain = 1;
  for (int v = 10; v < h - 10; ++v)
    for (int u = w / 2 - 3; u < w / 2; ++u) {  // the board's last three columns
      const int i = v * w + u;
      if (a[i].allFinite()) worst_aware = std::min<double>(worst_aware, a[i].dot(board));
      if (b[i].allFinite()) worst_plain = std::min<double>(worst_plain, b[i].dot(board));
    }
  EXPECT_GT(worst_aware, std::cos(2 * kPi / 180));
  EXPECT_LT(worst_plain, std::cos(20 * kPi / 180));
}

TEST(PointNormals, UnorganizedPlane) {
  Frame f = plane_frame(40, 30, 1.0f, 0.0f);
  f.width = 1200;
  f.height = 1;
  const auto n = point_normals(f, FeatureParams{});
  for (const auto& v : n) EXPECT_NEAR(v.z(), -1.0, 1e-3);
}

TEST(GaborBank, MatchesADirectConvolution) {
  // The DFT filtering must equal the spatial complex Gabor kernel away from the borders.
  const int w = 96, h = 80;
  Frame f = plane_frame(w, h, 1.f, 0.f);
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> pix(0, 255);
  for (auto& c : f.rgb) c = {static_cast<std::uint8_t>(pix(rng)), 0, 0};
  FeatureParams params;
  const GaborBank bank = gabor_bank(f, params);
  ASSERT_EQ(bank.magnitude.size(), static_cast<std::size_t>(kGaborScales * kGaborOrientations));
  const double sigma = params.gabor_sigma, f0 = 1.0 / params.gabor_wavelength;
  for (int o = 0; o < kGaborOrientations; ++o) {
    const double th = o * kPi / kGaborOrientations;
    for (const auto& [u, v] : std::vector<std::pair<int, int>>{{40, 40}, {50, 30}}) {
      std::complex<double> acc = 0;
      for (int dy = -12; dy <= 12; ++dy)
        for (int dx = -12; dx <= 12; ++dx) {
          const double g =
              std::exp(-(dx * dx + dy * dy) / (2 * sigma * sigma)) / (2 * kPi * sigma * sigma);
          const double grey = 0.299 * f.rgb[(v - dy) * w + (u - dx)][0] / 255.0;
          acc += g * std::polar(1.0, 2 * kPi * f0 * (dx * std::cos(th) + dy * std::sin(th))) * grey;
        }
      EXPECT_NEAR(bank.magnitude[o][v * w + u], std::abs(acc), 2e-3 + 0.02 * std::abs(acc))
          << "orientation " << o;
    }
  }
}

TEST(TextureFeature, StripesDifferFromFlat) {
  // Left half: vertical stripes of period 4 px (the level-0 wavelength); right half flat.
  const int w = 128, h = 96;
  Frame f = plane_frame(w, h, 1.f, 0.f);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const std::uint8_t g = u < w / 2 ? (u % 4 < 2 ? 230 : 30) : 128;
      f.rgb[v * w + u] = {g, g, g};
    }
  const GaborBank bank = gabor_bank(f, FeatureParams{});
  std::vector<int> left, right;
  for (int v = 30; v < 60; ++v)
    for (int u = 16; u < 40; ++u) {
      left.push_back(v * w + u);
      right.push_back(v * w + u + 70);
    }
  const Eigen::VectorXf tl = texture_feature(bank, left), tr = texture_feature(bank, right);
  ASSERT_EQ(tl.size(), kTextureDims);
  for (int filter = 0; filter < kGaborScales * kGaborOrientations; ++filter) {
    EXPECT_NEAR(tl.segment(filter * 10, 10).sum(), 1.0, 1e-5);
    EXPECT_NEAR(tr.segment(filter * 10, 10).sum(), 1.0, 1e-5);
  }
  // Scale 0, orientation 0 (horizontal frequency) responds strongly to vertical stripes.
  EXPECT_GT(tl.segment(5, 5).sum(), 0.9);  // upper half of the bins
  EXPECT_GT(tr(0), 0.9);                   // flat: lowest bin
}

TEST(VoxelFeatures, BlocksWeightsAndThreads) {
  Frame f = plane_frame(64, 48, 1.f, 0.3f);
  for (std::size_t i = 0; i < f.size(); ++i)
    f.rgb[i] = {static_cast<std::uint8_t>(i % 256), 80, 200};
  const VoxelGrid g = build_voxels(f, 0.02);
  const std::vector<int> all = dense_voxels(g, 1);
  FeatureParams p;
  const Eigen::MatrixXf a = voxel_features(f, g, all, p, 1);
  const Eigen::MatrixXf b = voxel_features(f, g, all, p, 2);
  ASSERT_EQ(a.cols(), kFeatureDims);
  ASSERT_EQ(a.rows(), static_cast<Eigen::Index>(all.size()));
  EXPECT_EQ((a - b).cwiseAbs().maxCoeff(), 0.f);  // same bits whatever the thread count
  for (Eigen::Index r = 0; r < a.rows(); ++r) {
    EXPECT_NEAR(a.row(r).segment(0, 100).sum(), 1.0, 1e-5);
    EXPECT_NEAR(a.row(r).segment(kColourDims, kTextureDims).sum(), 24.0, 1e-4);
  }
  p.colour_weight = 2.0;
  p.use_texture = false;
  const Eigen::MatrixXf c = voxel_features(f, g, all, p, 1);
  EXPECT_NEAR((c.leftCols(kColourDims) - 2 * a.leftCols(kColourDims)).cwiseAbs().maxCoeff(), 0,
              1e-6);
  EXPECT_EQ(c.middleCols(kColourDims, kTextureDims).cwiseAbs().maxCoeff(), 0.f);
  EXPECT_EQ((c.rightCols(kShapeDims) - a.rightCols(kShapeDims)).cwiseAbs().maxCoeff(), 0.f);
}

// voxel_features() bins each filter's responses without keeping the bank, through the response
// cells of the rows' pixels; at stride 1 its texture block must be the reference's exactly.
TEST(TextureFeature, VoxelFeaturesEqualTheReferenceAtStrideOne) {
  const Frame f = synth_scene(SynthParams{});
  FeatureParams params;
  params.use_colour = false;
  params.use_shape = false;
  params.gabor_stride = 1;
  const VoxelGrid grid = build_voxels(f, 0.02);
  const std::vector<int> voxels = dense_voxels(grid, 10);
  ASSERT_GT(voxels.size(), 500u);
  const Eigen::MatrixXf features = voxel_features(f, grid, voxels, params, 2);
  const GaborBank bank = gabor_bank(f, params);
  int textured = 0;
  for (std::size_t row = 0; row < voxels.size(); ++row) {
    const Eigen::VectorXf reference = texture_feature(bank, grid.points[voxels[row]]);
    const Eigen::VectorXf fast = features.row(row).segment(kColourDims, kTextureDims).transpose();
    ASSERT_LE((fast - reference).cwiseAbs().maxCoeff(), 1e-6f) << "voxel row " << row;
    // Not all in the lowest bins: the scene's texture reaches the upper bins somewhere.
    for (int filter = 0; filter < kGaborScales * kGaborOrientations; ++filter)
      textured += reference.segment(filter * kHistogramBins + 5, 5).sum() > 0.5f;
  }
  EXPECT_GT(textured, 100);
  EXPECT_EQ(features.leftCols(kColourDims).cwiseAbs().maxCoeff(), 0.f);  // colour off
}
