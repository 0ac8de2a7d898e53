// The Gabor filter bank of the texture feature [paper 3.1], shared by the texture block of
// voxel_features() (features.cpp) and the reference bank (gabor_reference.hpp): the filters, the
// response grid and the binning of magnitudes.
#pragma once
#include <proxseg/core/features.hpp>
#include <proxseg/core/frame.hpp>

#include "feature_bins.hpp"

#include <array>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <vector>

namespace proxseg::detail {

// Bin of a magnitude m under the upper edge of its filter: the reference definition.
inline int texture_bin(float m, float upper) {
  return upper > 0 ? bin_of(m / upper, kHistogramBins) : 0;
}

// The bin edges of one filter as magnitudes, so that binning a pixel takes comparisons instead of
// a division: texture_bin(m) >= k exactly when m >= edge[k - 1], for m < exact_above (beyond
// that, where the quotient could leave the int range, the division is done). texture_bin is
// monotone in m there (the float quotient is monotone), so each edge is the first float for
// which it reaches k: found by bisection over the float bit patterns, which are in the order of
// the values for non-negative floats.
struct TextureEdges {
  std::array<float, kHistogramBins - 1> edge;
  float upper, exact_above;
  explicit TextureEdges(float upper_edge) : upper(upper_edge) {
    const float inf = std::numeric_limits<float>::infinity();
    exact_above = upper > 0 ? static_cast<float>(static_cast<double>(upper) * 1e8) : inf;
    std::uint32_t end;  // bit pattern of exact_above: the search range is [0, end)
    std::memcpy(&end, &exact_above, sizeof end);
    for (int k = 1; k < kHistogramBins; ++k) {
      std::uint32_t lo = 0, hi = end;  // first pattern in [lo, hi) reaching bin k, or hi
      while (lo < hi) {
        const std::uint32_t mid = lo + (hi - lo) / 2;
        float m;
        std::memcpy(&m, &mid, sizeof m);
        if (texture_bin(m, upper) >= k)
          hi = mid;
        else
          lo = mid + 1;
      }
      std::memcpy(&edge[k - 1], &lo, sizeof lo);
    }
  }
  int bin(float m) const {
    if (!(m < exact_above)) return texture_bin(m, upper);
    int b = 0;
    for (const float e : edge) b += m >= e;
    return b;
  }
  // count[10 * row[t] + b] += weight[t] (1 without weights) for each pixel pixels[t] in bin b.
  // The pixels are taken four at a time: one 4-lane vector comparison per edge counts the edges
  // each one reaches, which is its bin (GCC and Clang vector extensions; a true lane is -1).
  void histograms(const float* magnitude, const std::vector<int>& pixels,
                  const std::vector<int>& row, const std::vector<int>* weight, int* count) const {
    auto w = [weight](std::size_t t) { return weight ? (*weight)[t] : 1; };
    using Floats = float __attribute__((vector_size(16)));
    using Ints = int __attribute__((vector_size(16)));
    const Floats below = {exact_above, exact_above, exact_above, exact_above};
    const std::size_t n = pixels.size();
    std::size_t t = 0;
    for (; t + 4 <= n; t += 4) {
      const Floats m = {magnitude[pixels[t]], magnitude[pixels[t + 1]], magnitude[pixels[t + 2]],
                        magnitude[pixels[t + 3]]};
      int inside[4];
      const Ints compared = m < below;
      std::memcpy(inside, &compared, sizeof inside);
      if (!(inside[0] & inside[1] & inside[2] & inside[3])) {  // one needs the division
        for (int lane = 0; lane < 4; ++lane)
          count[kHistogramBins * row[t + lane] + bin(m[lane])] += w(t + lane);
        continue;
      }
      Ints reached = {};
      for (const float e : edge) reached -= m >= Floats{e, e, e, e};
      int b[4];
      std::memcpy(b, &reached, sizeof b);
      for (int lane = 0; lane < 4; ++lane)
        count[kHistogramBins * row[t + lane] + b[lane]] += w(t + lane);
    }
    for (; t < n; ++t) count[kHistogramBins * row[t] + bin(magnitude[pixels[t]])] += w(t);
  }
};

// The grid the Gabor responses are given on: the frame's pixels at stride 1; at stride 2 the
// half-resolution grid of 2 x 2 cells, cell (i, j) centred at pixel (2i + 1/2, 2j + 1/2), and a
// pixel takes the response of its cell.
struct ResponseGrid {
  int width, height, stride;
  ResponseGrid(const Frame& frame, int s)
      : width((frame.width + s - 1) / s), height((frame.height + s - 1) / s), stride(s) {}
  int cell(int u, int v) const { return v / stride * width + u / stride; }
};

// Runs the 24 Gabor filters of an organized frame on `threads` threads and sets their upper bin
// edges; for each filter, the thread that computed it calls consume(filter, magnitude) with the
// magnitude image on the ResponseGrid of params.gabor_stride (valid during the call only). Every
// filter is computed the same way whatever the thread, so the outputs do not depend on the
// number of threads as long as `consume` writes only outputs of its filter. `prepare` runs as one
// more task beside the spectra, before any filter (what `consume` needs); `side` is one more
// independent task, run among the filters (OpenMP loops inside them run on that task's thread
// unless nested parallelism is enabled).
void gabor_filters(const Frame& frame, const FeatureParams& params, int threads,
                   std::vector<float>& upper_edge,
                   const std::function<void(int filter, const float* magnitude)>& consume,
                   const std::function<void()>& prepare, const std::function<void()>& side);

}  // namespace proxseg::detail
