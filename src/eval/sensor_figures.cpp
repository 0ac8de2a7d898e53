// A depth sensor's figures measured on real frames with ground truth (sensor_figures.hpp).
#include <proxseg/eval/sensor_figures.hpp>

#include "util/nearest_points.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace proxseg {
namespace {

constexpr int kPatch = 14;        // pixels per side of a planar patch
constexpr double kBin = 0.1;      // metres of range per bin
constexpr int kBorderPixels = 3;  // a labelled pixel this close to another label is a border

// Median axial RMS of the planar patches of each range bin (patch counts in `count`).
void measure_patches(const Frame& f, std::vector<int>& count, std::vector<double>& rms) {
  std::vector<std::vector<double>> bins;
  for (int v0 = 0; v0 + kPatch <= f.height; v0 += kPatch)
    for (int u0 = 0; u0 + kPatch <= f.width; u0 += kPatch) {
      std::vector<Eigen::Vector3d> p;
      for (int v = v0; v < v0 + kPatch; ++v)
        for (int u = u0; u < u0 + kPatch; ++u) {
          const std::size_t i = static_cast<std::size_t>(v) * f.width + u;
          if (f.valid(i)) p.push_back(f.xyz[i].cast<double>());
        }
      if (p.size() < kPatch * kPatch * 3 / 4) continue;
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (const auto& q : p) c += q;
      c /= static_cast<double>(p.size());
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (const auto& q : p) cov += (q - c) * (q - c).transpose();
      cov /= static_cast<double>(p.size());
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
      const double facing = std::abs(es.eigenvectors().col(0).dot(c.normalized()));
      // Planar (the smallest spread 5 % of the next) and facing the sensor within 45 degrees.
      if (facing < 0.7 || es.eigenvalues()(0) > 0.05 * es.eigenvalues()(1)) continue;
      const std::size_t bin = static_cast<std::size_t>(c.norm() / kBin);
      if (bin >= bins.size()) bins.resize(bin + 1);
      bins[bin].push_back(std::sqrt(es.eigenvalues()(0)) / facing);
    }
  count.assign(bins.size(), 0);
  rms.assign(bins.size(), 0);
  for (std::size_t b = 0; b < bins.size(); ++b) {
    if (bins[b].empty()) continue;
    std::nth_element(bins[b].begin(), bins[b].begin() + bins[b].size() / 2, bins[b].end());
    count[b] = static_cast<int>(bins[b].size());
    rms[b] = bins[b][bins[b].size() / 2];
  }
}

SensorFigures::ObjectResidual residual(const Frame& f, const ObjectTruth& o,
                                       const std::vector<Eigen::Vector3d>& model) {
  SensorFigures::ObjectResidual r;
  r.object = o.name;
  std::vector<Eigen::Vector3d> placed;
  for (const auto& p : model) placed.push_back((o.pose * p.homogeneous()).head<3>());
  const detail::NearestPoints tree(placed);
  std::vector<double> d, range;
  for (int i : o.points) {
    const Eigen::Vector3d q = f.xyz[i].cast<double>();
    const auto nearest = tree.nearest(q, 1);
    if (nearest.empty()) continue;
    d.push_back(std::sqrt(nearest[0].second));
    range.push_back(q.norm());
  }
  if (d.empty()) return r;
  const auto at = [](std::vector<double>& v, double share) {
    const auto k = v.begin() + static_cast<long>(share * (v.size() - 1));
    std::nth_element(v.begin(), k, v.end());
    return *k;
  };
  r.range = at(range, 0.5);
  r.p50 = at(d, 0.5);
  r.p90 = at(d, 0.9);
  return r;
}

}  // namespace

SensorFigures& SensorFigures::operator+=(const SensorFigures& o) {
  if (o.patches.size() > patches.size()) {
    patches.resize(o.patches.size(), 0);
    patch_rms.resize(o.patches.size(), 0);
  }
  // Bins of several frames: the patch-weighted mean of their medians.
  for (std::size_t b = 0; b < o.patches.size(); ++b) {
    const int n = patches[b] + o.patches[b];
    if (n > 0) patch_rms[b] = (patch_rms[b] * patches[b] + o.patch_rms[b] * o.patches[b]) / n;
    patches[b] = n;
  }
  residuals.insert(residuals.end(), o.residuals.begin(), o.residuals.end());
  border += o.border, border_missing += o.border_missing;
  inside += o.inside, inside_missing += o.inside_missing;
  return *this;
}

SensorFigures measure_sensor(const YcbFrame& frame, const YcbModels& models) {
  SensorFigures s;
  const Frame& f = frame.frame;
  measure_patches(f, s.patches, s.patch_rms);
  for (const ObjectTruth& o : frame.objects)
    if (models.points.count(o.name))
      s.residuals.push_back(residual(f, o, models.points.at(o.name)));
  if (frame.labels.size() != f.size()) return s;
  for (int v = 0; v < f.height; ++v)
    for (int u = 0; u < f.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * f.width + u;
      if (frame.labels[i] == 0) continue;
      bool border = false;
      for (int dv = -kBorderPixels; dv <= kBorderPixels && !border; ++dv)
        for (int du = -kBorderPixels; du <= kBorderPixels && !border; ++du) {
          const int x = u + du, y = v + dv;
          border = x >= 0 && y >= 0 && x < f.width && y < f.height &&
                   frame.labels[static_cast<std::size_t>(y) * f.width + x] != frame.labels[i];
        }
      (border ? s.border : s.inside) += 1;
      (border ? s.border_missing : s.inside_missing) += !f.valid(i);
    }
  return s;
}

}  // namespace proxseg
