// Tests of the compact outputs: the LZF compressor, PCD binary_compressed writing (checked against
// our reader and Open3D's), and 16-bit label PNGs.
#include <gtest/gtest.h>

#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>
#include <cmath>
#include <cstdint>
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
#include <random>
#include <string>
#include <vector>

#include "io/formats/lzf.hpp"

namespace fs = std::filesystem;
using proxseg::Frame;
using proxseg::InputError;
using proxseg::PcdData;

namespace {

const std::string kData = PROXSEG_DATA_DIR;
const std::string kScene = kData + "/mosd/learn/learn0.pcd";

std::string tmp_path(const std::string& name) {
  const fs::path d = fs::path(PROXSEG_TEST_TMP) / "compressed_io";
  fs::create_directories(d);
  return (d / name).string();
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string write_bytes(const std::string& name, const std::string& bytes) {
  const std::string path = tmp_path(name);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

std::string compress(const std::string& raw) {
  return proxseg::detail::lzf_compress(reinterpret_cast<const unsigned char*>(raw.data()),
                                       raw.size());
}

std::string decompress(const std::string& lzf, std::size_t size) {
  std::string out(size, '\0');
  proxseg::detail::lzf_decompress(reinterpret_cast<const unsigned char*>(lzf.data()), lzf.size(),
                                  reinterpret_cast<unsigned char*>(out.data()), out.size());
  return out;
}

// Compresses raw, checks that it decompresses to raw and is within LZF's worst case (one control
// byte per 32 literals); returns the compressed size.
std::size_t round_trip(const std::string& raw) {
  const std::string lzf = compress(raw);
  EXPECT_LE(lzf.size(), raw.size() + raw.size() / 32 + 1);
  EXPECT_EQ(decompress(lzf, raw.size()), raw) << raw.size() << " bytes";
  return lzf.size();
}

std::string random_bytes(std::size_t n, unsigned seed, int alphabet = 256) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, alphabet - 1);
  std::string s(n, '\0');
  for (char& c : s) c = static_cast<char>(byte(rng));
  return s;
}

// The mOSD scene's per-object instance (label / 10 for objects, 1 for the table, 0 invalid).
std::vector<std::uint32_t> instances(const std::vector<std::uint32_t>& labels) {
  std::vector<std::uint32_t> out(labels.size());
  for (std::size_t i = 0; i < labels.size(); ++i)
    out[i] = labels[i] == 0 ? 0 : labels[i] < 20 ? 1 : labels[i] / 10;
  return out;
}

// The frame's fields one after another (x, y, z, packed rgb, label): what binary_compressed
// compresses.
std::string soa(const Frame& f) {
  std::string raw;
  for (int k = 0; k < 3; ++k)
    for (const auto& p : f.xyz) raw.append(reinterpret_cast<const char*>(&p[k]), 4);
  for (const auto& c : f.rgb) {
    const std::uint32_t v = (std::uint32_t{c[0]} << 16) | (std::uint32_t{c[1]} << 8) | c[2];
    raw.append(reinterpret_cast<const char*>(&v), 4);
  }
  raw.append(reinterpret_cast<const char*>(f.label.data()), 4 * f.label.size());
  return raw;
}

bool same_bits(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  return std::memcmp(a.data(), b.data(), 12) == 0;
}

// Runs fn, expects an InputError (or the FileError subclass if file_error) naming every part.
void expect_error(const std::function<void()>& fn, const std::vector<std::string>& parts,
                  bool file_error = false) {
  try {
    fn();
    ADD_FAILURE() << "expected InputError mentioning " << parts.front();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(file_error, dynamic_cast<const proxseg::FileError*>(&e) != nullptr) << msg;
    for (const auto& p : parts)
      EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
  }
}

// ---- LZF ---------------------------------------------------------------------------------------

TEST(Lzf, ShortInputs) {
  EXPECT_EQ(compress(""), "");
  for (const std::string s : {"a", "ab", "abc", "abcd", "aaaa", "aaaaa", "abcabcabc"})
    round_trip(s);
  // Inputs of every length up to 100 from a small alphabet: matches start and end at every
  // position, including the last bytes of the input.
  for (std::size_t n = 0; n <= 100; ++n) round_trip(random_bytes(n, static_cast<unsigned>(n), 3));
}

TEST(Lzf, RandomBytes) {
  const std::string raw = random_bytes(1 << 20, 1);
  const std::size_t size = round_trip(raw);
  // Incompressible: all literal runs of 32, one control byte each.
  EXPECT_GE(size, raw.size());
  EXPECT_EQ(round_trip(random_bytes(1 << 16, 2, 4)) < (1u << 16), true);
}

TEST(Lzf, ZeroRunsAndLongRepeats) {
  const std::string zeros(1 << 20, '\0');
  // Runs of 264 bytes (the longest back-reference) cost 3 bytes each.
  EXPECT_LT(round_trip(zeros), zeros.size() / 80);
  std::string pattern;
  for (int i = 0; i < 200000; ++i) pattern += "0123456";
  EXPECT_LT(round_trip(pattern), pattern.size() / 80);
  // Zero runs between random stretches, as NaN-free padding between data.
  std::string mixed;
  for (int i = 0; i < 50; ++i) mixed += random_bytes(1000, 100 + i) + std::string(3000 + i, '\0');
  round_trip(mixed);
}

TEST(Lzf, BackReferenceDistanceLimit) {
  // A repeat 8192 bytes back is the farthest a back-reference reaches; 8193 is too far.
  const std::string block = random_bytes(8192, 7);
  EXPECT_LT(round_trip(block + block), block.size() + block.size() / 32 + 200);
  const std::string block1 = random_bytes(8193, 8);
  EXPECT_GE(round_trip(block1 + block1), 2 * block1.size());
}

TEST(Lzf, RealSceneAndDeterminism) {
  const Frame f = proxseg::read_pcd(kScene);
  ASSERT_EQ(f.size(), 640u * 480u);
  const std::string raw = soa(f);
  const std::size_t size = round_trip(raw);
  EXPECT_LT(size, raw.size() / 2);
  std::cout << "[ info ] LZF of learn0's fields (x y z rgb label): " << raw.size() << " -> " << size
            << " bytes, ratio " << static_cast<double>(size) / raw.size() << "\n";
  // The same input gives the same bytes (the hash table starts empty every time).
  EXPECT_EQ(compress(raw), compress(raw));
  const std::string other = random_bytes(100000, 3, 5);
  EXPECT_EQ(compress(other), compress(other));
}

// ---- PCD binary_compressed ----------------------------------------------------------------------

TEST(PcdCompressed, RealSceneRoundTrip) {
  const Frame f = proxseg::read_pcd(kScene);
  ASSERT_FALSE(f.label.empty());
  const std::vector<std::uint32_t> inst = instances(f.label);
  const std::vector<proxseg::PointField> fields = {{"label", f.label}, {"instance", inst}};
  const std::string path = tmp_path("learn0_compressed.pcd");
  proxseg::write_pcd(path, f, fields);  // binary_compressed is the default
  const std::string bytes = slurp(path);
  EXPECT_NE(bytes.find("\nFIELDS x y z rgb label instance\n"), std::string::npos);
  EXPECT_NE(bytes.find("\nWIDTH 640\nHEIGHT 480\n"), std::string::npos);
  EXPECT_NE(bytes.find("\nDATA binary_compressed\n"), std::string::npos);
  EXPECT_EQ(bytes, proxseg::pcd_bytes(f, fields, PcdData::kBinaryCompressed));
  EXPECT_EQ(bytes, proxseg::pcd_bytes(f, fields));  // deterministic

  const Frame g = proxseg::read_pcd(path);
  EXPECT_EQ(g.width, 640);
  EXPECT_EQ(g.height, 480);
  ASSERT_EQ(g.size(), f.size());
  std::size_t nan = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    ASSERT_TRUE(same_bits(g.xyz[i], f.xyz[i])) << "point " << i;
    nan += std::isnan(f.xyz[i].z());
  }
  EXPECT_GT(nan, 0u);  // the NaN points came through bit for bit too
  EXPECT_EQ(g.rgb, f.rgb);
  EXPECT_EQ(g.label, f.label);
  EXPECT_EQ(proxseg::read_pcd(path, "instance").label, inst);

