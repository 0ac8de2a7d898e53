// RGB-D input: colour and depth PNGs back-projected into an organized frame, their errors, and the
// camera intrinsics files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <string>
#include <vector>

#include "support/io_files.hpp"

using namespace io_test;
using proxseg::Frame;
using proxseg::InputError;

TEST(IoRgbd, SyntheticPngsGiveBackProjectedPoints) {
  cv::Mat colour(2, 3, CV_8UC3, cv::Scalar(0, 0, 0));
  colour.at<cv::Vec3b>(0, 0) = {0, 0, 255};  // BGR red
  colour.at<cv::Vec3b>(1, 2) = {255, 128, 0};
  cv::Mat depth(2, 3, CV_16UC1, cv::Scalar(0));
  depth.at<std::uint16_t>(0, 0) = 1000;  // 1 m
  depth.at<std::uint16_t>(1, 2) = 2500;
  const std::string cpath = tmp_path("c.png"), dpath = tmp_path("d.png");
  ASSERT_TRUE(cv::imwrite(cpath, colour));
  ASSERT_TRUE(cv::imwrite(dpath, depth));
  const Frame f = proxseg::read_rgbd(cpath, dpath, small_k());
  EXPECT_EQ(f.width, 3);
  EXPECT_EQ(f.height, 2);
  ASSERT_EQ(f.size(), 6u);
  EXPECT_EQ(f.valid_count(), 2u);
  EXPECT_EQ(f.rgb[0], (proxseg::Rgb{255, 0, 0}));
  EXPECT_EQ(f.rgb[5], (proxseg::Rgb{0, 128, 255}));
  EXPECT_NEAR(f.xyz[0].x(), (0 - 1) * 1.0 / 100, 1e-6);
  EXPECT_NEAR(f.xyz[0].y(), (0 - 0.5) * 1.0 / 200, 1e-6);
  EXPECT_NEAR(f.xyz[0].z(), 1.0, 1e-6);
  EXPECT_NEAR(f.xyz[5].x(), (2 - 1) * 2.5 / 100, 1e-6);
  EXPECT_NEAR(f.xyz[5].y(), (1 - 0.5) * 2.5 / 200, 1e-6);
  EXPECT_NEAR(f.xyz[5].z(), 2.5, 1e-6);
  EXPECT_FALSE(f.valid(1));

  // Grey colour images are accepted.
  cv::Mat grey(2, 3, CV_8UC1, cv::Scalar(77));
  const std::string gpath = tmp_path("g.png");
  ASSERT_TRUE(cv::imwrite(gpath, grey));
  const Frame g = proxseg::read_rgbd(gpath, dpath, small_k());
  EXPECT_EQ(g.rgb[3], (proxseg::Rgb{77, 77, 77}));
}

TEST(IoRgbd, Errors) {
  const std::string cpath = tmp_path("c4x3.png"), dpath = tmp_path("d5x3.png"),
                    d8 = tmp_path("d8bit.png"), dzero = tmp_path("dzero.png");
  ASSERT_TRUE(cv::imwrite(cpath, cv::Mat(3, 4, CV_8UC3, cv::Scalar(1, 2, 3))));
  ASSERT_TRUE(cv::imwrite(dpath, cv::Mat(3, 5, CV_16UC1, cv::Scalar(900))));
  ASSERT_TRUE(cv::imwrite(d8, cv::Mat(3, 4, CV_8UC1, cv::Scalar(90))));
  ASSERT_TRUE(cv::imwrite(dzero, cv::Mat(3, 4, CV_16UC1, cv::Scalar(0))));
  expect_input_error([&] { proxseg::read_rgbd(cpath, dpath, small_k()); },
                     {"c4x3.png", "d5x3.png", "4x3", "5x3"});
  expect_input_error([&] { proxseg::read_rgbd(cpath, d8, small_k()); }, {"d8bit.png", "16-bit"});
  expect_input_error([&] { proxseg::read_rgbd(cpath, dzero, small_k()); }, {"dzero.png"});
  expect_input_error([&] { proxseg::read_rgbd(tmp_path("nope.png"), dpath, small_k()); },
                     {"nope.png"});
  const std::string notpng = write_bytes("not_an_image.png", "hello");
  expect_input_error([&] { proxseg::read_rgbd(notpng, dpath, small_k()); }, {"not_an_image.png"});
}

