// The readers on the real data files: mOSD and PCL PCDs, a YCB-Video frame (colour and depth
// PNGs with its meta) and a LINEMOD PLY mesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <proxseg/core/errors.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <string>
#include <vector>

#include "support/io_files.hpp"

using namespace io_test;
using proxseg::Frame;
using proxseg::InputError;

namespace {
// WIDTH x HEIGHT points, organized (an image grid) when HEIGHT > 1.
void expect_grid(const Frame& f, int width, int height) {
  EXPECT_EQ(f.width, width);
  EXPECT_EQ(f.height, height);
  EXPECT_EQ(f.organized(), height > 1);
}
}  // namespace

TEST(IoReal, MosdLearn0HasOrganizedGridLabelsAndNaNs) {
  const Frame f = proxseg::read_pcd(kData + "/mosd/learn/learn0.pcd");
  expect_grid(f, 640, 480);
  ASSERT_EQ(f.size(), 307200u);
  ASSERT_EQ(f.rgb.size(), 307200u);
  ASSERT_EQ(f.label.size(), 307200u);
  const std::size_t valid = f.valid_count();
  EXPECT_GT(valid, 150000u);  // 182292 in this scene
  EXPECT_LT(valid, 307200u);  // and some NaN (no return) points
  std::set<std::uint32_t> labels;
  for (std::size_t i = 0; i < f.size(); ++i) {
    labels.insert(f.label[i]);
    // mOSD: label 0 exactly on invalid points, table parts 1-9, objects >= 20.
    EXPECT_EQ(f.valid(i), f.label[i] != 0) << "point " << i;
    EXPECT_TRUE(f.label[i] < 10 || f.label[i] >= 20) << f.label[i];
    if (f.valid(i)) {
      EXPECT_GT(f.xyz[i].z(), 0.3f);
      EXPECT_LT(f.xyz[i].z(), 3.0f);
    }
  }
  EXPECT_TRUE(labels.count(0));
  EXPECT_TRUE(labels.count(1));
  EXPECT_GE(*labels.rbegin(), 20u);
  EXPECT_GE(std::count_if(labels.begin(), labels.end(), [](std::uint32_t l) { return l >= 20; }),
            2);  // at least two objects
  // First valid point (row 155), checked against Open3D's PCD reader.
  std::size_t first = 0;
  while (!f.valid(first)) ++first;
  EXPECT_EQ(first, 99213u);
  EXPECT_NEAR(f.xyz[first].x(), -0.745525f, 1e-5);
  EXPECT_NEAR(f.xyz[first].y(), -0.205536f, 1e-5);
  EXPECT_NEAR(f.xyz[first].z(), 1.277f, 1e-5);
  EXPECT_EQ(f.rgb[first], (proxseg::Rgb{205, 183, 169}));
}

TEST(IoReal, MilkIsUnorganized) {
  const Frame f = proxseg::read_point_cloud(kData + "/pcl/milk.pcd");
  expect_grid(f, 12575, 1);
  EXPECT_EQ(f.size(), 12575u);
  EXPECT_EQ(f.valid_count(), 12575u);
  EXPECT_TRUE(f.label.empty());
  EXPECT_NEAR(f.xyz[0].x(), 0.185442f, 1e-5);
  EXPECT_EQ(f.rgb[0], (proxseg::Rgb{0, 0, 255}));
}

TEST(IoReal, TableSceneMugHasFloatRgb) {
  const Frame f = proxseg::read_point_cloud(kData + "/pcl/table_scene_mug_stereo_textured.pcd");
  EXPECT_EQ(f.width, 640);
  EXPECT_EQ(f.height, 480);
  ASSERT_EQ(f.size(), 307200u);
  std::size_t coloured = 0, distinct_rg = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    coloured += f.rgb[i] != proxseg::Rgb{0, 0, 0};
    distinct_rg += f.rgb[i][0] != f.rgb[i][2];
  }
  EXPECT_GT(coloured, f.size() / 2);
  EXPECT_GT(distinct_rg, 1000u);  // real colours, not grey or zero
  EXPECT_GT(f.valid_count(), 100000u);
  EXPECT_LT(f.valid_count(), f.size());
}

TEST(IoReal, YcbFrameFromPngsAndMeta) {
  const std::string base = kData + "/ycbv/frames/000001";
  const proxseg::Intrinsics k = proxseg::read_ycb_meta(base + "-meta.json");
  EXPECT_NEAR(k.fx, 1066.778, 1e-9);
  EXPECT_NEAR(k.fy, 1067.487, 1e-9);
  EXPECT_NEAR(k.cx, 312.9869, 1e-9);
  EXPECT_NEAR(k.cy, 241.3109, 1e-9);
  EXPECT_EQ(k.depth_scale, 10000.0);
  const Frame f = proxseg::read_rgbd(base + "-color.png", base + "-depth.png", k);
  EXPECT_EQ(f.width, 640);
  EXPECT_EQ(f.height, 480);
  ASSERT_EQ(f.size(), 640u * 480u);
  EXPECT_GT(f.valid_count(), 200000u);
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!f.valid(i)) continue;
    const float z = f.xyz[i].z();
    ASSERT_GT(z, 0.2f);
    ASSERT_LT(z, 3.0f);
    const double u = static_cast<double>(i % 640), v = static_cast<double>(i / 640);
    ASSERT_NEAR(f.xyz[i].x() * k.fx / z + k.cx, u, 1e-3);
    ASSERT_NEAR(f.xyz[i].y() * k.fy / z + k.cy, v, 1e-3);
  }
}

TEST(IoReal, LinemodPlyMeshVerticesWithColours) {
  const Frame f = proxseg::read_point_cloud(kData + "/lmo/models/obj_000001.ply");
  EXPECT_EQ(f.height, 1);
  EXPECT_EQ(f.width, 5841);
  ASSERT_EQ(f.size(), 5841u);  // the vertices, faces ignored
  // First vertex line: -23.0565 17.4191 -6.756 ... 148 57 57 255
  EXPECT_NEAR(f.xyz[0].x(), -23.0565f, 1e-4);
  EXPECT_NEAR(f.xyz[0].y(), 17.4191f, 1e-4);
  EXPECT_NEAR(f.xyz[0].z(), -6.756f, 1e-4);
  EXPECT_EQ(f.rgb[0], (proxseg::Rgb{148, 57, 57}));
  EXPECT_TRUE(f.label.empty());
}
