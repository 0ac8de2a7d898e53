// Colour scores [extension, docs/method.md "Colour in recognition"]: how well the colours of a
// candidate agree with those of a posed view, point by point (chromaticity and brightness) and
// as distributions (chromaticity histograms).
#include <proxseg/recognition/registration.hpp>

#include "colour_scores.hpp"
#include "search_index.hpp"
#include "transformation_estimation.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace proxseg {

using detail::apply;
using detail::explained_colour;
using detail::nearest;

double detail::explained_colour(const Cloud& cand, const Cloud& view, const Eigen::Matrix4d& pose,
                                double delta, double brightness_sigma, double& colour) {
  const Eigen::Matrix4d inv = pose.inverse();
  int n = 0;
  double sum = 0;
  for (std::size_t i = 0; i < cand.size(); ++i) {
    double d2 = 0;
    const int j = nearest(view.index->points, apply(inv, cand.points[i]), delta, d2);
    if (j < 0 || d2 > delta * delta) continue;
    ++n;
    sum += point_colour_agreement(cand.colours[i], view.colours[j], brightness_sigma);
  }
  colour = n ? sum / n : 0;
  return cand.size() ? double(n) / cand.size() : 0;
}

double chromaticity_histogram_agreement(const std::vector<Rgb>& a, const std::vector<Rgb>& b) {
  if (a.empty() || b.empty()) return 0;
  // 20 x 20 cells over the (r, g) chromaticity square; each colour a Gaussian of the width that
  // chromaticity_agreement() gives a pair of such colours, cut at 3 sigma.
  constexpr int kCells = 20;
  constexpr double kSigma0 = 0.05, kNoise = 6;
  const auto histogram = [](const std::vector<Rgb>& colours) {
    std::vector<double> h(kCells * kCells, 0.0);
    for (const Rgb& c : colours) {
      const Eigen::Vector3d v = Eigen::Vector3d(c[0], c[1], c[2]).array() + 1;
      const double s = v.sum();
      const double sigma = std::sqrt(kSigma0 * kSigma0 + 2 * (kNoise / s) * (kNoise / s));
      const Eigen::Vector2d x(v.x() / s, v.y() / s);
      const int lo_x = std::max(0, static_cast<int>(std::floor((x.x() - 3 * sigma) * kCells)));
      const int hi_x =
          std::min(kCells - 1, static_cast<int>(std::floor((x.x() + 3 * sigma) * kCells)));
      const int lo_y = std::max(0, static_cast<int>(std::floor((x.y() - 3 * sigma) * kCells)));
      const int hi_y =
          std::min(kCells - 1, static_cast<int>(std::floor((x.y() + 3 * sigma) * kCells)));
      std::vector<double> w;
      double total = 0;
      for (int cy = lo_y; cy <= hi_y; ++cy)
        for (int cx = lo_x; cx <= hi_x; ++cx) {
          const Eigen::Vector2d centre((cx + 0.5) / kCells, (cy + 0.5) / kCells);
          const double g = std::exp(-0.5 * (centre - x).squaredNorm() / (sigma * sigma));
          w.push_back(g);
          total += g;
        }
      if (!(total > 0)) continue;
      std::size_t k = 0;
      for (int cy = lo_y; cy <= hi_y; ++cy)
        for (int cx = lo_x; cx <= hi_x; ++cx) h[cy * kCells + cx] += w[k++] / total;
    }
    double sum = 0;
    for (double x : h) sum += x;
    if (sum > 0)
      for (double& x : h) x /= sum;
    return h;
  };
  const std::vector<double> ha = histogram(a), hb = histogram(b);
  double bc = 0;
  for (std::size_t k = 0; k < ha.size(); ++k) bc += std::sqrt(ha[k] * hb[k]);
  // Two single colours d apart have a coefficient of exp(-d^2 / (8 sigma^2)); its 4th power is
  // chromaticity_agreement()'s exp(-d^2 / (2 sigma^2)): both terms on one scale.
  return std::pow(std::min(1.0, bc), 4);
}

double point_colour_agreement(const Rgb& a, const Rgb& b, double brightness_sigma) {
  const double c = chromaticity_agreement(a, b);
  if (!(brightness_sigma > 0)) return c;
  const double ratio = std::log((a[0] + a[1] + a[2] + 3.0) / (b[0] + b[1] + b[2] + 3.0));
  return c * std::exp(-0.5 * ratio * ratio / (brightness_sigma * brightness_sigma));
}

double chromaticity_agreement(const Rgb& a, const Rgb& b) {
  // sigma0: a shaded and a lit side of one paint stay within ~0.02, a red and an orange of the
  // same brightness are ~0.2 apart. The chromaticity of a dark point is uncertain by about the
  // sensor's colour noise over its brightness (kNoise levels per channel), so dark points (a
  // black object) agree with any dark point but not with a bright colour.
  constexpr double kSigma0 = 0.05, kNoise = 6;
  const Eigen::Vector3d ca = Eigen::Vector3d(a[0], a[1], a[2]).array() + 1;
  const Eigen::Vector3d cb = Eigen::Vector3d(b[0], b[1], b[2]).array() + 1;
  const double sa = ca.sum(), sb = cb.sum();
  const double sigma2 =
      kSigma0 * kSigma0 + (kNoise / sa) * (kNoise / sa) + (kNoise / sb) * (kNoise / sb);
  const double d2 = (ca / sa - cb / sb).squaredNorm();
  return std::exp(-0.5 * d2 / sigma2);
}

double colour_agreement(const Cloud& candidate, const Cloud& view, const Eigen::Matrix4d& pose,
                        double delta) {
  if (candidate.colours.empty() || view.colours.empty()) return 1;
  double colour = 0;
  explained_colour(candidate, view, pose, delta, 0, colour);  // chromaticity only
  return colour;
}

}  // namespace proxseg
