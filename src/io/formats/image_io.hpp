// PNG and JPEG reading and PNG writing with libpng and libjpeg directly. Private to the library.
// OpenCV's imgcodecs would do the same but loads ~140 shared libraries (GDAL, GDCM, HEIF, ...)
// at every process start; Open3D's image IO cannot encode to memory, and its JPEG reader exits
// the process on a corrupt file.
#pragma once
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <string>

namespace proxseg::detail {

// Decodes the PNG or JPEG file at path (recognised by its content, not its name) into the Mat
// that cv::imread(path, cv::IMREAD_UNCHANGED) gives:
// - PNG: grey -> CV_8UC1 / CV_16UC1 (1, 2 and 4-bit grey expanded to 0..255), colour or palette
//   -> BGR, with an alpha channel or a tRNS chunk -> BGRA, grey + alpha -> BGRA; 16-bit samples
//   stay 16-bit and exact (no gamma or alpha conversion), interlaced images are supported;
// - JPEG: grey -> CV_8UC1, colour -> CV_8UC3 BGR (CMYK converted as OpenCV does), the EXIF
//   orientation ignored.
// Throws std::runtime_error with a one-line reason (no path) when the file cannot be opened, is
// neither a PNG nor a JPEG, has more than max_pixels pixels (checked from the header before
// anything is allocated) or is corrupt or truncated. Prints nothing.
cv::Mat read_image_file(const std::string& path, std::uint64_t max_pixels);

// PNG bytes of an 8-bit BGR image (CV_8UC3), RGB in the file. The compression is OpenCV's
// imencode default (zlib level 1, sub filter, run-length strategy): fast, and the same bytes.
// Throws std::runtime_error if libpng fails (out of memory).
std::string encode_png(const cv::Mat& bgr);

// PNG bytes of a 16-bit one-channel image (CV_16UC1): 16-bit grey, samples big-endian as PNG
// stores them, read back exactly by read_image_file. The same zlib settings as encode_png.
// Throws std::runtime_error if libpng fails (out of memory).
std::string encode_png16(const cv::Mat& grey16);

}  // namespace proxseg::detail