TEST(IoIntrinsics, ReadsAndValidates) {
  const std::string ok =
      write_bytes("k.json", R"({"fx": 525, "fy": 526.5, "cx": 319.5, "cy": 239.5})");
  const proxseg::Intrinsics k = proxseg::read_intrinsics(ok);
  EXPECT_EQ(k.fx, 525);
  EXPECT_EQ(k.fy, 526.5);
  EXPECT_EQ(k.cx, 319.5);
  EXPECT_EQ(k.cy, 239.5);
  EXPECT_EQ(k.depth_scale, 1000);  // default
  const std::string ds =
      write_bytes("k5000.json", R"({"fx":1,"fy":2,"cx":3,"cy":4,"depth_scale":5000})");
  EXPECT_EQ(proxseg::read_intrinsics(ds).depth_scale, 5000);

  const std::string no_fy = write_bytes("k_no_fy.json", R"({"fx": 525, "cx": 1, "cy": 2})");
  expect_input_error([&] { proxseg::read_intrinsics(no_fy); }, {"k_no_fy.json", "\"fy\""});
  const std::string neg = write_bytes("k_neg.json", R"({"fx":-1,"fy":2,"cx":3,"cy":4})");
  expect_input_error([&] { proxseg::read_intrinsics(neg); }, {"k_neg.json", "\"fx\""});
  const std::string str = write_bytes("k_str.json", R"({"fx":"525","fy":2,"cx":3,"cy":4})");
  expect_input_error([&] { proxseg::read_intrinsics(str); }, {"k_str.json", "\"fx\"", "number"});
  const std::string zero_ds =
      write_bytes("k_ds0.json", R"({"fx":1,"fy":2,"cx":3,"cy":4,"depth_scale":0})");
  expect_input_error([&] { proxseg::read_intrinsics(zero_ds); }, {"k_ds0.json", "depth_scale"});
  const std::string broken = write_bytes("k_broken.json", "{\"fx\": 1,\n");
  expect_input_error([&] { proxseg::read_intrinsics(broken); }, {"k_broken.json", "JSON"});
  expect_input_error([&] { proxseg::read_intrinsics(tmp_path("k_missing.json")); },
                     {"k_missing.json"});

  // YCB meta: factor_depth as a plain number, and a malformed matrix.
  const std::string meta = write_bytes(
      "meta.json",
      R"({"intrinsic_matrix": [[500,0,320],[0,501,240],[0,0,1]], "factor_depth": 4000})");
  const proxseg::Intrinsics m = proxseg::read_ycb_meta(meta);
  EXPECT_EQ(m.fx, 500);
  EXPECT_EQ(m.fy, 501);
  EXPECT_EQ(m.cx, 320);
  EXPECT_EQ(m.cy, 240);
  EXPECT_EQ(m.depth_scale, 4000);
  const std::string bad_meta = write_bytes(
      "meta_bad.json", R"({"intrinsic_matrix": [[500,0,320],[0,501,240]], "factor_depth": [[1]]})");
  expect_input_error([&] { proxseg::read_ycb_meta(bad_meta); },
                     {"meta_bad.json", "intrinsic_matrix"});
  const std::string no_factor =
      write_bytes("meta_nofactor.json", R"({"intrinsic_matrix": [[1,0,2],[0,3,4],[0,0,1]]})");
  expect_input_error([&] { proxseg::read_ycb_meta(no_factor); },
                     {"meta_nofactor.json", "factor_depth"});
}
