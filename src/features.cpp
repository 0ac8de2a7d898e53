// Per-voxel features [paper 3.1]: colour (HSV histograms), texture (Gabor bank), shape
// (normalised eigenvalues, curvature, normal-angle histogram).
#include <proxseg/features.hpp>

#include <omp.h>
#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace proxseg {
namespace {

constexpr double kPi = 3.14159265358979323846;

int bin_of(double t, int bins) {  // t in [0, 1] -> 0..bins-1
  return std::clamp(static_cast<int>(t * bins), 0, bins - 1);
}

// HSV with h in [0, 1) (fraction of the hue circle), s and v in [0, 1].
Eigen::Vector3d rgb_to_hsv(const Rgb& c) {
  const double r = c[0] / 255.0, g = c[1] / 255.0, b = c[2] / 255.0;
  const double mx = std::max({r, g, b}), mn = std::min({r, g, b}), delta = mx - mn;
  double h = 0;
  if (delta > 0) {
    if (mx == r) {
      // fmod(x, 6) for x = (g - b) / delta + 6 in [5, 7], exactly (x - 6 is exact there).
      const double x = (g - b) / delta + 6.0;
      h = x >= 6.0 ? x - 6.0 : x;
    } else if (mx == g) {
      h = (b - r) / delta + 2.0;
    } else {
      h = (r - g) / delta + 4.0;
    }
    h /= 6.0;
  }
  const double s = mx > 0 ? delta / mx : 0.0;
  return {h, s, mx};
}

void normalise(Eigen::Ref<Eigen::VectorXf> block) {
  const float sum = block.sum();
  if (sum > 0) block /= sum;
}

// exp(-(du2 + dv2) / denom) rounded to float, bit for bit as the direct expression gives it, with
// the exponential of a sum computed as a product of two exponentials (one per column, one per
// row) instead of one call per pixel. The product differs from the direct value by far less than
// 1e-12 relative; it is used only when it lies further than that from a midpoint between two
// floats, so that both round to the same float. Otherwise (a few pixels in a million) the direct
// expression is evaluated.
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

// Spectrum of one pyramid level (the level sizes are already fast DFT sizes, but padding keeps
// any size right).
cv::Mat level_spectrum(const cv::Mat& grey) {
  const int rows = cv::getOptimalDFTSize(grey.rows), cols = cv::getOptimalDFTSize(grey.cols);
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
struct GaborWork {
  cv::Mat filtered, response, planes[2];
  std::vector<double> du2, dv2, eu, ev;
};
void gabor_magnitude(const cv::Mat& spectrum, cv::Size size, int o, const FeatureParams& params,
                     GaborWork& work, cv::Mat& magnitude) {
  const int rows = spectrum.rows, cols = spectrum.cols;
  const double f0 = 1.0 / params.gabor_wavelength;           // cycles per pixel
  const double sf = 1.0 / (2.0 * kPi * params.gabor_sigma);  // frequency-domain std
  const double denom = 2 * sf * sf;
  const double theta = o * kPi / kGaborOrientations;
  const double fu = f0 * std::cos(theta), fv = f0 * std::sin(theta);
  work.du2.resize(cols);
  work.eu.resize(cols);
  for (int c = 0; c < cols; ++c) {
    const double u = (c <= cols / 2 ? c : c - cols) / static_cast<double>(cols);
    work.du2[c] = (u - fu) * (u - fu);
    work.eu[c] = std::exp(-work.du2[c] / denom);
  }
  work.dv2.resize(rows);
  work.ev.resize(rows);
  for (int r = 0; r < rows; ++r) {
    const double v = (r <= rows / 2 ? r : r - rows) / static_cast<double>(rows);
    work.dv2[r] = (v - fv) * (v - fv);
    work.ev[r] = std::exp(-work.dv2[r] / denom);
  }
  work.filtered.create(spectrum.size(), spectrum.type());
  for (int r = 0; r < rows; ++r) {
    const auto* in = spectrum.ptr<cv::Vec2f>(r);
    auto* dst = work.filtered.ptr<cv::Vec2f>(r);
    for (int c = 0; c < cols; ++c)
      dst[c] = in[c] * gaussian_factor(work.eu[c], work.ev[r], work.du2[c], work.dv2[r], denom);
  }
  cv::idft(work.filtered, work.response, cv::DFT_COMPLEX_OUTPUT | cv::DFT_SCALE);
  cv::split(work.response(cv::Rect(0, 0, size.width, size.height)), work.planes);
  cv::magnitude(work.planes[0], work.planes[1], magnitude);
}

}  // namespace

Eigen::VectorXf colour_feature(const std::vector<Rgb>& colours) {
  Eigen::VectorXf f = Eigen::VectorXf::Zero(kColourDims);
  for (const Rgb& c : colours) {
    const Eigen::Vector3d hsv = rgb_to_hsv(c);
    f(bin_of(hsv[0], kHistogramBins) * kHistogramBins + bin_of(hsv[1], kHistogramBins)) += 1;
    f(100 + bin_of(hsv[2], kHistogramBins)) += 1;
  }
  normalise(f.head(100));
  normalise(f.tail(10));
  return f;
}

Eigen::VectorXf shape_feature(const std::vector<Eigen::Vector3f>& points,
                              const std::vector<Eigen::Vector3f>& normals) {
  Eigen::VectorXf f = Eigen::VectorXf::Zero(kShapeDims);
  if (points.size() >= 3) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& p : points) mean += p.cast<double>();
    mean /= static_cast<double>(points.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& p : points) {
      const Eigen::Vector3d d = p.cast<double>() - mean;
      cov += d * d.transpose();
    }
    cov /= static_cast<double>(points.size());
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
  for (const auto& n : normals) {
    if (!n.allFinite()) continue;
    const double theta = std::acos(std::clamp(static_cast<double>(n.z()), -1.0, 1.0));
    const double phi = std::atan2(static_cast<double>(n.y()), static_cast<double>(n.x()));
    f(4 + bin_of(theta / kPi, kHistogramBins) * kHistogramBins +
      bin_of((phi + kPi) / (2 * kPi), kHistogramBins)) += 1;
  }
  normalise(f.tail(100));
  return f;
}

