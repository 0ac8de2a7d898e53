// A window of an organized frame (rows r0.., columns c0..) with its labels: a small real frame
// for the tests (test_faults) and the fuzzers' seeds (fuzz/make_seeds.cpp).
#pragma once
#include <proxseg/core/frame.hpp>

#include <cstddef>

namespace proxseg::test {

inline Frame frame_window(const Frame& f, int r0, int c0, int rows, int cols) {
  Frame out;
  out.width = cols;
  out.height = rows;
  for (int r = r0; r < r0 + rows; ++r)
    for (int c = c0; c < c0 + cols; ++c) {
      const std::size_t i = static_cast<std::size_t>(r) * f.width + c;
      out.xyz.push_back(f.xyz[i]);
      out.rgb.push_back(f.rgb[i]);
      if (!f.label.empty()) out.label.push_back(f.label[i]);
    }
  return out;
}

}  // namespace proxseg::test
