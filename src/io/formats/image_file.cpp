// Images as the frame readers take them (image_file.hpp).
#include "io/formats/image_file.hpp"

#include <cstdint>
#include <stdexcept>

#include "io/formats/image_io.hpp"
#include "io/input_file.hpp"
#include "io/reader_errors.hpp"

namespace proxseg::detail {
namespace {

// Larger images are refused from their header, before anything is decoded or allocated (a
// 16-bit 8192 x 8192 depth image is 128 MiB).
constexpr std::uint64_t kMaxImagePixels = std::uint64_t{8192} * 8192;

}  // namespace

cv::Mat read_image(const std::string& path) {
  require_regular_file(path);
  try {
    return read_image_file(path, kMaxImagePixels);
  } catch (const std::runtime_error& e) {
    fail(path, one_line(e.what()));
  }
}

std::string mat_kind(const cv::Mat& m) {
  std::string d;
  switch (m.depth()) {
    case CV_8U:
      d = "8-bit";
      break;
    case CV_8S:
      d = "8-bit signed";
      break;
    case CV_16U:
      d = "16-bit";
      break;
    case CV_16S:
      d = "16-bit signed";
      break;
    case CV_32S:
      d = "32-bit integer";
      break;
    case CV_32F:
      d = "32-bit float";
      break;
    default:
      d = "64-bit float";
      break;
  }
  return d + " " + std::to_string(m.channels()) + "-channel";
}

std::string size_str(const cv::Mat& m) {
  return std::to_string(m.cols) + "x" + std::to_string(m.rows);
}

}  // namespace proxseg::detail