namespace {

GaborBank gabor_bank(const Frame& frame, const FeatureParams& params, int threads) {
  GaborBank bank;
  if (!frame.organized()) return bank;
  bank.width = frame.width;
  bank.height = frame.height;
  const int nthreads = threads > 0 ? threads : omp_get_max_threads();
  cv::Mat grey(frame.height, frame.width, CV_32F);
#pragma omp parallel for schedule(static) num_threads(nthreads)
  for (int v = 0; v < frame.height; ++v) {
    float* row = grey.ptr<float>(v);
    for (int u = 0; u < frame.width; ++u) {
      const Rgb& c = frame.rgb[static_cast<std::size_t>(v) * frame.width + u];
      row[u] = static_cast<float>((0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2]) / 255.0);
    }
  }
  // Scale s filters the s-th level of a Gaussian pyramid with the same kernel: the wavelength in
  // the full image doubles with each scale at a quarter of the cost.
  std::vector<cv::Mat> levels(kGaborScales);
  levels[0] = grey;
  for (int s = 1; s < kGaborScales; ++s) cv::pyrDown(levels[s - 1], levels[s]);
  const int filters = kGaborScales * kGaborOrientations;
  bank.magnitude.assign(filters, {});
  bank.upper_edge.assign(filters, 0.f);
  const std::size_t n = static_cast<std::size_t>(frame.width) * frame.height;
  std::vector<cv::Mat> spectra(kGaborScales);
  // The 4 spectra, then the 24 filters (largest level first), are independent tasks; each writes
  // only its own outputs, so the bank does not depend on the number of threads.
#pragma omp parallel num_threads(nthreads)
  {
#pragma omp for schedule(dynamic, 1)
    for (int s = 0; s < kGaborScales; ++s) spectra[s] = level_spectrum(levels[s]);
    GaborWork work;
    cv::Mat level_magnitude;
    std::vector<float> sample;
#pragma omp for schedule(dynamic, 1)
    for (int filter = 0; filter < filters; ++filter) {
      const int s = filter / kGaborOrientations, o = filter % kGaborOrientations;
      gabor_magnitude(spectra[s], levels[s].size(), o, params, work, level_magnitude);
      // Back to full resolution, straight into the bank.
      auto& m = bank.magnitude[filter];
      m.resize(n);
      cv::Mat full(grey.size(), CV_32F, m.data());
      cv::resize(level_magnitude, full, grey.size(), 0, 0, cv::INTER_LINEAR);
      CV_Assert(full.data == reinterpret_cast<uchar*>(m.data()));
      // Fixed bin edges per filter over the frame: [0, quantile] in 10 bins, over valid points.
      sample.clear();
      sample.reserve(n / 4 + 1);
      for (std::size_t i = 0; i < n; i += 4)
        if (frame.valid(i)) sample.push_back(m[i]);
      if (!sample.empty()) {
        const std::size_t q =
            std::min(sample.size() - 1,
                     static_cast<std::size_t>(params.texture_clip_quantile * sample.size()));
        std::nth_element(sample.begin(), sample.begin() + q, sample.end());
        bank.upper_edge[filter] = sample[q];
      }
    }
  }
  return bank;
}

}  // namespace

