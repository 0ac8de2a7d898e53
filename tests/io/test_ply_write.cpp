// Writing PLYs: the header and bytes, round trips through read_ply of the valid points or of
// every point (NaN kept) and of the fields (read back as the label), clouds without colour, and
// the fields refused with their reason.
#include <gtest/gtest.h>

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
using proxseg::PlyPoints;

namespace {

// A 3x2 organized frame, point 4 invalid.
Frame small_frame(bool coloured) {
  Frame f;
  f.width = 3;
  f.height = 2;
  for (int i = 0; i < 6; ++i) {
    f.xyz.emplace_back(0.1f * i, -0.2f * i, 1.0f + i);
    if (coloured)
      f.rgb.push_back({static_cast<std::uint8_t>(40 * i), static_cast<std::uint8_t>(255 - i), 7});
  }
  f.xyz[4] = Eigen::Vector3f(kNan, kNan, kNan);
  return f;
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST(IoPlyWrite, HeaderAndBytesOfTheValidPoints) {
  const Frame f = small_frame(true);
  const std::string path = tmp_path("written.ply");
  proxseg::write_ply(path, f, {{"label", {0, 1, 20, 21, 0, 2147483647u}}});
  const std::string bytes = file_bytes(path);
  const std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment written by proxseg\n"
      "comment organized 3x2 frame (PLY keeps no grid)\nelement vertex 5\nproperty float x\n"
      "property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nproperty int label\nend_header\n";
  ASSERT_EQ(bytes.substr(0, header.size()), header);
  ASSERT_EQ(bytes.size(), header.size() + 5 * 19);
  // The last vertex is the frame's point 5: x y z, r g b, label.
  const char* last = bytes.data() + header.size() + 4 * 19;
  float z = 0;
  std::int32_t label = 0;
  std::memcpy(&z, last + 8, 4);
  std::memcpy(&label, last + 15, 4);
  EXPECT_EQ(z, 6.0f);
  EXPECT_EQ(static_cast<unsigned char>(last[12]), 200);
  EXPECT_EQ(label, 2147483647);
}

TEST(IoPlyWrite, RoundTripsThroughReadPly) {
  const Frame f = small_frame(true);
  const std::string valid = tmp_path("valid.ply"), all = tmp_path("all.ply");
  proxseg::write_ply(valid, f, {});
  proxseg::write_ply(all, f, {{"instance", {1, 2, 3, 4, 5, 6}}}, PlyPoints::kAll);
  const Frame v = proxseg::read_point_cloud(valid);
  const Frame a = proxseg::read_point_cloud(all);
  EXPECT_EQ(v.height, 1);
  ASSERT_EQ(v.size(), 5u);
  ASSERT_EQ(a.size(), 6u);
  EXPECT_EQ(a.valid_count(), 5u);
  EXPECT_FALSE(a.valid(4));
  for (std::size_t i = 0, j = 0; i < f.size(); ++i) {
    EXPECT_EQ(a.rgb[i], f.rgb[i]) << i;
    if (!f.valid(i)) continue;
    EXPECT_EQ(a.xyz[i], f.xyz[i]) << i;
    EXPECT_EQ(v.xyz[j], f.xyz[i]) << i;
    EXPECT_EQ(v.rgb[j], f.rgb[i]) << i;
    ++j;
  }
}

TEST(IoPlyWrite, FieldsComeBackAsTheLabel) {
  const Frame f = small_frame(true);
  const std::vector<std::uint32_t> instance = {1, 2, 3, 4, 5, 2147483647u};
  const std::string path = tmp_path("labelled.ply");
  proxseg::write_ply(path, f, {{"label", {9, 9, 9, 9, 9, 9}}, {"instance", instance}},
                     PlyPoints::kAll);
  EXPECT_EQ(proxseg::read_ply(path, "instance").label, instance);
  EXPECT_EQ(proxseg::read_ply(path, "label").label, std::vector<std::uint32_t>(6, 9));
  EXPECT_TRUE(proxseg::read_ply(path).label.empty());            // none asked for
  EXPECT_TRUE(proxseg::read_ply(path, "object").label.empty());  // none in the file
  // A float or negative "label" is refused with the reason.
  std::string floats =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nproperty float label\nend_header\n0 0 1 2.5\n";
  std::string negative = floats;
  negative.replace(negative.find("float label"), 11, "int label");
  negative.replace(negative.find("2.5"), 3, "-1");
  const auto refused = [](const std::string& file, const char* reason) {
    try {
      proxseg::read_ply(file, "label");
      ADD_FAILURE() << "accepted: " << reason;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  };
  refused(write_bytes("float_label.ply", floats), "is a float (expected an integer type");
  refused(write_bytes("negative_label.ply", negative),
          "vertex 0: label -1 (expected whole labels 0..2^32-1)");
}

TEST(IoPlyWrite, WithoutColoursIsXyzOnly) {
  const Frame f = small_frame(false);
  const std::string bytes = proxseg::ply_bytes(f, {}, PlyPoints::kAll);
  EXPECT_EQ(bytes.find("red"), std::string::npos);
  EXPECT_EQ(bytes.size(), bytes.find("end_header\n") + 11 + 6 * 12);
  const Frame back = proxseg::read_point_cloud(write_bytes("xyz_only.ply", bytes));
  EXPECT_FALSE(back.coloured());
  EXPECT_EQ(back.xyz[5], f.xyz[5]);
}

TEST(IoPlyWrite, RefusesWhatAPlyCannotHold) {
  const Frame f = small_frame(true);
  const auto refused = [&](const std::vector<proxseg::PointField>& fields, const char* reason) {
    try {
      proxseg::ply_bytes(f, fields);
      ADD_FAILURE() << "accepted: " << reason;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  };
  const std::vector<std::uint32_t> six(6, 1);
  refused({{"red", six}}, "is used twice");
  refused({{"a", six}, {"a", six}}, "is used twice");
  refused({{"la bel", six}}, "is not a PLY property name");
  refused({{"label", {1, 2}}}, "has 2 values for 6 points");
  refused({{"label", {1, 2, 3, 4, 5, 2147483648u}}}, "expected values up to 2^31 - 1");
  Frame empty = small_frame(true);
  for (auto& p : empty.xyz) p = Eigen::Vector3f(kNan, kNan, kNan);
  EXPECT_THROW(proxseg::ply_bytes(empty, {}), InputError);
  EXPECT_EQ(proxseg::ply_bytes(empty, {}, PlyPoints::kAll).size(),
            proxseg::ply_bytes(f, {}, PlyPoints::kAll).size());
  // Nothing is left behind when the directory does not exist.
  const std::string missing = tmp_path("no_such_dir/out.ply");
  EXPECT_THROW(proxseg::write_ply(missing, f, {}), proxseg::FileError);
  EXPECT_FALSE(std::filesystem::exists(missing));
}
