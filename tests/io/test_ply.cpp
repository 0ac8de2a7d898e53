// The PLY reader: clouds without colour, big-endian doubles, extra elements and quads, and
// malformed headers and bodies.
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

TEST(IoPly, WithoutColoursIsXyzOnly) {
  const std::string ascii =
      write_bytes("nocolour.ply",
                  "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                  "property float z\nend_header\n0 0 0.5\n1 1 1\n");
  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  for (int i = 0; i < 3; ++i)
    for (float v : {0.1f * i, -0.2f * i, 1.0f + i}) append<float>(binary, v);
  const Frame a = proxseg::read_ply(ascii);
  EXPECT_FALSE(a.coloured());
  EXPECT_EQ(a.height, 1);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a.xyz[0], Eigen::Vector3f(0, 0, 0.5f));
  EXPECT_EQ(a.xyz[1], Eigen::Vector3f(1, 1, 1));
  const Frame b = proxseg::read_point_cloud(write_bytes("nocolour_binary.ply", binary));
  EXPECT_FALSE(b.coloured());
  ASSERT_EQ(b.size(), 3u);
  EXPECT_EQ(b.xyz[2], Eigen::Vector3f(0.2f, -0.4f, 3.0f));
}

// Big-endian binary with double coordinates and uchar colours, an element before the vertices
// (skipped) and a quad face fanned into two triangles: what read_ply and read_mesh make of it.
TEST(IoPly, BigEndianDoublesExtraElementsAndQuads) {
  auto big = [](std::string& out, auto v) {
    char bytes[sizeof v];
    std::memcpy(bytes, &v, sizeof v);
    std::reverse(bytes, bytes + sizeof v);
    out.append(bytes, sizeof v);
  };
  std::string ply =
      "ply\nformat binary_big_endian 1.0\ncomment made by hand\nelement camera 1\n"
      "property int id\nelement vertex 4\nproperty double x\nproperty double y\n"
      "property double z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  big(ply, std::int32_t{42});
  const double xyz[4][3] = {{0, 0, 1}, {0.5, 0, 1}, {0.5, 0.25, 1.5}, {0, 0.25, 1.5}};
  for (int i = 0; i < 4; ++i) {
    for (double v : xyz[i]) big(ply, v);
    for (std::uint8_t c : {std::uint8_t(10 * i), std::uint8_t(20), std::uint8_t(255)})
      ply.push_back(static_cast<char>(c));
  }
  ply.push_back(4);
  for (std::int32_t v : {0, 1, 2, 3}) big(ply, v);
  const std::string path = write_bytes("big_endian.ply", ply);
  const Frame f = proxseg::read_ply(path);
  ASSERT_EQ(f.size(), 4u);
  EXPECT_EQ(f.xyz[2], Eigen::Vector3f(0.5f, 0.25f, 1.5f));
  EXPECT_EQ(f.rgb[3], (proxseg::Rgb{30, 20, 255}));
  const proxseg::Mesh m = proxseg::read_mesh(path);
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.triangles[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(m.triangles[1], Eigen::Vector3i(0, 2, 3));
}

// Malformed headers and bodies: an InputError naming the file and what was expected, never a
// crash or an allocation the file cannot back.
TEST(IoErrors, PlyHeadersAndBodies) {
  const std::string vertex3 =
      "element vertex 2\nproperty float x\nproperty float y\nproperty float z\n";
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {"ply\nelement vertex 1\nproperty float x\nend_header\n0\n", {"no format line"}},
      {"ply\nformat text 1.0\n" + vertex3 + "end_header\n", {"header line 2", "format"}},
      {"ply\nformat ascii 1.0\n" + vertex3, {"no end_header"}},
      {"ply\nformat ascii 1.0\nelement vertex two\nend_header\n", {"whole count"}},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n0\n",
       {"header line 4", "property TYPE NAME"}},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "end_header\n0 0\n",
       {"no x, y and z"}},
      {"ply\nformat ascii 1.0\nvertices 3\nend_header\n", {"unknown keyword 'vertices'"}},
      {"ply\nformat ascii 1.0\n" + vertex3 + "end_header\n0 0 1\n0 zero 1\n",
       {"vertex 1", "'zero' is not a number"}},
      {"ply\nformat ascii 1.0\n" + vertex3 + "end_header\n0 0 1\n", {"2 vertex records"}},
      {"ply\nformat binary_little_endian 1.0\n" + vertex3 + "end_header\n" + std::string(12, '\0'),
       {"2 vertex records", "only 12 bytes"}},
      {"ply\nformat ascii 1.0\n" + vertex3 +
           "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 1\n1 0 1\n"
           "3 0 1 -4\n",
       {"face 0", "vertex index -4"}},
      {"ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\n"
       "end_header\n",
       {"no vertex element"}},
  };
  int n = 0;
  for (const auto& [text, parts] : cases) {
    const std::string name = "bad" + std::to_string(n++) + ".ply";
    const std::string path = write_bytes(name, text);
    std::vector<std::string> want = parts;
    want.push_back(name);
    expect_input_error([&] { proxseg::read_mesh(path); }, want);
  }
}

TEST(IoErrors, PlyProblems) {
  const std::string garbage = write_bytes("garbage.ply", "not a ply file at all\n");
  expect_input_error([&] { proxseg::read_ply(garbage); }, {"garbage.ply"});
  // A vertex count the file cannot hold is rejected before anything is allocated.
  const std::string huge = write_bytes(
      "huge.ply",
      "ply\nformat ascii 1.0\nelement vertex 2000000000\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
      "end_header\n0 0 0 1 2 3\n");
  expect_input_error([&] { proxseg::read_ply(huge); }, {"huge.ply", "2000000000"});
  const std::string coloured = write_bytes(
      "coloured.ply",
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
      "end_header\n0 0 0 255 128 0\n1 1 1 1 2 3\n");
  const Frame f = proxseg::read_ply(coloured);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f.rgb[0], (proxseg::Rgb{255, 128, 0}));
  EXPECT_EQ(f.rgb[1], (proxseg::Rgb{1, 2, 3}));
  EXPECT_EQ(f.xyz[1], Eigen::Vector3f(1, 1, 1));
}
