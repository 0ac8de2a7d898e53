// Image decoding (libpng and libjpeg, src/io/formats/image_io.cpp) against OpenCV's
// cv::imread(IMREAD_UNCHANGED), broken images, and the pictures proxseg writes.
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
#include <proxseg/io/output.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "support/io_files.hpp"

using namespace io_test;
using proxseg::Frame;
using proxseg::InputError;

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
