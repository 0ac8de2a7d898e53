// Images as the frame readers take them (colour, depth and label images): a regular file of at
// most 8192 x 8192 pixels decoded by image_io.hpp, errors naming the file, and the words that
// describe an image in those errors. Private to the library.
#pragma once
#include <opencv2/core/mat.hpp>
#include <string>

namespace proxseg::detail {

// PNG or JPEG as cv::imread(IMREAD_UNCHANGED) gives it. FileError when path is not a readable
// regular file, InputError naming it when it is no image, a corrupt one or one too large.
cv::Mat read_image(const std::string& path);

// "16-bit 1-channel", "8-bit 3-channel", ...
std::string mat_kind(const cv::Mat& m);
// "640x480"
std::string size_str(const cv::Mat& m);

}  // namespace proxseg::detail
