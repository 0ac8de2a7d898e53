// The PCD reader on hand-made files: ascii, binary and binary_compressed data, mixed field types
// and padding, labels, clouds with and without colour.
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

TEST(IoPcd, AsciiWithFloatRgbLabelAndSkippedMultiValueField) {
  std::string s = header("x y z normal rgb label", "4 4 4 4 4 2", "F F F F F U", "1 1 1 3 1 1", 3,
                         1, 3, "ascii");
  s += "0.5 -1.25 2 0 0 1 " + float_text(packed_rgb_float(255, 128, 1)) + " 7\n";
  s += "nan nan nan 0 0 0 " + float_text(packed_rgb_float(0, 0, 0)) + " 0\n";
  s += "\n";  // blank lines are skipped
  s += "+1e-1 2.5E0 -3 1 0 0 " + float_text(packed_rgb_float(1, 2, 3)) + " 65535";  // no final \n
  const Frame f = proxseg::read_pcd(write_bytes("ascii.pcd", s));
  EXPECT_EQ(f.width, 3);
  EXPECT_EQ(f.height, 1);
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f.xyz[0], Eigen::Vector3f(0.5f, -1.25f, 2.0f));
  EXPECT_FALSE(f.valid(1));
  EXPECT_EQ(f.xyz[2], Eigen::Vector3f(0.1f, 2.5f, -3.0f));
  EXPECT_EQ(f.rgb[0], (proxseg::Rgb{255, 128, 1}));
  EXPECT_EQ(f.rgb[2], (proxseg::Rgb{1, 2, 3}));
  EXPECT_EQ(f.label, (std::vector<std::uint32_t>{7, 0, 65535}));
}

TEST(IoPcd, AsciiWithIntegerRgbaOrganized) {
  std::string s = header("rgba x y z", "4 4 4 4", "U F F F", "1 1 1 1", 2, 2, 4, "ascii");
  s += "16711680 1 2 3\n65280 4 5 6\r\n255 7 8 9\n4294967295 10 11 12\n";  // CRLF tolerated
  const Frame f = proxseg::read_pcd(write_bytes("ascii_rgba.pcd", s));
  EXPECT_EQ(f.width, 2);
  EXPECT_EQ(f.height, 2);
  EXPECT_TRUE(f.organized());
  ASSERT_EQ(f.size(), 4u);
  EXPECT_TRUE(f.label.empty());
  EXPECT_EQ(f.rgb[0], (proxseg::Rgb{255, 0, 0}));
  EXPECT_EQ(f.rgb[1], (proxseg::Rgb{0, 255, 0}));
  EXPECT_EQ(f.rgb[2], (proxseg::Rgb{0, 0, 255}));
  EXPECT_EQ(f.rgb[3], (proxseg::Rgb{255, 255, 255}));  // alpha byte dropped
  EXPECT_EQ(f.xyz[3], Eigen::Vector3f(10, 11, 12));
}

TEST(IoPcd, BinaryMixedTypesPaddingAndDoubleX) {
  // rgba first, a 1-byte padding field, x as double, signed 4-byte label.
  std::string s =
      header("rgba _ x y z label", "4 1 8 4 4 4", "U U F F F I", "1 1 1 1 1 1", 2, 1, 2, "binary");
  const std::uint32_t colours[2] = {0xFF102030u, 0x00405060u};
  for (int i = 0; i < 2; ++i) {
    append<std::uint32_t>(s, colours[i]);
    append<std::uint8_t>(s, 0xAB);
    append<double>(s, i == 0 ? 1.5 : std::numeric_limits<double>::quiet_NaN());
    append<float>(s, -2.0f);
    append<float>(s, 3.25f);
    append<std::int32_t>(s, 40 + i);
  }
  s += "trailing bytes are ignored";
  const Frame f = proxseg::read_pcd(write_bytes("binary.pcd", s));
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f.xyz[0], Eigen::Vector3f(1.5f, -2.0f, 3.25f));
  EXPECT_FALSE(f.valid(1));  // NaN x kept in file order
  EXPECT_EQ(f.rgb[0], (proxseg::Rgb{0x10, 0x20, 0x30}));
  EXPECT_EQ(f.rgb[1], (proxseg::Rgb{0x40, 0x50, 0x60}));
  EXPECT_EQ(f.label, (std::vector<std::uint32_t>{40, 41}));
}

TEST(IoPcd, BinaryCompressedLiteralRunsFieldByField) {
  std::string raw = compressed_raw_3pts();
  for (std::uint8_t l : {3, 4, 5}) append<std::uint8_t>(raw, l);
  const std::string s = header("x y z rgba label", "4 4 4 4 1", "F F F U U", "1 1 1 1 1", 3, 1, 3,
                               "binary_compressed") +
                        compressed_block(lzf_literals(raw), static_cast<std::uint32_t>(raw.size()));
  const Frame f = proxseg::read_pcd(write_bytes("compressed.pcd", s));
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f.xyz[0], Eigen::Vector3f(1, 10, 0.5f));
  EXPECT_FALSE(f.valid(1));
  EXPECT_EQ(f.xyz[2], Eigen::Vector3f(3, 30, 0.7f));
  EXPECT_EQ(f.rgb[0], (proxseg::Rgb{1, 2, 3}));
  EXPECT_EQ(f.rgb[2], (proxseg::Rgb{7, 8, 9}));
  EXPECT_EQ(f.label, (std::vector<std::uint32_t>{3, 4, 5}));
}

