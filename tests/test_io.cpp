// Tests of the input/output layer: real data files, hand-made PCDs, round trips, and errors.
#include <gtest/gtest.h>
#include <iostream>

#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/output.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using proxseg::Frame;
using proxseg::InputError;

namespace {

const std::string kData = PROXSEG_DATA_DIR;
const float kNan = std::numeric_limits<float>::quiet_NaN();

std::string tmp_dir() {
  const fs::path d = fs::path(PROXSEG_TEST_TMP) / "io";
  fs::create_directories(d);
  return d.string();
}

std::string tmp_path(const std::string& name) {
  return (fs::path(tmp_dir()) / name).string();
}

std::string write_bytes(const std::string& name, const std::string& bytes) {
  const std::string path = tmp_path(name);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

template <typename T>
void append(std::string& s, T v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

float packed_rgb_float(std::uint32_t r, std::uint32_t g, std::uint32_t b) {
  const std::uint32_t v = (r << 16) | (g << 8) | b;
  float f;
  std::memcpy(&f, &v, 4);
  return f;
}

// Shortest text that parses back to exactly the same float.
std::string float_text(float f) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof(buf), f);
  return std::string(buf, r.ptr);
}

// A valid LZF stream made only of literal runs (ctrl = run length - 1, at most 32 bytes).
std::string lzf_literals(const std::string& raw) {
  std::string out;
  for (std::size_t i = 0; i < raw.size(); i += 32) {
    const std::size_t run = std::min<std::size_t>(32, raw.size() - i);
    out += static_cast<char>(run - 1);
    out += raw.substr(i, run);
  }
  return out;
}

std::string compressed_block(const std::string& lzf, std::uint32_t uncompressed_size) {
  std::string s;
  append<std::uint32_t>(s, static_cast<std::uint32_t>(lzf.size()));
  append<std::uint32_t>(s, uncompressed_size);
  return s + lzf;
}

// Runs fn, expects InputError whose one-line message contains every part.
void expect_input_error(const std::function<void()>& fn, const std::vector<std::string>& parts) {
  try {
    fn();
    ADD_FAILURE() << "expected InputError mentioning " << parts.front();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    for (const auto& p : parts)
      EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
  }
}

std::string header(const std::string& fields, const std::string& size, const std::string& type,
                   const std::string& count, int width, int height, long points,
                   const std::string& data) {
  std::ostringstream h;
  h << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS " << fields << "\nSIZE "
    << size << "\nTYPE " << type << "\nCOUNT " << count << "\nWIDTH " << width << "\nHEIGHT "
    << height << "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << points << "\nDATA " << data << "\n";
  return h.str();
}

// Binary x y z rgb (float) cloud of n points, point i = (i, 2i, 3i + 1), colour (i, 10, 20).
std::string binary_xyzrgb(int n, int points_in_header) {
  std::string s = header("x y z rgb", "4 4 4 4", "F F F F", "1 1 1 1", points_in_header, 1,
                         points_in_header, "binary");
  for (int i = 0; i < n; ++i) {
    append<float>(s, static_cast<float>(i));
    append<float>(s, 2.0f * i);
    append<float>(s, 3.0f * i + 1);
    append<float>(s, packed_rgb_float(static_cast<std::uint32_t>(i), 10, 20));
  }
  return s;
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// Real data

TEST(IoReal, MosdLearn0HasOrganizedGridLabelsAndNaNs) {
  const Frame f = proxseg::read_pcd(kData + "/mosd/learn/learn0.pcd");
  EXPECT_EQ(f.width, 640);
  EXPECT_EQ(f.height, 480);
  EXPECT_TRUE(f.organized());
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
  EXPECT_EQ(f.width, 12575);
  EXPECT_EQ(f.height, 1);
  EXPECT_FALSE(f.organized());
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

// ------------------------------------------------------------------------------------------------
// Hand-made PCDs

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

// Field-by-field layout: all x, all y, all z, all rgb, all labels (U1).
std::string compressed_raw_3pts() {
  std::string raw;
  for (float x : {1.f, 2.f, 3.f}) append<float>(raw, x);
  for (float y : {10.f, kNan, 30.f}) append<float>(raw, y);
  for (float z : {0.5f, 0.6f, 0.7f}) append<float>(raw, z);
  for (std::uint32_t c : {0x010203u, 0x040506u, 0x070809u}) append<std::uint32_t>(raw, c);
  return raw;
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

// ------------------------------------------------------------------------------------------------
// Writing

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

// ------------------------------------------------------------------------------------------------
// RGB-D and intrinsics

namespace {
proxseg::Intrinsics small_k() {
  proxseg::Intrinsics k;
  k.fx = 100;
  k.fy = 200;
  k.cx = 1;
  k.cy = 0.5;
  k.depth_scale = 1000;
  return k;
}
}  // namespace

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

// ------------------------------------------------------------------------------------------------
// Image decoding (libpng / libjpeg, src/io/formats/image_io.cpp) against OpenCV's
// cv::imread(IMREAD_UNCHANGED)

namespace {

void put_be32(std::string& s, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) s += static_cast<char>((v >> shift) & 0xff);
}

std::uint32_t crc32_of(const std::string& s) {
  std::uint32_t c = 0xffffffffu;
  for (unsigned char b : s) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

void png_chunk(std::string& png, const std::string& type, const std::string& data) {
  put_be32(png, static_cast<std::uint32_t>(data.size()));
  png += type + data;
  put_be32(png, crc32_of(type + data));
}

// zlib stream of stored (uncompressed) deflate blocks.
std::string zlib_stored(const std::string& raw) {
  std::string z = "\x78\x01";
  std::size_t at = 0;
  do {
    const std::size_t n = std::min<std::size_t>(65535, raw.size() - at);
    z += static_cast<char>(at + n == raw.size());
    z += static_cast<char>(n & 0xff);
    z += static_cast<char>(n >> 8);
    z += static_cast<char>(~n & 0xff);
    z += static_cast<char>((~n >> 8) & 0xff);
    z.append(raw, at, n);
    at += n;
  } while (at < raw.size());
  std::uint32_t a = 1, b = 0;
  for (unsigned char c : raw) a = (a + c) % 65521, b = (b + a) % 65521;
  put_be32(z, (b << 16) | a);
  return z;
}

// A PNG of any colour type, bit depth and interlace, with the kinds cv::imwrite cannot write
// (palette, grey + alpha, 1-4 bit grey, tRNS, gAMA, Adam7). samples: row-major, channels per
// pixel (palette: the index), each < 2^bit_depth.
struct PngSpec {
  std::string name;
  int width = 5, height = 3, bit_depth = 8, colour_type = 2;
  bool interlaced = false, gamma = false;
  std::string plte, trns;  // raw chunk data, empty = no chunk
  std::vector<unsigned> samples;
};

int png_channels(int colour_type) {
  switch (colour_type) {
    case 2:
      return 3;
    case 4:
      return 2;
    case 6:
      return 4;
    default:
      return 1;
  }
}

std::string make_png(const PngSpec& s) {
  const int ch = png_channels(s.colour_type);
  auto row_bytes = [&](const std::vector<int>& xs, int y) {
    std::string row(1, '\0');  // filter: none
    unsigned acc = 0;
    int bits = 0;
    for (int x : xs)
      for (int c = 0; c < ch; ++c) {
        const unsigned v = s.samples[(static_cast<std::size_t>(y) * s.width + x) * ch + c];
        if (s.bit_depth == 16) {
          row += static_cast<char>(v >> 8);
          row += static_cast<char>(v & 0xff);
          continue;
        }
        acc = (acc << s.bit_depth) | v;
        bits += s.bit_depth;
        if (bits == 8) row += static_cast<char>(acc), acc = 0, bits = 0;
      }
    if (bits) row += static_cast<char>(acc << (8 - bits));
    return row;
  };
  std::string raw;
  if (!s.interlaced) {
    std::vector<int> xs(s.width);
    for (int x = 0; x < s.width; ++x) xs[x] = x;
    for (int y = 0; y < s.height; ++y) raw += row_bytes(xs, y);
  } else {
    const int pass[7][4] = {{0, 0, 8, 8}, {4, 0, 8, 8}, {0, 4, 4, 8}, {2, 0, 4, 4},
                            {0, 2, 2, 4}, {1, 0, 2, 2}, {0, 1, 1, 2}};
    for (const auto& p : pass) {
      std::vector<int> xs;
      for (int x = p[0]; x < s.width; x += p[2]) xs.push_back(x);
      if (xs.empty()) continue;
      for (int y = p[1]; y < s.height; y += p[3]) raw += row_bytes(xs, y);
    }
  }
  std::string png = "\x89PNG\r\n\x1a\n";
  std::string ihdr;
  put_be32(ihdr, s.width);
  put_be32(ihdr, s.height);
  ihdr += static_cast<char>(s.bit_depth);
  ihdr += static_cast<char>(s.colour_type);
  ihdr += std::string(2, '\0');
  ihdr += static_cast<char>(s.interlaced);
  png_chunk(png, "IHDR", ihdr);
  if (s.gamma) {
    std::string g;
    put_be32(g, 45455);
    png_chunk(png, "gAMA", g);
  }
  if (!s.plte.empty()) png_chunk(png, "PLTE", s.plte);
  if (!s.trns.empty()) png_chunk(png, "tRNS", s.trns);
  png_chunk(png, "IDAT", zlib_stored(raw));
  png_chunk(png, "IEND", "");
  return png;
}

// Deterministic samples < 2^bits (or < limit), some at the extremes.
std::vector<unsigned> some_samples(std::size_t n, unsigned limit) {
  std::vector<unsigned> v(n);
  std::uint32_t x = 12345;
  for (std::size_t i = 0; i < n; ++i) {
    x = x * 1664525u + 1013904223u;
    v[i] = i % 7 == 0 ? limit - 1 : i % 11 == 0 ? 0 : (x >> 8) % limit;
  }
  return v;
}

std::string be16(unsigned v) {
  return {static_cast<char>(v >> 8), static_cast<char>(v & 0xff)};
}

std::vector<PngSpec> png_kinds() {
  std::vector<PngSpec> kinds;
  auto add = [&](std::string name, int type, int depth, std::string trns = "",
                 bool interlaced = false, bool gamma = false, int w = 5, int h = 3) {
    PngSpec s;
    s.name = std::move(name);
    s.colour_type = type;
    s.bit_depth = depth;
    s.trns = std::move(trns);
    s.interlaced = interlaced;
    s.gamma = gamma;
    s.width = w;
    s.height = h;
    unsigned limit = 1u << depth;
    if (type == 3) {
      const int entries = std::min(1 << depth, 6);
      for (int i = 0; i < entries; ++i)
        s.plte += std::string{static_cast<char>(40 * i), static_cast<char>(255 - 30 * i),
                              static_cast<char>(7 * i + 1)};
      limit = entries;
    }
    s.samples = some_samples(static_cast<std::size_t>(w) * h * png_channels(type), limit);
    kinds.push_back(s);
  };
  add("grey1", 0, 1);
  add("grey2", 0, 2);
  add("grey4", 0, 4);
  add("grey8", 0, 8);
  add("grey16", 0, 16);
  add("grey8_trns", 0, 8, be16(3));
  add("grey16_trns_gamma", 0, 16, be16(1000), false, true);
  add("rgb8", 2, 8);
  add("rgb8_gamma", 2, 8, "", false, true);
  add("rgb8_trns", 2, 8, be16(1) + be16(2) + be16(3));
  add("rgb16", 2, 16);
  add("palette1", 3, 1);
  add("palette2", 3, 2);
  add("palette4", 3, 4);
  add("palette8", 3, 8);
  add("palette8_trns", 3, 8, std::string("\x00\x80", 2));
  add("grey_alpha8", 4, 8);
  add("grey_alpha16", 4, 16);
  add("rgba8", 6, 8);
  add("rgba16", 6, 16);
  add("rgb8_adam7", 2, 8, "", true, false, 9, 7);
  add("grey16_adam7_gamma", 0, 16, "", true, true, 11, 10);
  add("palette4_adam7", 3, 4, "", true, false, 9, 7);
  add("grey1_adam7", 0, 1, "", true, false, 13, 9);
  return kinds;
}

std::string opencv_kind(const cv::Mat& m) {
  return (m.depth() == CV_16U ? std::string("16-bit ") : std::string("8-bit ")) +
         std::to_string(m.channels()) + "-channel";
}

// Checks that read_rgbd / read_label_image see the file as cv::imread(IMREAD_UNCHANGED) does.
void expect_read_like_opencv(const std::string& path) {
  SCOPED_TRACE(path);
  const cv::Mat ref = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(ref.empty());
  const int w = ref.cols, h = ref.rows;
  proxseg::Intrinsics k = small_k();
  if (ref.depth() == CV_8U) {
    const std::string depth = tmp_path("ones-depth.png");
    ASSERT_TRUE(cv::imwrite(depth, cv::Mat(h, w, CV_16UC1, cv::Scalar(1000))));
    const Frame f = proxseg::read_rgbd(path, depth, k);
    ASSERT_EQ(f.width, w);
    ASSERT_EQ(f.height, h);
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        const std::uint8_t* p = ref.ptr<std::uint8_t>(v) + u * ref.channels();
        const proxseg::Rgb want =
            ref.channels() == 1 ? proxseg::Rgb{p[0], p[0], p[0]} : proxseg::Rgb{p[2], p[1], p[0]};
        ASSERT_EQ(f.rgb[v * w + u], want) << u << "," << v;
      }
    if (ref.channels() == 1) {
      const auto labels = proxseg::read_label_image(path, w, h);
      for (int v = 0; v < h; ++v)
        for (int u = 0; u < w; ++u) ASSERT_EQ(labels[v * w + u], ref.at<std::uint8_t>(v, u));
    } else {
      expect_input_error([&] { proxseg::read_label_image(path, w, h); },
                         {"label image is " + opencv_kind(ref)});
    }
  } else if (ref.channels() == 1) {
    const std::string colour = tmp_path("grey-color.png");
    ASSERT_TRUE(cv::imwrite(colour, cv::Mat(h, w, CV_8UC1, cv::Scalar(9))));
    bool any = false;
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) any = any || ref.at<std::uint16_t>(v, u) > 0;
    if (!any) return;
    const Frame f = proxseg::read_rgbd(colour, path, k);
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        const std::uint16_t d = ref.at<std::uint16_t>(v, u);
        const float z = f.xyz[v * w + u].z();
        if (d == 0)
          ASSERT_TRUE(std::isnan(z)) << u << "," << v;
        else
          ASSERT_EQ(z, static_cast<float>(d / k.depth_scale)) << u << "," << v;
      }
  } else {
    const std::string depth = tmp_path("ones-depth.png");
    ASSERT_TRUE(cv::imwrite(depth, cv::Mat(h, w, CV_16UC1, cv::Scalar(1000))));
    expect_input_error([&] { proxseg::read_rgbd(path, depth, k); },
                       {"colour image is " + opencv_kind(ref)});
  }
}

}  // namespace

TEST(IoImages, PngKindsReadLikeOpenCv) {
  for (const PngSpec& s : png_kinds())
    expect_read_like_opencv(write_bytes(s.name + ".png", make_png(s)));
}

// What OpenCV does, spelled out: 1-bit grey is 0 or 255; 16-bit depth is exact whatever the gAMA
// chunk says; alpha is dropped, never multiplied into the colour; palette indices become colours.
TEST(IoImages, PngValuesAreExact) {
  PngSpec s;
  s.width = 4;
  s.height = 2;
  s.colour_type = 0;
  s.bit_depth = 1;
  s.samples = {1, 0, 1, 1, 0, 0, 1, 0};
  const std::string g1 = write_bytes("g1.png", make_png(s));
  EXPECT_EQ(proxseg::read_label_image(g1, 4, 2),
            (std::vector<std::uint8_t>{255, 0, 255, 255, 0, 0, 255, 0}));

  const std::vector<unsigned> depth = {0, 1, 1000, 65535, 12345, 2, 0, 40000};
  s.bit_depth = 16;
  s.gamma = true;
  s.samples = depth;
  const std::string d16 = write_bytes("d16.png", make_png(s));
  s.colour_type = 6;
  s.bit_depth = 8;
  s.gamma = false;
  s.samples.clear();
  for (unsigned i = 0; i < 8; ++i)
    s.samples.insert(s.samples.end(), {200u, 100u, 50u + i, i % 2 ? 0u : 128u});
  const std::string rgba = write_bytes("rgba.png", make_png(s));
  proxseg::Intrinsics k = small_k();
  k.depth_scale = 1;
  const Frame f = proxseg::read_rgbd(rgba, d16, k);
  for (std::size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(f.rgb[i], (proxseg::Rgb{200, 100, static_cast<std::uint8_t>(50 + i)})) << i;
    if (depth[i] == 0)
      EXPECT_TRUE(std::isnan(f.xyz[i].z())) << i;
    else
      EXPECT_EQ(f.xyz[i].z(), static_cast<float>(depth[i])) << i;
  }

  PngSpec p;
  p.width = 4;
  p.height = 2;
  p.colour_type = 3;
  p.plte = std::string("\x01\x02\x03\xff\x80\x00", 6);
  p.samples = {0, 1, 1, 0, 0, 1, 1, 1};
  const std::string pal = write_bytes("pal.png", make_png(p));
  const Frame q = proxseg::read_rgbd(pal, d16, k);
  for (std::size_t i = 0; i < 8; ++i)
    EXPECT_EQ(q.rgb[i], p.samples[i] ? (proxseg::Rgb{255, 128, 0}) : (proxseg::Rgb{1, 2, 3})) << i;
}

// JPEG colour and grey (also under a .png name: the content decides), as OpenCV decodes them
// (the same libjpeg).
TEST(IoImages, JpegReadsLikeOpenCv) {
  cv::Mat colour(24, 33, CV_8UC3), grey(24, 33, CV_8UC1);
  for (int v = 0; v < colour.rows; ++v)
    for (int u = 0; u < colour.cols; ++u) {
      colour.at<cv::Vec3b>(v, u) =
          cv::Vec3b(static_cast<std::uint8_t>(7 * u), static_cast<std::uint8_t>(10 * v),
                    static_cast<std::uint8_t>(u * v));
      grey.at<std::uint8_t>(v, u) = static_cast<std::uint8_t>(3 * u + 5 * v);
    }
  const std::string c = tmp_path("colour.jpg"), g = tmp_path("grey.jpg");
  ASSERT_TRUE(cv::imwrite(c, colour));
  ASSERT_TRUE(cv::imwrite(g, grey));
  expect_read_like_opencv(c);
  expect_read_like_opencv(g);
  std::ifstream in(c, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  expect_read_like_opencv(write_bytes("jpeg-named.png", bytes));
}

// Broken images are InputErrors naming the file, and nothing is printed (stdout carries the
// CLI's JSON; libpng and libjpeg print warnings on stderr by default).
TEST(IoImages, BrokenImagesAreInputErrorsAndPrintNothing) {
  PngSpec s;
  s.width = 40;
  s.height = 30;
  s.samples = some_samples(40 * 30 * 3, 256);
  const std::string png = make_png(s);
  const std::string depth = tmp_path("depth-40x30.png");
  ASSERT_TRUE(cv::imwrite(depth, cv::Mat(30, 40, CV_16UC1, cv::Scalar(1000))));
  cv::Mat colour(30, 40, CV_8UC3, cv::Scalar(10, 20, 30));
  std::vector<std::uint8_t> jpeg_bytes;
  ASSERT_TRUE(cv::imencode(".jpg", colour, jpeg_bytes));
  const std::string jpeg(jpeg_bytes.begin(), jpeg_bytes.end());

  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  ASSERT_EQ(proxseg::read_rgbd(write_bytes("whole.png", png), depth, small_k()).width, 40);
  for (const std::size_t cut : {std::size_t{1}, std::size_t{8}, std::size_t{20}, std::size_t{33},
                                std::size_t{60}, png.size() / 2, png.size() - 13, png.size() - 1})
    expect_input_error(
        [&] { proxseg::read_rgbd(write_bytes("cut.png", png.substr(0, cut)), depth, small_k()); },
        {"cut.png"});
  std::string bad_crc = png;
  bad_crc[29] ^= 1;  // IHDR's CRC
  expect_input_error([&] { proxseg::read_rgbd(write_bytes("crc.png", bad_crc), depth, small_k()); },
                     {"crc.png", "PNG"});
  std::string bad_data = png;
  bad_data[png.size() / 2] ^= 0x55;  // inside IDAT: its CRC no longer matches
  expect_input_error(
      [&] { proxseg::read_rgbd(write_bytes("data.png", bad_data), depth, small_k()); },
      {"data.png"});
  expect_input_error(
      [&] {
        proxseg::read_rgbd(write_bytes("sig.png", "\x89PNX\r\n\x1a\nabcdefgh"), depth, small_k());
      },
      {"sig.png"});
  expect_input_error([&] { proxseg::read_rgbd(write_bytes("empty.png", ""), depth, small_k()); },
                     {"empty.png", "cannot read image"});
  expect_input_error(
      [&] { proxseg::read_rgbd(write_bytes("text.png", "P6 40 30 255"), depth, small_k()); },
      {"text.png", "expected a PNG or JPEG"});
  // A header claiming 30000 x 30000 pixels: refused before anything is allocated.
  std::string huge = png;
  huge.replace(16, 8, std::string("\x00\x00\x75\x30\x00\x00\x75\x30", 8));
  const std::uint32_t crc = crc32_of(huge.substr(12, 17));
  for (int b = 0; b < 4; ++b) huge[29 + b] = static_cast<char>(crc >> (24 - 8 * b));
  expect_input_error([&] { proxseg::read_rgbd(write_bytes("huge.png", huge), depth, small_k()); },
                     {"huge.png", "30000x30000", "8192x8192"});
  // JPEG: corrupt headers and data are errors (libjpeg's default handler would exit the
  // process); a truncated scan is completed by libjpeg, as OpenCV accepts it.
  expect_input_error(
      [&] {
        proxseg::read_rgbd(write_bytes("junk.jpg", "\xff\xd8\xff\xe0junkjunkjunk"), depth,
                           small_k());
      },
      {"junk.jpg", "JPEG"});
  expect_input_error(
      [&] { proxseg::read_rgbd(write_bytes("soi.jpg", jpeg.substr(0, 2)), depth, small_k()); },
      {"soi.jpg", "JPEG"});
  for (const std::size_t cut :
       {std::size_t{1}, std::size_t{30}, jpeg.size() / 2, jpeg.size() - 2}) {
    try {
      const Frame f =
          proxseg::read_rgbd(write_bytes("cut.jpg", jpeg.substr(0, cut)), depth, small_k());
      EXPECT_EQ(f.width, 40);
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("cut.jpg"), std::string::npos) << e.what();
    }
  }
  const std::string out = testing::internal::GetCapturedStdout();
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(out, "");
  EXPECT_EQ(err, "");
}

// The output picture: a PNG (8-bit RGB) of exactly the pixels drawn, in the right channel order.
TEST(IoImages, LabelPictureIsAPngOfThePixels) {
  Frame f;
  f.width = 7;
  f.height = 5;
  for (int i = 0; i < 35; ++i) {
    f.xyz.emplace_back(0.01f * (i % 7), 0.01f * (i / 7), 1.0f);
    f.rgb.push_back({static_cast<std::uint8_t>(250 - i), static_cast<std::uint8_t>(3 * i), 90});
  }
  std::vector<std::uint32_t> labels(35, 0);
  for (int i = 20; i < 35; ++i) labels[i] = 1 + i % 2;
  const std::string png = proxseg::label_image_png(f, labels);
  ASSERT_GT(png.size(), 33u);
  EXPECT_EQ(png.substr(0, 8), "\x89PNG\r\n\x1a\n");
  EXPECT_EQ(png.substr(12, 4), "IHDR");
  EXPECT_EQ(png[24], 8);  // bit depth
  EXPECT_EQ(png[25], 2);  // RGB
  const cv::Mat m =
      cv::imdecode(std::vector<std::uint8_t>(png.begin(), png.end()), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(m.type(), CV_8UC3);
  ASSERT_EQ(m.cols, 7);
  ASSERT_EQ(m.rows, 5);
  for (int i = 0; i < 20; ++i) {  // unlabelled: the colour dimmed to a third (BGR in OpenCV)
    const proxseg::Rgb& c = f.rgb[i];
    EXPECT_EQ(m.at<cv::Vec3b>(i / 7, i % 7), cv::Vec3b(c[2] / 3, c[1] / 3, c[0] / 3)) << i;
  }
  // The same pixels through proxseg's own reader.
  const std::string path = write_bytes("labels.png", png);
  const std::string depth = tmp_path("depth-7x5.png");
  ASSERT_TRUE(cv::imwrite(depth, cv::Mat(5, 7, CV_16UC1, cv::Scalar(1000))));
  const Frame back = proxseg::read_rgbd(path, depth, small_k());
  for (int i = 0; i < 35; ++i) {
    const cv::Vec3b b = m.at<cv::Vec3b>(i / 7, i % 7);
    EXPECT_EQ(back.rgb[i], (proxseg::Rgb{b[2], b[1], b[0]})) << i;
  }
}

// A frame without colours is drawn grey by depth: the nearer, the lighter; invalid pixels black.
TEST(IoImages, ColourlessPicturesAreGreyByDepth) {
  Frame f;
  f.width = 7;
  f.height = 5;
  for (int i = 0; i < 35; ++i) f.xyz.emplace_back(0.01f * (i % 7), 0.01f * (i / 7), 1.0f + i / 7);
  f.xyz[3] = Eigen::Vector3f(kNan, kNan, kNan);
  ASSERT_FALSE(f.coloured());
  std::vector<std::uint32_t> labels(35, 0);
  for (int i = 28; i < 35; ++i) labels[i] = 1;
  const std::string png = proxseg::label_image_png(f, labels);
  const cv::Mat m =
      cv::imdecode(std::vector<std::uint8_t>(png.begin(), png.end()), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(m.type(), CV_8UC3);
  ASSERT_EQ(m.cols, 7);
  ASSERT_EQ(m.rows, 5);
  EXPECT_EQ(m.at<cv::Vec3b>(0, 3), cv::Vec3b(0, 0, 0));  // invalid
  int previous = 256;
  for (int v = 0; v < 4; ++v) {  // unlabelled rows, one depth each, further down the image
    const cv::Vec3b c = m.at<cv::Vec3b>(v, 0);
    EXPECT_EQ(c[0], c[1]) << v;
    EXPECT_EQ(c[1], c[2]) << v;
    EXPECT_LT(c[0], previous) << v;
    EXPECT_GT(c[0], 0) << v;
    previous = c[0];
  }
  // Unorganized: the points seen from the sensor, grey too (no colour to read).
  f.height = 1;
  f.width = 35;
  const std::string cloud = proxseg::label_image_png(f, labels);
  const cv::Mat r =
      cv::imdecode(std::vector<std::uint8_t>(cloud.begin(), cloud.end()), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(r.cols, 640);
  EXPECT_EQ(r.rows, 480);
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

// ------------------------------------------------------------------------------------------------
// Point-cloud errors

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
  auto check = [](const std::string& name, const std::string& text,
                  const std::vector<std::string>& parts) {
    const std::string path = write_bytes(name, text);
    std::vector<std::string> all = parts;
    all.insert(all.begin(), name);
    expect_input_error([&] { proxseg::read_pcd(path); }, all);
  };
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
  auto check = [](const std::string& name, const std::string& text,
                  const std::vector<std::string>& parts) {
    const std::string path = write_bytes(name, text);
    std::vector<std::string> all = parts;
    all.insert(all.begin(), name);
    expect_input_error([&] { proxseg::read_pcd(path); }, all);
  };
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
  check("ascii_count.pcd",
        header("x y z rgb", "4 4 4 4", "F F F F", "1 1 1 1", 2, 1, 2, "ascii") + "1 2 3 0\n1 2 3\n",
        {"line 13", "3 values", "expected 4"});
  check("ascii_nan_text.pcd",
        header("x y z rgb", "4 4 4 4", "F F F F", "1 1 1 1", 1, 1, 1, "ascii") + "1 two 3 0\n",
        {"line 12", "two"});
  check("ascii_short.pcd",
        header("x y z rgb", "4 4 4 4", "F F F F", "1 1 1 1", 3, 1, 3, "ascii") + "1 2 3 0\n",
        {"1 data line", "POINTS 3"});
  check(
      "ascii_long.pcd",
      header("x y z rgb", "4 4 4 4", "F F F F", "1 1 1 1", 1, 1, 1, "ascii") + "1 2 3 0\n4 5 6 0\n",
      {"line 13", "beyond POINTS"});
  // All-NaN cloud: zero valid points.
  check("all_nan.pcd",
        header("x y z rgb", "4 4 4 4", "F F F F", "1 1 1 1", 2, 1, 2, "ascii") +
            "nan nan nan 0\nnan 1 2 0\n",
        {"no valid points"});
  check("neg_label.pcd",
        header("x y z rgb label", "4 4 4 4 4", "F F F F I", "1 1 1 1 1", 1, 1, 1, "ascii") +
            "1 2 3 0 -5\n",
        {"label"});
}

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
