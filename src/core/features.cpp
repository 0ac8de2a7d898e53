// Per-voxel features [paper 3.1]: colour (HSV histograms), texture (Gabor bank), shape
// (normalised eigenvalues, curvature, normal-angle histogram).
#include <proxseg/core/colour.hpp>
#include <proxseg/core/features.hpp>

#include "gabor_reference.hpp"
#include "util/moments.hpp"
#include "util/nearest_points.hpp"
#include "util/parallel_for.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdint>
#include <cstring>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include "util/angles.hpp"

namespace proxseg {
namespace {

using detail::kPi;

int bin_of(double t, int bins) {  // t in [0, 1] -> 0..bins-1
  return std::clamp(static_cast<int>(t * bins), 0, bins - 1);
}

void normalise(Eigen::Ref<Eigen::VectorXf> block) {
  const float sum = block.sum();
  if (sum > 0) block /= sum;
}

// Bin (inclination * 10 + azimuth) of a finite unit normal in the 10x10 angle histogram: the
// reference definition, with acos and atan2.
int normal_bin_exact(const Eigen::Vector3f& n) {
  const double theta = std::acos(std::clamp(static_cast<double>(n.z()), -1.0, 1.0));
  const double phi = std::atan2(static_cast<double>(n.y()), static_cast<double>(n.x()));
  return bin_of(theta / kPi, kHistogramBins) * kHistogramBins +
         bin_of((phi + kPi) / (2 * kPi), kHistogramBins);
}

// The same bin without acos and atan2: the bin edges are fixed angles, so the bin follows from
// comparing z with the cosines of the inclination edges and (x, y) with the azimuth edge
// directions. The reference's rounding moves an angle by less than 1e-14 rad; whenever the normal
// lies within 1e-9 (rad, or in z) of an edge the reference definition decides instead, so the bin
// is always the reference's.
int normal_bin(const Eigen::Vector3f& n) {
  constexpr int kBins = kHistogramBins;
  constexpr double kMargin = 1e-9;
  struct Edges {
    double cos_theta[kBins + 1];                    // cos(k pi / 10): inclination edges as z
    double cos_phi[kBins + 1], sin_phi[kBins + 1];  // azimuth edges -pi + k pi / 5
    Edges() {
      for (int k = 0; k <= kBins; ++k) {
        cos_theta[k] = std::cos(k * kPi / kBins);
        cos_phi[k] = std::cos(-kPi + k * 2 * kPi / kBins);
        sin_phi[k] = std::sin(-kPi + k * 2 * kPi / kBins);
      }
    }
  };
  static const Edges edges;
  const double x = n.x(), y = n.y(), z = std::clamp(static_cast<double>(n.z()), -1.0, 1.0);
  int theta_bin = 0;  // theta >= k pi / 10 exactly when z <= cos(k pi / 10)
  for (int k = 1; k < kBins; ++k) {
    if (std::abs(z - edges.cos_theta[k]) <= kMargin) return normal_bin_exact(n);
    theta_bin += z < edges.cos_theta[k];
  }
  // Azimuth: y < 0 is bins 0..4, y >= 0 bins 5..9 (y = 0 is the edge at 0 and at +-pi); within a
  // half, phi >= edge k exactly when sin(phi - edge) = y cos(edge) - x sin(edge) >= 0.
  const double r2 = x * x + y * y;
  if (!(r2 > 1e-12) || y * y <= kMargin * kMargin * r2) return normal_bin_exact(n);
  const int first = y < 0 ? 1 : kBins / 2 + 1;
  int phi_bin = first - 1;
  for (int k = first; k < first + kBins / 2 - 1; ++k) {
    const double side = y * edges.cos_phi[k] - x * edges.sin_phi[k];
    if (side * side <= kMargin * kMargin * r2) return normal_bin_exact(n);
    phi_bin += side > 0;
  }
  return theta_bin * kBins + phi_bin;
}

// exp(-(du2 + dv2) / denom) rounded to float, bit for bit as the direct expression gives it, with
// the exponential of a sum computed as a product of two exponentials (one per column, one per
// row) instead of one call per pixel. For an argument below 1000 in magnitude the two differ by
// less than 5e-13 relative (a few ulps of the arguments and of exp); the product is used only when
// it lies further than 1e-12 relative from a midpoint between two floats, so that both round to
// the same float. Otherwise (a few pixels in a million) the direct expression is evaluated.
float gaussian_factor(double eu, double ev, double du2, double dv2, double denom) {
  constexpr double kTolerance = 1e-12;
  const double y = eu * ev;
  const float f = static_cast<float>(y);
  if (f > 0 && y < 1.0 && (du2 + dv2) < 1000 * denom) {  // |argument| < 1000: error < 1e-12
    std::uint32_t bits;
    std::memcpy(&bits, &f, sizeof f);
    const std::uint32_t below = bits - 1, above = bits + 1;
    float lo, hi;
    std::memcpy(&lo, &below, sizeof lo);
    std::memcpy(&hi, &above, sizeof hi);
    const double mid_lo = 0.5 * (static_cast<double>(f) + lo);  // exact in double
    const double mid_hi = 0.5 * (static_cast<double>(f) + hi);
    if (y - mid_lo > kTolerance * y && mid_hi - y > kTolerance * y) return f;
  }
  return static_cast<float>(std::exp(-(du2 + dv2) / denom));
}

// Spectrum of one pyramid level, padded to a fast DFT size (the level sizes of a 640 x 480 frame
// already are). With stride 2 the size is even and its half is a fast size too.
cv::Mat level_spectrum(const cv::Mat& grey, int stride) {
  auto padded_size = [stride](int n) {
    return stride == 1 ? cv::getOptimalDFTSize(n) : 2 * cv::getOptimalDFTSize((n + 1) / 2);
  };
  const int rows = padded_size(grey.rows), cols = padded_size(grey.cols);
  cv::Mat padded;
  cv::copyMakeBorder(grey, padded, 0, rows - grey.rows, 0, cols - grey.cols, cv::BORDER_REFLECT);
  cv::Mat spectrum;
  cv::dft(padded, spectrum, cv::DFT_COMPLEX_OUTPUT);
  return spectrum;
}

// Gabor magnitude of one level for orientation o, via the DFT: the spectrum is multiplied by a
// one-sided Gaussian centred on the filter's frequency, which is the Fourier transform of a
// complex Gabor kernel, so the inverse transform is the complex response. `work` holds buffers
// reused between calls of one thread.
//
// With stride 2 the response is wanted at every second position of the level only: sampling it
// so folds its spectrum onto the half-size frequency grid (bin k and bin k + n/2 land together),
// so the inverse DFT of the folded product, a quarter of the size, gives exactly those samples (up
// to rounding) at a quarter of the cost. The samples are taken half a pixel off the pixel grid,
// at (2i + 1/2, 2j + 1/2) (a phase ramp on the spectrum: the response is band-limited), where
// cv::resize expects the centres of a half-size image to lie.
struct GaborWork {
  cv::Mat filtered, planes[2];
  std::vector<double> du2, dv2, eu, ev;
  std::vector<float> column_re, column_im;
};
void gabor_magnitude(const cv::Mat& spectrum, cv::Size size, int o, int stride,
                     const FeatureParams& params, GaborWork& work, cv::Mat& magnitude) {
  const int rows = spectrum.rows, cols = spectrum.cols;
  const double f0 = 1.0 / params.gabor_wavelength;           // cycles per pixel
  const double sf = 1.0 / (2.0 * kPi * params.gabor_sigma);  // frequency-domain std
  const double denom = 2 * sf * sf;
  const double theta = o * kPi / kGaborOrientations;
  const double fu = f0 * std::cos(theta), fv = f0 * std::sin(theta);
  // One axis of the separable envelope: squared distance to the centre frequency and its factor.
  auto axis = [denom](int n, double centre, std::vector<double>& d2, std::vector<double>& e) {
    d2.resize(n);
    e.resize(n);
    for (int i = 0; i < n; ++i) {
      const double f = (i <= n / 2 ? i : i - n) / static_cast<double>(n);
      d2[i] = (f - centre) * (f - centre);
      e[i] = std::exp(-d2[i] / denom);
    }
  };
  axis(cols, fu, work.du2, work.eu);
  axis(rows, fv, work.dv2, work.ev);
  if (stride == 1) {
    work.filtered.create(spectrum.size(), spectrum.type());
    for (int r = 0; r < rows; ++r) {
      const auto* in = spectrum.ptr<cv::Vec2f>(r);
      auto* dst = work.filtered.ptr<cv::Vec2f>(r);
      for (int c = 0; c < cols; ++c)
        dst[c] = in[c] * gaussian_factor(work.eu[c], work.ev[r], work.du2[c], work.dv2[r], denom);
    }
  } else {
    // The folded product; the factor 1/4 keeps the scale of the full-size inverse DFT. The
    // envelope times the half-pixel shift exp(i pi f) (f in cycles per sample) is separable: the
    // two halves of a spectrum row meet under their column factors, then under the row factor.
    const int half_rows = rows / 2, half_cols = cols / 2;
    auto shifted = [](double envelope, int i, int n) {
      return std::polar(envelope, kPi * (i <= n / 2 ? i : i - n) / n);
    };
    work.column_re.resize(cols);
    work.column_im.resize(cols);
    for (int c = 0; c < cols; ++c) {
      const std::complex<double> z = shifted(work.eu[c], c, cols);
      work.column_re[c] = static_cast<float>(z.real());
      work.column_im[c] = static_cast<float>(z.imag());
    }
    const float* kr = work.column_re.data();
    const float* ki = work.column_im.data();
    work.filtered = cv::Mat::zeros(half_rows, half_cols, spectrum.type());
    for (int r = 0; r < rows; ++r) {
      const float* in = spectrum.ptr<float>(r);  // re, im interleaved
      float* dst = work.filtered.ptr<float>(r < half_rows ? r : r - half_rows);
      const std::complex<double> z = shifted(0.25 * work.ev[r], r, rows);
      const float fr = static_cast<float>(z.real()), fi = static_cast<float>(z.imag());
      for (int c = 0; c < half_cols; ++c) {
        const int c2 = c + half_cols;  // std::complex's operator* would check for NaN: written out
        const float a = in[2 * c] * kr[c] - in[2 * c + 1] * ki[c] + in[2 * c2] * kr[c2] -
                        in[2 * c2 + 1] * ki[c2];
        const float b = in[2 * c] * ki[c] + in[2 * c + 1] * kr[c] + in[2 * c2] * ki[c2] +
                        in[2 * c2 + 1] * kr[c2];
        dst[2 * c] += a * fr - b * fi;
        dst[2 * c + 1] += a * fi + b * fr;
      }
    }
    size = cv::Size((size.width + 1) / 2, (size.height + 1) / 2);
  }
  cv::idft(work.filtered, work.filtered, cv::DFT_COMPLEX_OUTPUT | cv::DFT_SCALE);  // in place
  cv::split(work.filtered(cv::Rect(0, 0, size.width, size.height)), work.planes);
  cv::magnitude(work.planes[0], work.planes[1], magnitude);
}

// The colour block of `count` pixels, colour(j) the j-th one's colour.
template <class Colour>
Eigen::VectorXf colour_block(std::size_t count, Colour&& colour) {
  Eigen::VectorXf f = Eigen::VectorXf::Zero(kColourDims);
  for (std::size_t j = 0; j < count; ++j) {
    const Eigen::Vector3d hsv = rgb_to_hsv(colour(j));
    f(bin_of(hsv[0], kHistogramBins) * kHistogramBins + bin_of(hsv[1], kHistogramBins)) += 1;
    f(100 + bin_of(hsv[2], kHistogramBins)) += 1;
  }
  normalise(f.head(100));
  normalise(f.tail(10));
  return f;
}

// The shape block of `count` points, point(j) the j-th one, and of the `normal_count` normals
// normal(j) (one per point, NaN where unknown).
template <class Point, class Normal>
Eigen::VectorXf shape_block(std::size_t count, Point&& point, std::size_t normal_count,
                            Normal&& normal) {
  Eigen::VectorXf f = Eigen::VectorXf::Zero(kShapeDims);
  if (count >= 3) {
    const Eigen::Matrix3d cov = detail::moments(count, point).scatter / static_cast<double>(count);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov, Eigen::EigenvaluesOnly);
    const Eigen::Vector3d l = eig.eigenvalues().cwiseMax(0.0);  // ascending
    const double sum = l.sum();
    if (sum > 0) {
      f(0) = static_cast<float>(l[2] / sum);  // l1 >= l2 >= l3
      f(1) = static_cast<float>(l[1] / sum);
      f(2) = static_cast<float>(l[0] / sum);
      f(3) = static_cast<float>(l[0] / sum);  // curvature index l3 / (l1 + l2 + l3)
    }
  }
  // 10x10 histogram of the normals' polar angles: inclination from the optical axis in [0, pi]
  // and azimuth in [-pi, pi).
  for (std::size_t j = 0; j < normal_count; ++j) {
    const Eigen::Vector3f& n = normal(j);
    if (n.allFinite()) f(4 + normal_bin(n)) += 1;
  }
  normalise(f.tail(100));
  return f;
}

}  // namespace