  const std::string binary = proxseg::pcd_bytes(f, fields, PcdData::kBinary);
  const double ratio = static_cast<double>(bytes.size()) / binary.size();
  std::cout << "[ info ] learn0 with label + instance: binary " << binary.size()
            << " bytes, binary_compressed " << bytes.size() << " bytes, ratio " << ratio << "\n";
  EXPECT_LT(ratio, 0.5);
  // The binary file reads back to the same frame.
  const Frame b = proxseg::read_pcd(write_bytes("learn0_binary.pcd", binary));
  EXPECT_EQ(b.label, g.label);
  EXPECT_EQ(b.rgb, g.rgb);
  for (std::size_t i = 0; i < f.size(); ++i) ASSERT_TRUE(same_bits(b.xyz[i], g.xyz[i]));
}

TEST(PcdCompressed, SmallFramesAndNoColour) {
  // Unorganized, with and without colours, with and without extra fields, 1 point or a few.
  for (int n : {1, 2, 5, 40}) {
    Frame f;
    f.width = n;
    f.height = 1;
    std::vector<std::uint32_t> labels;
    for (int i = 0; i < n; ++i) {
      f.xyz.emplace_back(0.1f * i, -0.2f * i, 1.0f + i);
      labels.push_back(static_cast<std::uint32_t>(i % 3 == 0 ? 4000000000u : i));
    }
    for (bool colour : {false, true}) {
      if (colour)
        for (int i = 0; i < n; ++i)
          f.rgb.push_back({static_cast<std::uint8_t>(i), 200, static_cast<std::uint8_t>(255 - i)});
      const std::string bytes = proxseg::pcd_bytes(f, {{"label", labels}});
      ASSERT_NE(bytes.find("DATA binary_compressed\n"), std::string::npos);
      const Frame g = proxseg::read_pcd(write_bytes("small.pcd", bytes));
      EXPECT_EQ(g.width, n);
      EXPECT_EQ(g.height, 1);
      EXPECT_EQ(g.xyz, f.xyz);
      EXPECT_EQ(g.rgb, f.rgb);
      EXPECT_EQ(g.label, labels);
      const Frame h =
          proxseg::read_pcd(write_bytes("small_nofields.pcd", proxseg::pcd_bytes(f, {})));
      EXPECT_EQ(h.xyz, f.xyz);
      EXPECT_TRUE(h.label.empty());
    }
  }
}

