// Clouds told apart by their content (read_point_cloud_bytes, cloud_io.hpp): the same frames as
// the readers of files give, from PCD (ascii, binary, binary_compressed, comments first) and PLY
// bytes, and errors naming the given name for anything else. Standard input is the CLI's
// (tests/cli/test_cli_unix.cpp).
#include <gtest/gtest.h>

#include <proxseg/core/errors.hpp>
#include <proxseg/io/cloud_io.hpp>

#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "support/io_files.hpp"

using namespace io_test;
using proxseg::Frame;
using proxseg::read_point_cloud_bytes;

namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The same frame, bit for bit (invalid points are NaN).
void expect_same(const Frame& a, const Frame& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  ASSERT_EQ(a.xyz.size(), b.xyz.size());
  EXPECT_EQ(std::memcmp(a.xyz.data(), b.xyz.data(), a.xyz.size() * sizeof a.xyz[0]), 0);
  EXPECT_EQ(a.rgb, b.rgb);
  EXPECT_EQ(a.label, b.label);
}

}  // namespace

TEST(IoCloudContent, PcdAndPlyBytesReadAsTheirFiles) {
  for (const std::string& file : {kData + "/mosd/learn/learn0.pcd", kData + "/pcl/milk.pcd",
                                  kData + "/lmo/models/obj_000001.ply"}) {
    SCOPED_TRACE(file);
    const Frame bytes = read_point_cloud_bytes(slurp(file), "<memory>");
    expect_same(bytes, proxseg::read_point_cloud(file));
  }
  // ascii and binary PCDs, with comment lines first or none.
  const std::string binary = binary_xyzrgb(3, 3);
  expect_same(read_point_cloud_bytes(binary, "b"), proxseg::read_pcd(write_bytes("b.pcd", binary)));
  const std::string ascii =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
      "POINTS 2\nDATA ascii\n1 2 3\n4 5 6\n";
  const Frame a = read_point_cloud_bytes(ascii, "a");
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a.xyz[1], Eigen::Vector3f(4, 5, 6));
  EXPECT_FALSE(a.coloured());
}

TEST(IoCloudContent, AnythingElseIsRefusedNamingIt) {
  const std::pair<std::string, std::string> cases[] = {
      {"", "is neither a PCD nor a PLY cloud"},
      {"hello\nworld\n", "is neither a PCD nor a PLY cloud"},
      {"# only a comment\n", "is neither"},
      {std::string(100000, '\0'), "is neither"},
      {" ply\n", "is neither"},  // the PLY magic is the whole first line
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n",
       "PLY vertex element has no x, y and z properties"},
      {"# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\n", "header has no DATA line"},
  };
  for (const auto& [bytes, message] : cases)
    expect_input_error([&] { read_point_cloud_bytes(bytes, "<piped>"); }, {"<piped>: ", message});
}