Eigen::VectorXf colour_feature(const std::vector<Rgb>& colours) {
  return colour_block(colours.size(), [&](std::size_t j) -> const Rgb& { return colours[j]; });
}

Eigen::VectorXf shape_feature(const std::vector<Eigen::Vector3f>& points,
                              const std::vector<Eigen::Vector3f>& normals) {
  return shape_block(
      points.size(), [&](std::size_t j) -> const Eigen::Vector3f& { return points[j]; },
      normals.size(), [&](std::size_t j) -> const Eigen::Vector3f& { return normals[j]; });
}

namespace {

// Bin of a magnitude m under the upper edge of its filter: the reference definition.
int texture_bin(float m, float upper) {
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

// The value std::nth_element would put at position q of `values` (which it may reorder). Magnitudes
// are non-negative floats, whose bit patterns sort as their values: the top 12 bits of the
// patterns narrow the search to one bucket of candidates, and nth_element runs on those only.
// Anything else (NaN, negative or -0) goes to nth_element on all values.
float order_statistic(std::vector<float>& values, std::size_t q, std::vector<float>& candidates) {
  constexpr int kShift = 20;  // 32 - 12 bits
  std::uint32_t count[(0x7f800000u >> kShift) + 1] = {};
  for (const float v : values) {
    std::uint32_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    if (bits > 0x7f800000u) {  // NaN or sign bit set
      std::nth_element(values.begin(), values.begin() + q, values.end());
      return values[q];
    }
    ++count[bits >> kShift];
  }
  std::uint32_t bucket = 0;
  std::size_t below = 0;
  while (below + count[bucket] <= q) below += count[bucket++];
  candidates.clear();
  for (const float v : values) {
    std::uint32_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    if (bits >> kShift == bucket) candidates.push_back(v);
  }
  std::nth_element(candidates.begin(), candidates.begin() + (q - below), candidates.end());
  return candidates[q - below];
}

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
template <class Consume, class Prepare, class Side>
void gabor_filters(const Frame& frame, const FeatureParams& params, int threads,
                   std::vector<float>& upper_edge, Consume&& consume, Prepare&& prepare,
                   Side&& side) {
  const int nthreads = detail::thread_count(threads);
  cv::Mat grey(frame.height, frame.width, CV_32F);
  detail::parallel_for(frame.height, nthreads, [&](int v) {
    float* row = grey.ptr<float>(v);
    for (int u = 0; u < frame.width; ++u) {
      const Rgb& c = frame.rgb[static_cast<std::size_t>(v) * frame.width + u];
      row[u] = static_cast<float>((0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2]) / 255.0);
    }
  });
  // Scale s filters the s-th level of a Gaussian pyramid with the same kernel: the wavelength in
  // the full image doubles with each scale at a quarter of the cost.
  std::vector<cv::Mat> levels(kGaborScales);
  levels[0] = grey;
  for (int s = 1; s < kGaborScales; ++s) cv::pyrDown(levels[s - 1], levels[s]);
  const int filters = kGaborScales * kGaborOrientations;
  upper_edge.assign(filters, 0.f);
  const std::size_t n = static_cast<std::size_t>(frame.width) * frame.height;
  std::vector<cv::Mat> spectra(kGaborScales);
  const int stride = params.gabor_stride;
  const ResponseGrid response(frame, stride);
  // The pixels whose magnitudes set the bin edges: every 4th pixel, if valid (their cells).
  std::vector<int> sampled;
  sampled.reserve(n / 4 + 1);
  for (std::size_t i = 0; i < n; i += 4) {
    if (frame.valid(i))
      sampled.push_back(
          response.cell(static_cast<int>(i % frame.width), static_cast<int>(i / frame.width)));
  }
  // `prepare` and the 4 spectra, then the 24 filters (largest level first), are independent
  // tasks.
  detail::parallel_for(
      kGaborScales + 1, nthreads,
      [&](int i) {
        if (i == 0)
          prepare();
        else
          spectra[i - 1] = level_spectrum(levels[i - 1], stride);
      },
      1);
  // Buffers per thread, reused from filter to filter.
  struct Buffers {
    GaborWork work;
    cv::Mat level_magnitude, full;
    std::vector<float> sample, candidates;
  };
  std::vector<Buffers> buffers(static_cast<std::size_t>(std::max(1, nthreads)));
  detail::parallel_for(
      filters + 1, nthreads,
      [&](int i, int t) {
        if (i == 0) {
          side();
          return;
        }
        GaborWork& work = buffers[t].work;
        cv::Mat &level_magnitude = buffers[t].level_magnitude, &full = buffers[t].full;
        std::vector<float>&sample = buffers[t].sample, &candidates = buffers[t].candidates;
        const int filter = i - 1;
        const int s = filter / kGaborOrientations, o = filter % kGaborOrientations;
        // On the response grid: level 0 is computed there; coarser levels are interpolated to it.
        if (s == 0) {
          gabor_magnitude(spectra[s], levels[s].size(), o, stride, params, work, full);
        } else {
          gabor_magnitude(spectra[s], levels[s].size(), o, stride, params, work, level_magnitude);
          cv::resize(level_magnitude, full, cv::Size(response.width, response.height), 0, 0,
                     cv::INTER_LINEAR);
        }
        CV_Assert(full.cols == response.width && full.rows == response.height);
        CV_Assert(full.isContinuous() && full.type() == CV_32F);
        const float* m = full.ptr<float>(0);
        // Fixed bin edges per filter over the frame: [0, quantile] in 10 bins, over valid points.
        sample.resize(sampled.size());
        for (std::size_t j = 0; j < sampled.size(); ++j) sample[j] = m[sampled[j]];
        if (!sample.empty()) {
          const std::size_t q =
              std::min(sample.size() - 1,
                       static_cast<std::size_t>(params.texture_clip_quantile * sample.size()));
          upper_edge[filter] = order_statistic(sample, q, candidates);
        }
        consume(filter, m);
      },
      1);
}

GaborBank gabor_bank(const Frame& frame, const FeatureParams& params, int threads) {
  GaborBank bank;
  if (!frame.organized()) return bank;
  FeatureParams every_pixel = params;  // the reference responses (see features.hpp)
  every_pixel.gabor_stride = 1;
  bank.width = frame.width;
  bank.height = frame.height;
  const std::size_t n = static_cast<std::size_t>(frame.width) * frame.height;
  bank.magnitude.assign(kGaborScales * kGaborOrientations, {});
  gabor_filters(
      frame, every_pixel, threads, bank.upper_edge,
      [&](int filter, const float* m) { bank.magnitude[filter].assign(m, m + n); }, [] {}, [] {});
  return bank;
}

}  // namespace