TEST(PcdCompressed, OpenThreeDReadsOurFile) {
  // Open3D's PCD reader decodes LZF with liblzf's decoder: it reading the same points shows that
  // the compressor writes the format others read, not only the one our reader reads. It keeps
  // x y z and rgb (the extra label fields are skipped) and NaN points (remove_nan_points false).
  const Frame f = proxseg::read_pcd(kScene);
  const std::string path = tmp_path("learn0_open3d.pcd");
  proxseg::write_pcd(path, f, {{"label", f.label}, {"instance", instances(f.label)}});
  open3d::geometry::PointCloud pc;
  ASSERT_TRUE(open3d::io::ReadPointCloud(path, pc, open3d::io::ReadPointCloudOption("pcd")));
  ASSERT_EQ(pc.points_.size(), f.size());
  ASSERT_EQ(pc.colors_.size(), f.size());
  std::size_t finite = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    const Eigen::Vector3f p = pc.points_[i].cast<float>();
    EXPECT_EQ(f.valid(i), p.allFinite()) << "point " << i;
    if (!f.valid(i)) continue;
    ++finite;
    ASSERT_TRUE(same_bits(p, f.xyz[i])) << "point " << i;
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(std::lround(pc.colors_[i][k] * 255.0), f.rgb[i][k]) << "point " << i;
  }
  EXPECT_GT(finite, 100000u);
}

// ---- 16-bit label PNGs -------------------------------------------------------------------------

