// The texture feature [paper 3.1]: 24 Gabor filters (6 orientations x 4 scales) computed in the
// frequency domain on a Gaussian pyramid, their magnitudes binned into 10 bins per filter.
#include "gabor_detail.hpp"
#include "gabor_reference.hpp"
#include "util/angles.hpp"
#include "util/parallel_for.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace proxseg {
namespace {

using detail::bin_of;
using detail::kPi;
using detail::normalise;
using detail::ResponseGrid;
using detail::texture_bin;

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

// The frame's grey image and its Gaussian pyramid: scale s filters the s-th level with the same
// kernel, so the wavelength in the full image doubles with each scale at a quarter of the cost.
std::vector<cv::Mat> grey_pyramid(const Frame& frame, int nthreads) {
  cv::Mat grey(frame.height, frame.width, CV_32F);
  detail::parallel_for(frame.height, nthreads, [&](int v) {
    float* row = grey.ptr<float>(v);
    for (int u = 0; u < frame.width; ++u) {
      const Rgb& c = frame.rgb[static_cast<std::size_t>(v) * frame.width + u];
      row[u] = static_cast<float>((0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2]) / 255.0);
    }
  });
  std::vector<cv::Mat> levels(kGaborScales);
  levels[0] = grey;
  for (int s = 1; s < kGaborScales; ++s) cv::pyrDown(levels[s - 1], levels[s]);
  return levels;
}

// The cells of the pixels whose magnitudes set the bin edges: every 4th pixel, if valid.
std::vector<int> sampled_cells(const Frame& frame, const ResponseGrid& response) {
  const std::size_t n = static_cast<std::size_t>(frame.width) * frame.height;
  std::vector<int> sampled;
  sampled.reserve(n / 4 + 1);
  for (std::size_t i = 0; i < n; i += 4) {
    if (frame.valid(i))
      sampled.push_back(
          response.cell(static_cast<int>(i % frame.width), static_cast<int>(i / frame.width)));
  }
  return sampled;
}

}  // namespace

namespace detail {

void gabor_filters(const Frame& frame, const FeatureParams& params, int threads,
                   std::vector<float>& upper_edge,
                   const std::function<void(int filter, const float* magnitude)>& consume,
                   const std::function<void()>& prepare, const std::function<void()>& side) {
  const int nthreads = detail::thread_count(threads);
  const std::vector<cv::Mat> levels = grey_pyramid(frame, nthreads);
  const int filters = kGaborScales * kGaborOrientations;
  upper_edge.assign(filters, 0.f);
  std::vector<cv::Mat> spectra(kGaborScales);
  const int stride = params.gabor_stride;
  const ResponseGrid response(frame, stride);
  const std::vector<int> sampled = sampled_cells(frame, response);
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

}  // namespace detail

namespace {

using detail::gabor_filters;

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

}  // namespace proxseg
