// Point-cloud errors: a missing file, an unknown extension, and malformed PCD headers and data,
// each a one-line InputError naming the file.
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

// The header of an ascii x y z rgb cloud of n points in one row.
std::string ascii_header(int n) {
  return header("x y z rgb", "4 4 4 4", "F F F F", "1 1 1 1", n, 1, n, "ascii");
}

}  // namespace

TEST(IoErrors, MissingFileAndUnknownExtension) {
  expect_input_error([] { proxseg::read_point_cloud(tmp_path("missing.pcd")); }, {"missing.pcd"});
  expect_input_error([] { proxseg::read_point_cloud(tmp_path("missing.ply")); }, {"missing.ply"});
  const std::string xyz = write_bytes("cloud.xyz", "1 2 3\n");
  expect_input_error([&] { proxseg::read_point_cloud(xyz); }, {"cloud.xyz", ".xyz"});
  // Extensions are case-insensitive.
  const std::string upper = write_bytes("UPPER.PCD", binary_xyzrgb(2, 2));
  EXPECT_EQ(proxseg::read_point_cloud(upper).size(), 2u);
  expect_input_error([] { proxseg::read_pcd(tmp_dir()); }, {"directory"});
}

TEST(IoErrors, HeaderProblems) {
  const auto check = expect_pcd_error;
  check("no_xyz.pcd", header("x y rgb", "4 4 4", "F F F", "1 1 1", 1, 1, 1, "ascii") + "1 2 3\n",
        {"x/y/z"});
  // No colour field is an XYZ-only cloud (IoPcd.XyzOnlyInEveryDataKindHasNoColour); one that is
  // there but not a packed colour is still an error.
  check("short_colour.pcd",
        header("x y z rgb", "4 4 4 2", "F F F U", "1 1 1 1", 1, 1, 1, "ascii") + "1 2 3 4\n",
        {"rgb", "4 bytes"});
  check("two_colours.pcd",
        header("x y z rgba", "4 4 4 4", "F F F U", "1 1 1 2", 1, 1, 1, "ascii") + "1 2 3 4 5\n",
        {"rgba", "COUNT 1"});
  check("points_mismatch.pcd",
        header("x y z rgb", "4 4 4 4", "F F F F", "1 1 1 1", 4, 2, 7, "ascii"), {"POINTS", "8"});
  check("bad_line.pcd", "VERSION 0.7\nFIELDS x y z rgb\nHELLO world\n", {"line 3", "HELLO"});
  check("no_data.pcd", "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\n", {"DATA"});
  check("no_width.pcd", "FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nHEIGHT 1\nDATA ascii\n",
        {"WIDTH"});
  check("size_count.pcd",
        header("x y z rgb", "4 4 4", "F F F F", "1 1 1 1", 1, 1, 1, "ascii") + "1 2 3 4\n",
        {"SIZE"});
  check("bad_type.pcd",
        header("x y z rgb", "4 4 4 4", "F F F Q", "1 1 1 1", 1, 1, 1, "ascii") + "1 2 3 4\n",
        {"TYPE"});
  check("bad_data.pcd", header("x y z rgb", "4 4 4 4", "F F F F", "1 1 1 1", 1, 1, 1, "zip"),
        {"DATA", "zip"});
  check("empty.pcd", "", {"empty"});
  check("png_as.pcd", std::string("\x89PNG\r\n\x1a\n\0\0\0", 11), {"line 1"});
}

TEST(IoErrors, DataProblems) {
  const auto check = expect_pcd_error;
  // Binary shorter than POINTS * point size.
  std::string trunc = binary_xyzrgb(5, 5);
  trunc.resize(trunc.size() - 3);
  check("truncated.pcd", trunc, {"truncated"});
  // A huge header on a tiny file: no allocation, just an error.
  check("huge.pcd", binary_xyzrgb(1, 2000000000), {"truncated"});
  // Compressed: sizes larger than the file, inconsistent sizes, corrupt LZF.
  const std::string raw = compressed_raw_3pts();
  const std::string ch =
      header("x y z rgb", "4 4 4 4", "F F F F", "1 1 1 1", 3, 1, 3, "binary_compressed");
  const std::string lzf = lzf_literals(raw);
  check("ctrunc.pcd", ch + compressed_block(lzf, 48).substr(0, 30), {"truncated"});
  check("csize.pcd", ch + compressed_block(lzf, 47), {"47", "48"});
  std::string corrupt = ch + compressed_block(std::string("\x00\x01\x40\x05", 4) + lzf, 48);
  check("ccorrupt.pcd", corrupt, {"corrupt"});
  std::string short_lzf = ch + compressed_block(lzf.substr(0, lzf.size() - 10), 48);
  check("cshort.pcd", short_lzf, {"corrupt"});
  check("chuge.pcd",
        header("x y z rgb", "4 4 4 4", "F F F F", "1 1 1 1", 200000000, 1, 200000000,
               "binary_compressed") +
            compressed_block(std::string("\x00\x01", 2), 3200000000u),
        {"chuge.pcd"});
  // Ascii line with the wrong number of values names the line (header is 11 lines).
  check("ascii_count.pcd", ascii_header(2) + "1 2 3 0\n1 2 3\n",
        {"line 13", "3 values", "expected 4"});
  check("ascii_nan_text.pcd", ascii_header(1) + "1 two 3 0\n", {"line 12", "two"});
  check("ascii_short.pcd", ascii_header(3) + "1 2 3 0\n", {"1 data line", "POINTS 3"});
  check("ascii_long.pcd", ascii_header(1) + "1 2 3 0\n4 5 6 0\n", {"line 13", "beyond POINTS"});
  // All-NaN cloud: zero valid points.
  check("all_nan.pcd", ascii_header(2) + "nan nan nan 0\nnan 1 2 0\n", {"no valid points"});
  check("neg_label.pcd",
        header("x y z rgb label", "4 4 4 4 4", "F F F F I", "1 1 1 1 1", 1, 1, 1, "ascii") +
            "1 2 3 0 -5\n",
        {"label"});
}