GaborBank gabor_bank(const Frame& frame, const FeatureParams& params) {
  return gabor_bank(frame, params, 0);
}

namespace {

// Bin of a magnitude m under the upper edge of its filter: the reference definition.
int texture_bin(float m, float upper) {
  return upper > 0 ? bin_of(m / upper, kHistogramBins) : 0;
}

// The bin edges of one filter as magnitudes, so that binning a point takes comparisons instead of
// a division: texture_bin(m) >= k exactly when m >= edge[k - 1], for m < exact_above (beyond
// that, where the quotient could leave the int range, the division is done). texture_bin is
// monotone in m there (the float quotient is monotone), so each edge is the first float for
// which it reaches k: found by bisection over the float bit patterns, which are in the order of
// the values for non-negative floats.
struct TextureEdges {
  std::array<float, kHistogramBins - 1> edge;
  float exact_above;
  explicit TextureEdges(float upper) {
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
  int bin(float m, float upper) const {
    if (!(m < exact_above)) return texture_bin(m, upper);
    int b = 0;
    for (const float e : edge) b += m >= e;
    return b;
  }
};

std::vector<TextureEdges> texture_edges(const GaborBank& bank) {
  std::vector<TextureEdges> edges;
  for (const float upper : bank.upper_edge) edges.emplace_back(upper);
  return edges;
}

// Texture block of one voxel (see texture_feature) with the bank's edges already computed.
Eigen::VectorXf texture_histograms(const GaborBank& bank, const std::vector<TextureEdges>& edges,
                                   const std::vector<int>& pixels) {
  Eigen::VectorXf f = Eigen::VectorXf::Zero(kTextureDims);
  if (bank.magnitude.empty()) return f;
  for (std::size_t filter = 0; filter < bank.magnitude.size(); ++filter) {
    const float upper = bank.upper_edge[filter];
    const TextureEdges& e = edges[filter];
    const float* magnitude = bank.magnitude[filter].data();
    int count[kHistogramBins] = {};
    for (int p : pixels) ++count[e.bin(magnitude[p], upper)];
    auto block = f.segment(static_cast<int>(filter) * kHistogramBins, kHistogramBins);
    for (int b = 0; b < kHistogramBins; ++b) block(b) = static_cast<float>(count[b]);
    normalise(block);
  }
  return f;
}

}  // namespace

Eigen::VectorXf texture_feature(const GaborBank& bank, const std::vector<int>& pixels) {
  return texture_histograms(bank, texture_edges(bank), pixels);
}

namespace {

std::vector<Eigen::Vector3f> point_normals(const Frame& frame, const FeatureParams& params,
                                           int threads) {
  const Eigen::Vector3f nan = Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
  std::vector<Eigen::Vector3f> normals(frame.size(), nan);
  if (!frame.organized()) {
    // Unorganized: PCA normals over k nearest neighbours (Open3D), oriented to the sensor origin.
    open3d::geometry::PointCloud cloud;
    std::vector<std::size_t> index;
    for (std::size_t i = 0; i < frame.size(); ++i)
      if (frame.valid(i)) {
        cloud.points_.push_back(frame.xyz[i].cast<double>());
        index.push_back(i);
      }
    if (cloud.points_.size() < 3) return normals;
    cloud.EstimateNormals(open3d::geometry::KDTreeSearchParamKNN(params.normal_knn), false);
    for (std::size_t j = 0; j < index.size(); ++j) {
      Eigen::Vector3d n = cloud.normals_[j];
      if (n.dot(cloud.points_[j]) > 0) n = -n;
      normals[index[j]] = n.cast<float>();
    }
    return normals;
  }
  // Organized: smooth the xyz image (NaN-aware box filter), then cross the central differences
  // along rows and columns, as integral-image normal estimation does; skip depth discontinuities.
  const int w = frame.width, h = frame.height, s = std::max(1, params.normal_step);
  const int nthreads = threads > 0 ? threads : omp_get_max_threads();
  cv::Mat xyz(h, w, CV_32FC3), mask(h, w, CV_32F);
  // Every pixel is written by one iteration: rows can go to any thread.
#pragma omp parallel for schedule(static) num_threads(nthreads)
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const int i = v * w + u;
      const bool ok = frame.valid(i);
      xyz.at<cv::Vec3f>(v, u) =
          ok ? cv::Vec3f(frame.xyz[i].x(), frame.xyz[i].y(), frame.xyz[i].z()) : cv::Vec3f(0, 0, 0);
      mask.at<float>(v, u) = ok ? 1.f : 0.f;
    }
  cv::Mat sx, sm;
  cv::boxFilter(xyz, sx, -1, cv::Size(s, s), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  cv::boxFilter(mask, sm, -1, cv::Size(s, s), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  auto at = [&](int u, int v, Eigen::Vector3f& p) {
    if (u < 0 || v < 0 || u >= w || v >= h || !frame.valid(v * w + u)) return false;
    const float m = sm.at<float>(v, u);
    const cv::Vec3f q = sx.at<cv::Vec3f>(v, u) / m;
    p = Eigen::Vector3f(q[0], q[1], q[2]);
    return true;
  };
#pragma omp parallel for schedule(static) num_threads(nthreads)
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      Eigen::Vector3f c, l, r, t, b;
      if (!at(u, v, c)) continue;
      const float jump = 0.05f * c.z();  // beyond this depth step a neighbour is another surface
      auto usable = [&](bool ok, const Eigen::Vector3f& p) {
        return ok && std::abs(p.z() - c.z()) < jump;
      };
      const bool hl = usable(at(u - s, v, l), l), hr = usable(at(u + s, v, r), r);
      const bool ht = usable(at(u, v - s, t), t), hb = usable(at(u, v + s, b), b);
      if (!(hl || hr) || !(ht || hb)) continue;
      const Eigen::Vector3f du = (hr ? r : c) - (hl ? l : c);
      const Eigen::Vector3f dv = (hb ? b : c) - (ht ? t : c);
      Eigen::Vector3f n = du.cross(dv);
      const float len = n.norm();
      if (!(len > 0)) continue;
      n /= len;
      if (n.dot(frame.xyz[v * w + u]) > 0) n = -n;  // towards the sensor
      normals[v * w + u] = n;
    }
  }
  return normals;
}

}  // namespace

