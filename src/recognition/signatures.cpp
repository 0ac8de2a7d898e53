// Signatures [extension, docs/method.md "A database that scales"]: the summary of a cloud that
// the shortlist compares (mean FPFH, chromaticity histogram, spread), the signatures of the parts
// an occlusion would leave of a view, their distances, and the quantised sketches that bound
// those distances [docs/database.md].
#include <proxseg/recognition/registration.hpp>

#include "search_index.hpp"
#include "signatures.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace proxseg {
namespace {

// Chromaticity (r, g) of a colour, lifted like chromaticity_agreement().
Eigen::Vector2d chromaticity(const Rgb& c) {
  const Eigen::Vector3d v = Eigen::Vector3d(c[0], c[1], c[2]).array() + 5;
  return Eigen::Vector2d(v.x(), v.y()) / v.sum();
}

// The signature of the points `keep` of c (indices, ascending; every point when null).
Signature signature_of(const Cloud& c, const std::vector<int>* keep) {
  Signature s;
  const int n = keep ? static_cast<int>(keep->size()) : static_cast<int>(c.size());
  if (n == 0) return s;
  const auto at = [&](int k) { return keep ? (*keep)[k] : k; };
  Eigen::Vector3d centroid = c.centroid;
  if (keep) {
    Eigen::VectorXd shape = Eigen::VectorXd::Zero(c.features.rows());
    centroid.setZero();
    for (int i : *keep) {
      shape += c.features.col(i);
      centroid += c.points[i];
    }
    centroid /= n;
    s.shape = (shape / n).cast<float>();
  } else {
    s.shape = c.features.rowwise().mean().cast<float>();
  }
  for (int b = 0; b + kFpfhBins <= s.shape.size(); b += kFpfhBins) {
    const float sum = s.shape.segment(b, kFpfhBins).sum();
    if (sum > 0) s.shape.segment(b, kFpfhBins) /= sum;
  }
  if (!c.colours.empty()) {
    // 8 x 8 cells over the (r, g) chromaticity square, bilinear votes so that a colour near a
    // cell border does not jump between cells.
    constexpr int kCells = 8;
    s.colour = Eigen::VectorXf::Zero(kCells * kCells);
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector2d x =
          chromaticity(c.colours[at(k)]) * kCells - Eigen::Vector2d::Constant(0.5);
      const int x0 = static_cast<int>(std::floor(x.x())), y0 = static_cast<int>(std::floor(x.y()));
      const double fx = x.x() - x0, fy = x.y() - y0;
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          const int cx = std::clamp(x0 + dx, 0, kCells - 1),
                    cy = std::clamp(y0 + dy, 0, kCells - 1);
          s.colour[cy * kCells + cx] += static_cast<float>((dx ? fx : 1 - fx) * (dy ? fy : 1 - fy));
        }
    }
    s.colour /= s.colour.sum();
  }
  double sum2 = 0;
  for (int k = 0; k < n; ++k) sum2 += (c.points[at(k)] - centroid).squaredNorm();
  s.spread = std::sqrt(sum2 / n);
  return s;
}

}  // namespace

Signature detail::make_signature(const Cloud& c) {
  return signature_of(c, nullptr);
}

// The parts an occlusion would leave of a view [extension, docs/method.md "A database that
// scales"]: the paper's occlusions (and an object in front) hide the points near some point of
// the view, which moves the mean FPFH and shrinks the spread, so the whole view's signature is far
// from what is left of it. Each part is the cloud without the share kPartShares of its points
// nearest to a centre; the kPartCentres centres are spread over the cloud by farthest-point
// sampling from the point farthest from the centroid.
void add_part_signatures(Cloud& c) {
  constexpr int kPartCentres = 8;
  constexpr double kPartShares[] = {0.15, 0.3, 0.45};
  Signature& s = c.signature;
  s.parts.clear();
  const int n = static_cast<int>(c.size());
  if (n < 2 * kPartCentres) return;
  std::vector<int> centres;
  int first = 0;
  for (int i = 1; i < n; ++i)
    if ((c.points[i] - c.centroid).squaredNorm() > (c.points[first] - c.centroid).squaredNorm())
      first = i;
  centres.push_back(first);
  std::vector<double> d2(n, std::numeric_limits<double>::infinity());
  while (static_cast<int>(centres.size()) < kPartCentres) {
    int far = 0;
    for (int i = 0; i < n; ++i) {
      d2[i] = std::min(d2[i], (c.points[i] - c.points[centres.back()]).squaredNorm());
      if (d2[i] > d2[far]) far = i;
    }
    centres.push_back(far);
  }
  std::vector<int> order(n), keep;
  std::vector<double> dist(n);
  for (int centre : centres) {
    for (int i = 0; i < n; ++i) dist[i] = (c.points[i] - c.points[centre]).squaredNorm();
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return dist[a] < dist[b]; });
    for (double share : kPartShares) {
      keep.assign(order.begin() + static_cast<int>(share * n), order.end());
      std::sort(keep.begin(), keep.end());
      s.parts.push_back(signature_of(c, &keep));
    }
  }
}