TEST(IoPcd, BinaryCompressedBackReference) {
  // 4 points; the label field (U1, all 9) is one literal byte followed by a back-reference
  // ctrl = (len - 2) << 5 = 1 << 5, offset byte 0 (offset 1): copies 3 bytes overlapping itself.
  std::string x, y, z, c;
  for (int i = 0; i < 4; ++i) {
    append<float>(x, static_cast<float>(i));
    append<float>(y, 1.f);
    append<float>(z, 2.f);
    append<std::uint32_t>(c, 0x112233u);
  }
  const std::string raw = x + y + z + c;
  std::string lzf = lzf_literals(raw);
  lzf += std::string("\x00\x09", 2);
  lzf += static_cast<char>(1 << 5);
  lzf += static_cast<char>(0);
  const std::string s = header("x y z rgb label", "4 4 4 4 1", "F F F F U", "1 1 1 1 1", 4, 1, 4,
                               "binary_compressed") +
                        compressed_block(lzf, static_cast<std::uint32_t>(raw.size() + 4));
  const Frame f = proxseg::read_pcd(write_bytes("compressed_backref.pcd", s));
  EXPECT_EQ(f.label, (std::vector<std::uint32_t>{9, 9, 9, 9}));
  EXPECT_EQ(f.xyz[3], Eigen::Vector3f(3, 1, 2));
  EXPECT_EQ(f.rgb[3], (proxseg::Rgb{0x11, 0x22, 0x33}));
}

TEST(IoPcd, CorruptCompressedNeverCrashes) {
  // Every truncation and every single-byte change of a small compressed file either reads or
  // throws InputError naming the file.
  std::string raw = compressed_raw_3pts();
  const std::string good =
      header("x y z rgb", "4 4 4 4", "F F F F", "1 1 1 1", 3, 1, 3, "binary_compressed") +
      compressed_block(lzf_literals(raw), static_cast<std::uint32_t>(raw.size()));
  const std::size_t data_start = good.find("DATA binary_compressed\n") + 23;
  int errors = 0;
  for (std::size_t len = data_start; len < good.size(); ++len) {
    const std::string path = write_bytes("cut.pcd", good.substr(0, len));
    expect_input_error([&] { proxseg::read_pcd(path); }, {"cut.pcd"});
    ++errors;
  }
  for (std::size_t i = data_start; i < data_start + 10; ++i) {
    for (int v : {0x00, 0x1f, 0x20, 0xe0, 0xff}) {
      std::string bad = good;
      bad[i] = static_cast<char>(v);
      const std::string path = write_bytes("flip.pcd", bad);
      try {
        proxseg::read_pcd(path);
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("flip.pcd"), std::string::npos);
        ++errors;
      }
    }
  }
  EXPECT_GT(errors, 40);
}

// An XYZ-only cloud in each DATA kind: read with Frame::rgb empty (no made-up colour).
TEST(IoPcd, XyzOnlyInEveryDataKindHasNoColour) {
  const std::string ascii =
      write_bytes("xyz_ascii.pcd", header("x y z", "4 4 4", "F F F", "1 1 1", 2, 1, 2, "ascii") +
                                       "1 2 3\nnan nan nan\n");
  std::string binary = header("x y z label", "4 4 4 4", "F F F U", "1 1 1 1", 2, 1, 2, "binary");
  for (int i = 0; i < 2; ++i) {
    append<float>(binary, 1.f + 3 * i);
    append<float>(binary, 2.f + 3 * i);
    append<float>(binary, 3.f + 3 * i);
    append<std::uint32_t>(binary, 7u + i);
  }
  std::string raw;  // field by field: all x, all y, all z
  for (float v : {1.f, 4.f, 2.f, 5.f, 3.f, 6.f}) append<float>(raw, v);
  const std::string compressed =
      header("x y z", "4 4 4", "F F F", "1 1 1", 2, 1, 2, "binary_compressed") +
      compressed_block(lzf_literals(raw), static_cast<std::uint32_t>(raw.size()));
  for (const auto& [name, text] :
       {std::pair{"xyz_binary.pcd", binary}, std::pair{"xyz_compressed.pcd", compressed}}) {
    const Frame f = proxseg::read_pcd(write_bytes(name, text));
    EXPECT_FALSE(f.coloured()) << name;
    EXPECT_TRUE(f.rgb.empty()) << name;
    ASSERT_EQ(f.size(), 2u) << name;
    EXPECT_EQ(f.xyz[0], Eigen::Vector3f(1, 2, 3)) << name;
    EXPECT_EQ(f.xyz[1], Eigen::Vector3f(4, 5, 6)) << name;
  }
  EXPECT_EQ(proxseg::read_pcd(tmp_path("xyz_binary.pcd")).label,
            (std::vector<std::uint32_t>{7, 8}));
  const Frame a = proxseg::read_pcd(ascii);
  EXPECT_FALSE(a.coloured());
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a.xyz[0], Eigen::Vector3f(1, 2, 3));
  EXPECT_FALSE(a.valid(1));
  // The same cloud with colours still reads them.
  EXPECT_TRUE(proxseg::read_pcd(write_bytes("xyzrgb.pcd", binary_xyzrgb(2, 2))).coloured());
}