std::vector<Eigen::Vector3f> point_normals(const Frame& frame, const FeatureParams& params) {
  return point_normals(frame, params, 0);
}

Eigen::MatrixXf voxel_features(const Frame& frame, const VoxelGrid& grid,
                               const std::vector<int>& voxels, const FeatureParams& params,
                               int threads) {
  Eigen::MatrixXf f = Eigen::MatrixXf::Zero(static_cast<Eigen::Index>(voxels.size()), kFeatureDims);
  const bool shape = params.use_shape && params.shape_weight > 0;
  const bool texture = params.use_texture && params.texture_weight > 0 && frame.organized();
  const bool colour = params.use_colour && params.colour_weight > 0;
  const std::vector<Eigen::Vector3f> normals =
      shape ? point_normals(frame, params, threads) : std::vector<Eigen::Vector3f>{};
  const GaborBank bank = texture ? gabor_bank(frame, params, threads) : GaborBank{};
  const std::vector<TextureEdges> edges = texture_edges(bank);
  // Each row is written by one iteration only: the result does not depend on the thread count.
#pragma omp parallel for schedule(dynamic, 64) \
    num_threads(threads > 0 ? threads : omp_get_max_threads())
  for (std::size_t row = 0; row < voxels.size(); ++row) {
    const std::vector<int>& pts = grid.points[voxels[row]];
    if (colour) {
      std::vector<Rgb> colours;
      colours.reserve(pts.size());
      for (int i : pts) colours.push_back(frame.rgb[i]);
      f.row(row).segment(0, kColourDims) =
          colour_feature(colours) * static_cast<float>(params.colour_weight);
    }
    if (texture)
      f.row(row).segment(kColourDims, kTextureDims) =
          texture_histograms(bank, edges, pts) * static_cast<float>(params.texture_weight);
    if (shape) {
      std::vector<Eigen::Vector3f> p, n;
      p.reserve(pts.size());
      n.reserve(pts.size());
      for (int i : pts) {
        p.push_back(frame.xyz[i]);
        n.push_back(normals[i]);
      }
      f.row(row).segment(kColourDims + kTextureDims, kShapeDims) =
          shape_feature(p, n) * static_cast<float>(params.shape_weight);
    }
  }
  return f;
}

}  // namespace proxseg