double view_distance(const Signature& candidate, const Signature& view) {
  double d = signature_distance(candidate, view);
  for (const Signature& part : view.parts) d = std::min(d, signature_distance(candidate, part));
  return d;
}

double signature_distance(const Signature& a, const Signature& b) {
  double d = 0;
  if (a.shape.size() == b.shape.size() && a.shape.size() > 0)
    d += (a.shape - b.shape).lpNorm<1>() / 2 / (a.shape.size() / kFpfhBins);
  if (a.colour.size() > 0 && a.colour.size() == b.colour.size())
    d += (a.colour - b.colour).lpNorm<1>() / 2;
  if (a.spread > 0 && b.spread > 0) d += std::abs(std::log(a.spread / b.spread));
  return d;
}

namespace {

constexpr int kSubBins = 11;             // an FPFH sub-histogram (three per 33-bin block)
constexpr int kSketchSub = 6;            // its bins summed in pairs: 2, 2, 2, 2, 2, 1
constexpr int kColourCells = 8;          // signature_of()'s colour grid, sketched 4 x 4
constexpr double kSketchLevels = 65535;  // SketchSet's quantisation

}  // namespace

Eigen::VectorXf sketch_of(const Signature& s) {
  const Eigen::Index subs = s.shape.size() / kSubBins;
  const Eigen::Index colour = s.colour.size() ? 16 : 0;
  Eigen::VectorXf out = Eigen::VectorXf::Zero(subs * kSketchSub + colour + 1);
  for (Eigen::Index h = 0; h < subs; ++h)
    for (int i = 0; i < kSubBins; ++i) out[h * kSketchSub + i / 2] += s.shape[h * kSubBins + i];
  for (int y = 0; colour && y < kColourCells; ++y)
    for (int x = 0; x < kColourCells; ++x)
      out[subs * kSketchSub + (y / 2) * 4 + x / 2] += s.colour[y * kColourCells + x];
  out[out.size() - 1] = static_cast<float>(s.spread);
  return out;
}

SketchSet sketch_set(const std::vector<Signature>& signatures) {
  SketchSet set;
  if (signatures.empty()) return set;
  const Eigen::Index bins = sketch_of(signatures[0]).size() - 1;
  set.bins.resize(bins, static_cast<Eigen::Index>(signatures.size()));
  set.spreads.resize(static_cast<Eigen::Index>(signatures.size()));
  for (std::size_t k = 0; k < signatures.size(); ++k) {
    const Eigen::VectorXf sketch = sketch_of(signatures[k]);
    for (Eigen::Index i = 0; i < bins; ++i)
      set.bins(i, k) = static_cast<std::uint16_t>(
          std::lround(std::clamp(sketch[i], 0.0f, 1.0f) * kSketchLevels));
    set.spreads[k] = sketch[bins];
  }
  return set;
}

namespace {

// L1 distance from x to the values that quantised bins stand for: each bin q holds a value
// within half a step of q / kSketchLevels.
double to_quantised(const float* x, const std::uint16_t* q, Eigen::Index n) {
  constexpr double kStep = 1.0 / kSketchLevels;
  double d = 0;
  for (Eigen::Index i = 0; i < n; ++i)
    d += std::max(0.0, std::abs(x[i] - q[i] * kStep) - kStep / 2);
  return d;
}

}  // namespace

double sketch_distance(const Eigen::VectorXf& a, const SketchSet& set, Eigen::Index k,
                       Eigen::Index shape_bins, bool a_coloured, bool set_coloured) {
  // Mirrors signature_distance() term by term.
  const Eigen::Index shape = shape_bins / kSubBins * kSketchSub;
  const std::uint16_t* q = set.bins.col(k).data();
  double d = 0;
  if (shape > 0) d += to_quantised(a.data(), q, shape) / 2.0 / (shape_bins / kFpfhBins);
  if (a_coloured && set_coloured) d += to_quantised(a.data() + shape, q + shape, 16) / 2.0;
  const double sa = a[a.size() - 1], sb = set.spreads[k];
  if (sa > 0 && sb > 0) d += std::abs(std::log(sa / sb));
  return d;
}

}  // namespace proxseg
