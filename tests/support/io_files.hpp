// Hand-made input files for the tests of the readers (tests/io/): scratch paths, raw bytes, PCD
// headers and LZF blocks, and the check of a one-line InputError.
#pragma once
#include <gtest/gtest.h>

#include <charconv>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <proxseg/core/errors.hpp>
#include <proxseg/core/rgbd.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace io_test {

namespace fs = std::filesystem;
inline const std::string kData = PROXSEG_DATA_DIR;
inline const float kNan = std::numeric_limits<float>::quiet_NaN();

// PROXSEG_TEST_TMP/io, made if missing.
inline std::string tmp_dir() {
  const fs::path d = fs::path(PROXSEG_TEST_TMP) / "io";
  fs::create_directories(d);
  return d.string();
}

inline std::string tmp_path(const std::string& name) {
  return (fs::path(tmp_dir()) / name).string();
}

inline std::string write_bytes(const std::string& name, const std::string& bytes) {
  const std::string path = tmp_path(name);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

template <typename T>
void append(std::string& s, T v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

inline float packed_rgb_float(std::uint32_t r, std::uint32_t g, std::uint32_t b) {
  const std::uint32_t v = (r << 16) | (g << 8) | b;
  float f;
  std::memcpy(&f, &v, 4);
  return f;
}

// Shortest text that parses back to exactly the same float.
inline std::string float_text(float f) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof(buf), f);
  return std::string(buf, r.ptr);
}

// A valid LZF stream made only of literal runs (ctrl = run length - 1, at most 32 bytes).
inline std::string lzf_literals(const std::string& raw) {
  std::string out;
  for (std::size_t i = 0; i < raw.size(); i += 32) {
    const std::size_t run = std::min<std::size_t>(32, raw.size() - i);
    out += static_cast<char>(run - 1);
    out += raw.substr(i, run);
  }
  return out;
}

inline std::string compressed_block(const std::string& lzf, std::uint32_t uncompressed_size) {
  std::string s;
  append<std::uint32_t>(s, static_cast<std::uint32_t>(lzf.size()));
  append<std::uint32_t>(s, uncompressed_size);
  return s + lzf;
}

// Runs fn, expects InputError whose one-line message contains every part.
inline void expect_input_error(const std::function<void()>& fn,
                               const std::vector<std::string>& parts) {
  try {
    fn();
    ADD_FAILURE() << "expected InputError mentioning " << parts.front();
  } catch (const proxseg::InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    for (const auto& p : parts)
      EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
  }
}

// Writes TEXT to the scratch file NAME and expects read_pcd to refuse it with an InputError
// naming NAME and every part.
inline void expect_pcd_error(const std::string& name, const std::string& text,
                             std::vector<std::string> parts) {
  const std::string path = write_bytes(name, text);
  parts.insert(parts.begin(), name);
  expect_input_error([&] { proxseg::read_pcd(path); }, parts);
}

inline std::string header(const std::string& fields, const std::string& size,
                          const std::string& type, const std::string& count, int width, int height,
                          long points, const std::string& data) {
  std::ostringstream h;
  h << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS " << fields << "\nSIZE "
    << size << "\nTYPE " << type << "\nCOUNT " << count << "\nWIDTH " << width << "\nHEIGHT "
    << height << "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << points << "\nDATA " << data << "\n";
  return h.str();
}

// Binary x y z rgb (float) cloud of n points, point i = (i, 2i, 3i + 1), colour (i, 10, 20).
inline std::string binary_xyzrgb(int n, int points_in_header) {
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

// Field-by-field layout: all x, all y, all z, all rgb, all labels (U1).
inline std::string compressed_raw_3pts() {
  std::string raw;
  for (float x : {1.f, 2.f, 3.f}) append<float>(raw, x);
  for (float y : {10.f, kNan, 30.f}) append<float>(raw, y);
  for (float z : {0.5f, 0.6f, 0.7f}) append<float>(raw, z);
  for (std::uint32_t c : {0x010203u, 0x040506u, 0x070809u}) append<std::uint32_t>(raw, c);
  return raw;
}

// A small camera for hand-made RGB-D pairs: depths in millimetres.
inline proxseg::Intrinsics small_k() {
  proxseg::Intrinsics k;
  k.fx = 100;
  k.fy = 200;
  k.cx = 1;
  k.cy = 0.5;
  k.depth_scale = 1000;
  return k;
}

}  // namespace io_test