TEST(LabelPng, OrganizedRoundTripIs16Bit) {
  Frame f;
  f.width = 640;
  f.height = 480;
  f.xyz.assign(640 * 480, Eigen::Vector3f(0, 0, 1));
  std::vector<std::uint32_t> labels(f.size());
  for (std::size_t i = 0; i < labels.size(); ++i)
    labels[i] = static_cast<std::uint32_t>((i / 640) / 40 * 1000 + (i % 640) / 64);
  labels[1] = 65535;
  labels[2] = 256;  // both bytes of a sample matter: a byte-order mistake shows
  const std::string png = proxseg::label_png(f, labels);
  // IHDR right after the signature: width, height, bit depth 16, colour type 0 (grey).
  ASSERT_GT(png.size(), 26u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(png.substr(12, 4), "IHDR");
  EXPECT_EQ(static_cast<unsigned char>(png[24]), 16);
  EXPECT_EQ(static_cast<unsigned char>(png[25]), 0);
  const std::string path = write_bytes("labels640.png", png);
  const proxseg::LabelImage back = proxseg::read_label_png(path);
  EXPECT_EQ(back.width, 640);
  EXPECT_EQ(back.height, 480);
  EXPECT_EQ(back.values, labels);
  EXPECT_LT(png.size(), labels.size() / 4);  // compact: mostly constant rows
  // OpenCV's decoder (its own libpng set-up) reads the same values: the samples are big-endian
  // in the file, not only symmetric between our writer and reader.
  const cv::Mat m = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(m.type(), CV_16UC1);
  ASSERT_EQ(m.cols, 640);
  ASSERT_EQ(m.rows, 480);
  for (std::size_t i = 0; i < labels.size(); ++i)
    ASSERT_EQ(m.at<std::uint16_t>(static_cast<int>(i / 640), static_cast<int>(i % 640)), labels[i])
        << "pixel " << i;
}

TEST(LabelPng, UnorganizedRoundTripOfSceneLabels) {
  const Frame scene = proxseg::read_pcd(kScene);
  Frame f;  // the scene's points as an unorganized cloud: one row
  f.width = static_cast<int>(scene.size());
  f.height = 1;
  f.xyz = scene.xyz;
  const std::vector<std::uint32_t> labels = instances(scene.label);
  const proxseg::LabelImage back =
      proxseg::read_label_png(write_bytes("labels_row.png", proxseg::label_png(f, labels)));
  EXPECT_EQ(back.width, f.width);
  EXPECT_EQ(back.height, 1);
  EXPECT_EQ(back.values, labels);
  // Wider than libpng's default limit of 1,000,000 columns: a large unorganized cloud.
  f.width = 1500000;
  f.xyz.assign(f.width, Eigen::Vector3f(0, 0, 1));
  std::vector<std::uint32_t> many(f.xyz.size());
  for (std::size_t i = 0; i < many.size(); ++i) many[i] = static_cast<std::uint32_t>(i % 65536);
  const proxseg::LabelImage wide =
      proxseg::read_label_png(write_bytes("labels_wide.png", proxseg::label_png(f, many)));
  EXPECT_EQ(wide.width, f.width);
  EXPECT_EQ(wide.values, many);
}

TEST(LabelPng, Errors) {
  Frame f;
  f.width = 3;
  f.height = 1;
  f.xyz.assign(3, Eigen::Vector3f(0, 0, 1));
  expect_error(
      [&] {
        proxseg::label_png(f, {1, 70000, 65536});
      },
      {"label 70000 does not fit a 16-bit PNG"});
  EXPECT_NO_THROW(proxseg::label_png(f, {1, 65535, 0}));
  EXPECT_THROW(proxseg::label_png(f, {1, 2}), std::invalid_argument);

  // 8-bit grey PNGs (YCB-Video labels) read; colour images, JPEGs, junk and missing files do
  // not, each named.
  const proxseg::LabelImage ycb = proxseg::read_label_png(kData + "/ycbv/frames/000001-label.png");
  EXPECT_EQ(ycb.width, 640);
  EXPECT_EQ(ycb.height, 480);
  EXPECT_EQ(ycb.values.size(), 640u * 480u);
  const std::string colour = kData + "/ycbv/frames/000001-color.png";
  expect_error([&] { proxseg::read_label_png(colour); }, {colour, "8-bit 3-channel"});
  std::vector<unsigned char> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", cv::Mat(8, 8, CV_8UC1, cv::Scalar(3)), jpeg));
  const std::string jpg = write_bytes("labels.jpg", std::string(jpeg.begin(), jpeg.end()));
  expect_error([&] { proxseg::read_label_png(jpg); }, {jpg, "not a PNG"});
  const std::string junk = write_bytes("junk.png", "not a png at all");
  expect_error([&] { proxseg::read_label_png(junk); }, {junk});
  const std::string cut = write_bytes("cut.png", proxseg::label_png(f, {1, 2, 3}).substr(0, 40));
  expect_error([&] { proxseg::read_label_png(cut); }, {cut});
  const std::string missing = tmp_path("no_such_labels.png");
  fs::remove(missing);
  expect_error([&] { proxseg::read_label_png(missing); }, {missing}, true);
}

}  // namespace