GaborBank gabor_bank(const Frame& frame, const FeatureParams& params) {
  return gabor_bank(frame, params, 0);
}

Eigen::VectorXf texture_feature(const GaborBank& bank, const std::vector<int>& pixels) {
  // One voxel: the division per point is cheaper than computing the bank's edges.
  Eigen::VectorXf f = Eigen::VectorXf::Zero(kTextureDims);
  if (bank.magnitude.empty()) return f;
  for (std::size_t filter = 0; filter < bank.magnitude.size(); ++filter) {
    const float upper = bank.upper_edge[filter];
    auto block = f.segment(static_cast<int>(filter) * kHistogramBins, kHistogramBins);
    for (int p : pixels) block(texture_bin(bank.magnitude[filter][p], upper)) += 1;
    normalise(block);
  }
  return f;
}

namespace {

// The box filter of point_normals restricted to each pixel's own surface: where the s x s window
// holds a depth step between neighbouring pixels (more than ratio x the depth) or a missing
// pixel, the mean of the valid pixels whose depth lies within ratio x (pixels apart) x the
// centre's depth of it (the image grid's depth-step test); elsewhere (most pixels) the plain
// box filter's mean. A plain box filter mixes an object's silhouette with the table a few
// centimetres behind it, and the bent normals read as a concave crease.
void edge_aware_smooth(const cv::Mat& xyz, const cv::Mat& mask, int s, float ratio, int threads,
                       cv::Mat& out) {
  const int w = xyz.cols, h = xyz.rows, lo = -(s / 2), hi = (s - 1) / 2;  // boxFilter's anchor
  cv::Mat sm, step(h, w, CV_8U), near_step;
  cv::boxFilter(xyz, out, -1, cv::Size(s, s), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  cv::boxFilter(mask, sm, -1, cv::Size(s, s), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  const auto* p = xyz.ptr<cv::Vec3f>(0);  // continuous: made whole by point_normals
  const float* m = mask.ptr<float>(0);
  auto z = [&](int i) { return std::abs(p[i][2]); };
  // A pixel that is missing or steps to its right or lower neighbour.
  auto steps = [&](int i, int j) { return std::abs(z(i) - z(j)) > ratio * std::min(z(i), z(j)); };
  detail::parallel_for(h, threads, [&](int v) {
    auto* row = step.ptr<std::uint8_t>(v);
    for (int u = 0; u < w; ++u) {
      const int i = v * w + u;
      row[u] = !(m[i] > 0) || (u + 1 < w && steps(i, i + 1)) || (v + 1 < h && steps(i, i + w));
    }
  });
  cv::dilate(step, near_step, cv::Mat::ones(s, s, CV_8U));
  auto* o = out.ptr<cv::Vec3f>(0);
  const float* count = sm.ptr<float>(0);
  detail::parallel_for(h, threads, [&](int v) {
    const auto* near = near_step.ptr<std::uint8_t>(v);
    for (int u = 0; u < w; ++u) {
      const int i = v * w + u;
      if (!(m[i] > 0)) continue;
      if (!near[u]) {
        o[i] /= count[i];
        continue;
      }
      const float zc = z(i);
      cv::Vec3f sum(0, 0, 0);
      int n = 0;
      for (int dv = lo; dv <= hi; ++dv) {
        const int vv = v + dv;
        if (vv < 0 || vv >= h) continue;
        for (int du = lo; du <= hi; ++du) {
          const int uu = u + du, j = vv * w + uu;
          if (uu < 0 || uu >= w || !(m[j] > 0)) continue;
          if (std::abs(z(j) - zc) > ratio * std::max(std::abs(du), std::abs(dv)) * zc) continue;
          sum += p[j];
          ++n;
        }
      }
      o[i] = sum / static_cast<float>(n);
    }
  });
}

// Normals of row v of an organized w x h frame from the smoothed points (valid where mask > 0):
// central differences s pixels apart, skipping neighbours across a depth step.
void normals_row(const Eigen::Vector3f* xyz, const float* mask, const Eigen::Vector3f* smooth,
                 int w, int h, int s, int v, Eigen::Vector3f* normals) {
  const bool up = v - s >= 0, down = v + s < h;
  for (int u = 0; u < w; ++u) {
    const int i = v * w + u;
    if (!(mask[i] > 0)) continue;
    const Eigen::Vector3f c = smooth[i];
    // Beyond this depth step a neighbour is another surface (|z|: some clouds look down -z).
    const float jump = 0.05f * std::abs(c.z());
    auto usable = [&](bool inside, int j) {
      return inside && mask[j] > 0 && std::abs(smooth[j].z() - c.z()) < jump;
    };
    const bool hl = usable(u - s >= 0, i - s), hr = usable(u + s < w, i + s);
    const bool ht = usable(up, i - s * w), hb = usable(down, i + s * w);
    if (!(hl || hr) || !(ht || hb)) continue;
    const Eigen::Vector3f du = (hr ? smooth[i + s] : c) - (hl ? smooth[i - s] : c);
    const Eigen::Vector3f dv = (hb ? smooth[i + s * w] : c) - (ht ? smooth[i - s * w] : c);
    Eigen::Vector3f n = du.cross(dv);
    const float len = n.norm();
    if (!(len > 0)) continue;
    n /= len;
    if (n.dot(xyz[i]) > 0) n = -n;  // towards the sensor
    normals[i] = n;
  }
}

// Unorganized: PCA normals over the k nearest valid points (the point itself among them), as
// Open3D's EstimateNormals computes them (the covariance from the neighbours' moments, the
// eigenvector of its smallest eigenvalue), oriented towards the sensor origin.
void unorganized_normals(const Frame& frame, int k, int threads,
                         std::vector<Eigen::Vector3f>& normals) {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::size_t> index;
  for (std::size_t i = 0; i < frame.size(); ++i)
    if (frame.valid(i)) {
      points.push_back(frame.xyz[i].cast<double>());
      index.push_back(i);
    }
  if (points.size() < 3) return;
  const detail::NearestPoints nearest(points);
  const int nthreads = detail::thread_count(threads);
  detail::parallel_for(
      static_cast<int>(points.size()), nthreads,
      [&](int j) {
        const auto neighbours = nearest.nearest(points[j], k);
        Eigen::Vector3d normal(0, 0, 1);
        if (neighbours.size() >= 3) {
          // Open3D's cumulants: means of x, y, z and of their products, in neighbour order.
          Eigen::Matrix<double, 9, 1> m = Eigen::Matrix<double, 9, 1>::Zero();
          for (const auto& [q, d2] : neighbours) {
            const Eigen::Vector3d& p = points[q];
            m(0) += p(0), m(1) += p(1), m(2) += p(2);
            m(3) += p(0) * p(0), m(4) += p(0) * p(1), m(5) += p(0) * p(2);
            m(6) += p(1) * p(1), m(7) += p(1) * p(2), m(8) += p(2) * p(2);
          }
          m /= static_cast<double>(neighbours.size());
          Eigen::Matrix3d cov;
          cov(0, 0) = m(3) - m(0) * m(0);
          cov(1, 1) = m(6) - m(1) * m(1);
          cov(2, 2) = m(8) - m(2) * m(2);
          cov(0, 1) = cov(1, 0) = m(4) - m(0) * m(1);
          cov(0, 2) = cov(2, 0) = m(5) - m(0) * m(2);
          cov(1, 2) = cov(2, 1) = m(7) - m(1) * m(2);
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
          solver.compute(cov, Eigen::ComputeEigenvectors);
          normal = solver.eigenvectors().col(0);
        }
        if (normal.dot(points[j]) > 0) normal = -normal;
        normals[index[j]] = normal.cast<float>();
      },
      256);
}

}  // namespace

std::vector<Eigen::Vector3f> point_normals(const Frame& frame, const FeatureParams& params,
                                           int threads) {
  const Eigen::Vector3f nan = Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
  std::vector<Eigen::Vector3f> normals(frame.size(), nan);
  if (!frame.organized()) {
    unorganized_normals(frame, params.normal_knn, threads, normals);
    return normals;
  }
  // Organized: smooth the xyz image (NaN-aware box filter), then cross the central differences
  // along rows and columns, as integral-image normal estimation does; skip depth discontinuities.
  const int w = frame.width, h = frame.height, s = std::max(1, params.normal_step);
  const int nthreads = detail::thread_count(threads);
  cv::Mat xyz(h, w, CV_32FC3), mask(h, w, CV_32F);
  // Every pixel is written by one iteration: rows can go to any thread. The loops run on
  // threads that block when done (parallel_for): this is the image-grid selection's path too.
  detail::parallel_for(h, nthreads, [&](int v) {
    for (int u = 0; u < w; ++u) {
      const int i = v * w + u;
      const bool ok = frame.valid(i);
      xyz.at<cv::Vec3f>(v, u) =
          ok ? cv::Vec3f(frame.xyz[i].x(), frame.xyz[i].y(), frame.xyz[i].z()) : cv::Vec3f(0, 0, 0);
      mask.at<float>(v, u) = ok ? 1.f : 0.f;
    }
  });
  cv::Mat sx, sm;
  if (params.normal_edge_ratio > 0) {
    edge_aware_smooth(xyz, mask, s, static_cast<float>(params.normal_edge_ratio), nthreads, sx);
  } else {
    cv::boxFilter(xyz, sx, -1, cv::Size(s, s), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
    cv::boxFilter(mask, sm, -1, cv::Size(s, s), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
    // The smoothed point of every valid pixel, once (each is read by up to 5 pixels below), in
    // place: a fresh buffer would cost more in page faults than the divisions it saves.
    detail::parallel_for(h, nthreads, [&](int v) {
      for (int u = 0; u < w; ++u)
        if (mask.at<float>(v, u) > 0)
          sx.at<cv::Vec3f>(v, u) = sx.at<cv::Vec3f>(v, u) / sm.at<float>(v, u);
    });
  }
  static_assert(sizeof(cv::Vec3f) == sizeof(Eigen::Vector3f), "same layout");
  CV_Assert(sx.isContinuous() && mask.isContinuous());
  const auto* smooth = reinterpret_cast<const Eigen::Vector3f*>(sx.ptr<cv::Vec3f>(0));
  detail::parallel_for(h, nthreads, [&](int v) {
    normals_row(frame.xyz.data(), mask.ptr<float>(0), smooth, w, h, s, v, normals.data());
  });
  return normals;
}

Eigen::MatrixXf voxel_features(const Frame& frame, const VoxelGrid& grid,
                               const std::vector<int>& voxels, const FeatureParams& params,
                               int threads) {
  Eigen::MatrixXf f = Eigen::MatrixXf::Zero(static_cast<Eigen::Index>(voxels.size()), kFeatureDims);
  const bool shape = params.use_shape && params.shape_weight > 0;
  const bool texture = params.use_texture && params.texture_weight > 0 && frame.organized();
  const bool colour = params.use_colour && params.colour_weight > 0;
  // The normals are computed while the Gabor filters run (as one more task among them) when
  // there is texture, on their own otherwise.
  std::vector<Eigen::Vector3f> normals;
  auto compute_normals = [&] {
    if (shape) normals = point_normals(frame, params, threads);
  };
  if (!texture) compute_normals();
  // Texture: each filter's 10 bins of every row, made by the task that computed the filter from
  // its magnitude image (no bank of 24 full images is kept). A histogram sums to its point count
  // exactly (integer counts), so normalise() divides each count by that count, as below.
  const int filters = kGaborScales * kGaborOrientations;
  std::vector<std::vector<float>> texture_blocks(texture ? filters : 0);
  if (texture) {
    // The response cells of the rows' points in image order, so that the magnitude images are
    // read front to back: (cell, row, weight) with weight the row's points in the cell (at
    // stride 2 a cell holds up to 4 pixels, mostly of one voxel: binned once).
    std::vector<int> row_of_voxel(grid.size(), -1), cells, cell_row, cell_weight;
    for (std::size_t row = 0; row < voxels.size(); ++row)
      row_of_voxel[voxels[row]] = static_cast<int>(row);
    auto row_of_pixel = [&](int u, int v) {
      const int voxel = grid.voxel_of_point[static_cast<std::size_t>(v) * frame.width + u];
      return voxel >= 0 ? row_of_voxel[voxel] : -1;
    };
    const ResponseGrid response(frame, params.gabor_stride);
    auto build_cells = [&] {  // run beside the spectra
      for (int cy = 0; cy < response.height; ++cy)
        for (int cx = 0; cx < response.width; ++cx) {
          const std::size_t first = cells.size();
          for (int v = cy * response.stride; v < std::min(frame.height, (cy + 1) * response.stride);
               ++v)
            for (int u = cx * response.stride;
                 u < std::min(frame.width, (cx + 1) * response.stride); ++u) {
              const int row = row_of_pixel(u, v);
              if (row < 0) continue;
              std::size_t t = first;
              while (t < cells.size() && cell_row[t] != row) ++t;
              if (t < cells.size()) {
                ++cell_weight[t];
              } else {
                cells.push_back(cy * response.width + cx);
                cell_row.push_back(row);
                cell_weight.push_back(1);
              }
            }
        }
    };
    // Every weight is 1 at stride 1: the unweighted count (the paper's definition, same bits).
    const std::vector<int>* weights = params.gabor_stride == 1 ? nullptr : &cell_weight;
    const float weight = static_cast<float>(params.texture_weight);
    std::vector<float> upper_edge;
    gabor_filters(
        frame, params, threads, upper_edge,
        [&](int filter, const float* m) {
          std::vector<int> count(voxels.size() * kHistogramBins, 0);
          TextureEdges(upper_edge[filter]).histograms(m, cells, cell_row, weights, count.data());
          std::vector<float>& out = texture_blocks[filter];
          out.assign(voxels.size() * kHistogramBins, 0.f);
          for (std::size_t row = 0; row < voxels.size(); ++row) {
            const std::size_t points = grid.points[voxels[row]].size();
            if (points == 0) continue;
            const float total = static_cast<float>(points);
            for (int b = 0; b < kHistogramBins; ++b)
              out[row * kHistogramBins + b] =
                  static_cast<float>(count[row * kHistogramBins + b]) / total * weight;
          }
        },
        build_cells, compute_normals);
  }
  // Each row is written by one iteration only: the result does not depend on the thread count.
  detail::parallel_for(
      static_cast<int>(voxels.size()), detail::thread_count(threads),
      [&](int r) {
        const std::size_t row = static_cast<std::size_t>(r);
        const std::vector<int>& pts = grid.points[voxels[row]];
        if (colour) {
          f.row(row).segment(0, kColourDims) =
              colour_block(pts.size(),
                           [&](std::size_t j) -> const Rgb& { return frame.rgb[pts[j]]; }) *
              static_cast<float>(params.colour_weight);
        }
        if (shape) {
          auto point = [&](std::size_t j) -> const Eigen::Vector3f& { return frame.xyz[pts[j]]; };
          auto normal = [&](std::size_t j) -> const Eigen::Vector3f& { return normals[pts[j]]; };
          f.row(row).segment(kColourDims + kTextureDims, kShapeDims) =
              shape_block(pts.size(), point, pts.size(), normal) *
              static_cast<float>(params.shape_weight);
        }
      },
      64);
  // The texture blocks, column by column.
  detail::parallel_for(static_cast<int>(texture_blocks.size()) * kHistogramBins,
                       detail::thread_count(threads), [&](int c) {
                         const float* block =
                             texture_blocks[c / kHistogramBins].data() + c % kHistogramBins;
                         float* column = f.col(kColourDims + c).data();
                         for (std::size_t row = 0; row < voxels.size(); ++row)
                           column[row] = block[row * kHistogramBins];
                       });
  return f;
}

}  // namespace proxseg
