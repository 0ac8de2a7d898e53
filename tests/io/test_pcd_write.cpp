// Writing PCDs: round trips of organized clouds with labels and of clouds without colour, wrong
// field lengths, and atomic replacement that fails cleanly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <proxseg/core/errors.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <set>
#include <string>
#include <vector>

#include "support/io_files.hpp"

using namespace io_test;
using proxseg::Frame;
using proxseg::InputError;

TEST(IoWrite, PcdRoundTripOrganizedWithLabels) {
  Frame f;
  f.width = 3;
  f.height = 2;
  for (int i = 0; i < 6; ++i) {
    f.xyz.emplace_back(0.1f * i, -0.2f * i, 1.0f + i);
    f.rgb.push_back({static_cast<std::uint8_t>(40 * i), static_cast<std::uint8_t>(255 - i), 7});
  }
  f.xyz[4] = Eigen::Vector3f(kNan, kNan, kNan);
  const std::vector<std::uint32_t> labels = {0, 1, 20, 21, 0, 4000000000u};
  const std::string path = tmp_path("roundtrip.pcd");
  // DATA binary here (byte layout checked below); binary_compressed, the default, in
  // test_compressed_io.
  proxseg::write_pcd(path, f, {{"label", labels}, {"instance", {1, 2, 3, 4, 5, 6}}},
                     proxseg::PcdData::kBinary);

  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("VERSION 0.7\nFIELDS x y z rgb label instance\nSIZE 4 4 4 4 4 4\n"
                      "TYPE F F F F U U\nCOUNT 1 1 1 1 1 1\nWIDTH 3\nHEIGHT 2\n"
                      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 6\nDATA binary\n"),
            std::string::npos);
  EXPECT_EQ(text.size(), text.find("DATA binary\n") + 12 + 6 * 24);

  const Frame g = proxseg::read_point_cloud(path);
  EXPECT_EQ(g.width, 3);
  EXPECT_EQ(g.height, 2);
  ASSERT_EQ(g.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(g.valid(i), i != 4);
    if (i != 4) {
      EXPECT_EQ(g.xyz[i], f.xyz[i]);
    }
    EXPECT_EQ(g.rgb[i], f.rgb[i]);
  }
  EXPECT_EQ(g.label, labels);
  // No temporary files left next to it.
  for (const auto& e : fs::directory_iterator(tmp_dir()))
    EXPECT_EQ(e.path().filename().string().find(".roundtrip.pcd.tmp"), std::string::npos);
}

TEST(IoWrite, PcdRoundTripWithoutColour) {
  Frame f;
  f.width = 2;
  f.height = 2;
  for (int i = 0; i < 4; ++i) f.xyz.emplace_back(0.5f * i, -0.25f * i, 1.0f + i);
  const std::vector<std::uint32_t> labels = {3, 0, 1, 2};
  const std::string path = tmp_path("roundtrip_xyz.pcd");
  proxseg::write_pcd(path, f, {{"label", labels}}, proxseg::PcdData::kBinary);
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // x y z and the extra field only: no colour field, no made-up colour.
  EXPECT_NE(text.find("FIELDS x y z label\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 2\n"
                      "HEIGHT 2\n"),
            std::string::npos)
      << text.substr(0, 200);
  EXPECT_EQ(text.size(), text.find("DATA binary\n") + 12 + 4 * 16);
  const Frame g = proxseg::read_pcd(path);
  EXPECT_FALSE(g.coloured());
  EXPECT_EQ(g.width, 2);
  EXPECT_EQ(g.height, 2);
  EXPECT_EQ(g.xyz, f.xyz);
  EXPECT_EQ(g.label, labels);
  // A field named like the colour would be read back as colours; colours not one per point are
  // a caller's mistake.
  EXPECT_THROW(proxseg::pcd_bytes(f, {{"rgb", labels}}), proxseg::InputError);
  EXPECT_THROW(proxseg::pcd_bytes(f, {{"rgba", labels}}), proxseg::InputError);
  f.rgb = {{1, 2, 3}};
  EXPECT_THROW(proxseg::pcd_bytes(f, {}), proxseg::InputError);
}

TEST(IoWrite, PcdRejectsWrongFieldLength) {
  Frame f;
  f.width = 2;
  f.height = 1;
  f.xyz = {{0, 0, 1}, {1, 0, 1}};
  f.rgb = {{1, 2, 3}, {4, 5, 6}};
  const std::string path = tmp_path("bad_field.pcd");
  fs::remove(path);
  EXPECT_THROW(proxseg::write_pcd(path, f, {{"label", {1}}}), proxseg::InputError);
  EXPECT_THROW(proxseg::write_pcd(path, f, {{"rgb", {1, 2}}}), proxseg::InputError);
  EXPECT_THROW(proxseg::write_pcd(path, f, {{"two words", {1, 2}}}), proxseg::InputError);
  EXPECT_FALSE(fs::exists(path));
}

TEST(IoWrite, AtomicWriteReplacesAndFailsCleanly) {
  const std::string path = tmp_path("atomic.txt");
  proxseg::write_file_atomic(path, "first");
  proxseg::write_file_atomic(path, "second, longer");
  std::ifstream in(path);
  std::string content;
  std::getline(in, content);
  EXPECT_EQ(content, "second, longer");

  const fs::path missing_dir = fs::path(tmp_dir()) / "no_such_dir";
  fs::remove_all(missing_dir);
  const std::string bad = (missing_dir / "out.pcd").string();
  expect_input_error([&] { proxseg::write_file_atomic(bad, "x"); }, {bad, "cannot write"});
  EXPECT_FALSE(fs::exists(missing_dir));

  Frame f;
  f.width = 1;
  f.height = 1;
  f.xyz = {{0, 0, 1}};
  f.rgb = {{1, 2, 3}};
  expect_input_error([&] { proxseg::write_pcd(bad, f, {}); }, {"out.pcd", "cannot write"});
  EXPECT_FALSE(fs::exists(missing_dir));

  // The target is a directory: the rename fails, the temporary file is removed.
  const fs::path as_dir = fs::path(tmp_dir()) / "a_directory";
  fs::create_directories(as_dir / "child");
  expect_input_error([&] { proxseg::write_file_atomic(as_dir.string(), "x"); }, {"a_directory"});
  for (const auto& e : fs::directory_iterator(tmp_dir()))
    EXPECT_EQ(e.path().filename().string().find(".a_directory.tmp"), std::string::npos) << e.path();
}
