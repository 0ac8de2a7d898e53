// Label images: per pixel an object or segment label, as YCB-Video's 8-bit -label.png files hold
// them (read_label_image, one label per pixel of the frame) and as label_png (output.hpp) writes
// them, 8- or 16-bit grey PNG (read_label_png).
#include <proxseg/io/cloud_io.hpp>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <opencv2/core.hpp>

#include "io/formats/image_file.hpp"
#include "io/reader_errors.hpp"

namespace proxseg {
namespace {

using detail::fail;
using detail::mat_kind;
using detail::read_image;
using detail::size_str;

}  // namespace

std::vector<std::uint8_t> read_label_image(const std::string& path, int width, int height) {
  const cv::Mat m = read_image(path);
  if (m.type() != CV_8UC1 || m.cols != width || m.rows != height)
    fail(path, "label image is " + mat_kind(m) + " " + size_str(m) +
                   " (expected 8-bit one-channel " + std::to_string(width) + "x" +
                   std::to_string(height) + ", the size of the frame)");
  std::vector<std::uint8_t> labels(static_cast<std::size_t>(width) * height);
  for (int r = 0; r < height; ++r)
    std::memcpy(labels.data() + static_cast<std::size_t>(r) * width, m.ptr<std::uint8_t>(r), width);
  return labels;
}

LabelImage read_label_png(const std::string& path) {
  const cv::Mat m = read_image(path);
  if (m.type() != CV_8UC1 && m.type() != CV_16UC1)
    fail(path, "label image is " + mat_kind(m) + " " + size_str(m) +
                   " (expected an 8- or 16-bit one-channel PNG)");
  // read_image takes JPEGs too: their lossy grey values are no labels.
  std::ifstream in(path, std::ios::binary);
  char signature[8] = {};
  in.read(signature, sizeof signature);
  if (!in || std::memcmp(signature, "\x89PNG\r\n\x1a\n", 8) != 0)
    fail(path, "label image is not a PNG (expected an 8- or 16-bit one-channel PNG)");
  LabelImage out;
  out.width = m.cols;
  out.height = m.rows;
  out.values.resize(static_cast<std::size_t>(m.cols) * m.rows);
  std::uint32_t* to = out.values.data();
  for (int r = 0; r < m.rows; ++r, to += m.cols) {
    if (m.depth() == CV_8U)
      std::copy_n(m.ptr<std::uint8_t>(r), m.cols, to);
    else
      std::copy_n(m.ptr<std::uint16_t>(r), m.cols, to);
  }
  return out;
}

}  // namespace proxseg
