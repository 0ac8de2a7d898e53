// Descriptors [paper 3.4]: describe()'s FPFH, normals and spacing against Open3D's to the last
// bit, kept at float precision.
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

#include "support/fresh_dir.hpp"
#include "support/model_views.hpp"

namespace fs = std::filesystem;
using namespace proxseg;
using namespace proxseg::test;

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
