// Descriptors [paper 3.4]: the voxel filter, normals and multi-radius FPFH of a cloud (a model
// view or a candidate), the described cloud restored from the database, and its subsample for
// registration.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>
#include <proxseg/core/stop.hpp>
#include <proxseg/recognition/registration.hpp>

#include "fpfh.hpp"
#include "search_index.hpp"
#include "signatures.hpp"

#include "util/nearest_points.hpp"
#include "util/pca_normal.hpp"

#include <algorithm>
#include <cmath>

namespace proxseg {

using detail::build_index;
using detail::fpfh_features;
using detail::make_signature;

namespace {

double median_spacing(const Cloud& c) {
  std::vector<double> d;
  d.reserve(c.size());
  const detail::NearestPoints index(c.points);
  for (const auto& p : c.points) {
    const auto two = index.nearest(p, 2);  // the point itself (or a twin) and its nearest
    if (two.size() == 2) d.push_back(std::sqrt(two[1].second));
  }
  if (d.empty()) return 0;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

// The normals of the points from their max_nn nearest within the radius (pca_normal()), as
// Open3D's EstimateNormals with a hybrid search gives them: with fewer than 3 neighbours, the
// identity's first eigenvector.
std::vector<Eigen::Vector3d> estimate_normals(const std::vector<Eigen::Vector3d>& points,
                                              double radius, int max_nn) {
  const detail::NearestPoints index(points);
  std::vector<Eigen::Vector3d> normals(points.size());
#pragma omp parallel for schedule(static)
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const auto neighbours = index.nearest(points[i], max_nn, radius);
    normals[i] =
        neighbours.size() >= 3 ? detail::pca_normal(points, neighbours) : Eigen::Vector3d::UnitX();
  }
  return normals;
}

// x rounded to float precision: the precision of a cloud in a PCD file or in the database. The
// float is stored and read back through a volatile: GCC 12's vectoriser (at -O2 and -O3) folds
// the truncation and extension of two adjacent coordinates away, which left x and y of every
// point and normal unrounded while z was rounded.
double to_float_precision(double x) {
  volatile float f = static_cast<float>(x);
  return f;
}

Eigen::Vector3d round_to_float(const Eigen::Vector3d& v) {
  return {to_float_precision(v.x()), to_float_precision(v.y()), to_float_precision(v.z())};
}

Eigen::Vector3d mean(const std::vector<Eigen::Vector3d>& p) {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (const auto& x : p) s += x;
  return p.empty() ? s : Eigen::Vector3d(s / double(p.size()));
}

}  // namespace

std::vector<Eigen::Vector3d> voxel_filter(const std::vector<Eigen::Vector3d>& points,
                                          double voxel_size, const std::vector<Rgb>* colours,
                                          std::vector<Rgb>* out_colours) {
  if (!(voxel_size > 0)) throw InputError("voxel_size: expected > 0");
  struct Entry {
    Eigen::Vector3i key;
    int index;
  };
  std::vector<Entry> e;
  e.reserve(points.size());
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const auto& p = points[i];
    if (!p.allFinite()) continue;
    const Eigen::Vector3d k = (p / voxel_size).array().floor();
    if (!(k.cwiseAbs().maxCoeff() < 1e9)) continue;  // beyond any sensor; would overflow
    e.push_back({k.cast<int>(), i});
  }
  std::sort(e.begin(), e.end(), [](const Entry& a, const Entry& b) {
    return std::tie(a.key.z(), a.key.y(), a.key.x(), a.index) <
           std::tie(b.key.z(), b.key.y(), b.key.x(), b.index);
  });
  std::vector<Eigen::Vector3d> out;
  if (out_colours) out_colours->clear();
  for (std::size_t a = 0; a < e.size();) {
    std::size_t b = a;
    Eigen::Vector3d s = Eigen::Vector3d::Zero(), rgb = Eigen::Vector3d::Zero();
    for (; b < e.size() && e[b].key == e[a].key; ++b) {
      s += points[e[b].index];
      if (colours) {
        const Rgb& c = (*colours)[e[b].index];
        rgb += Eigen::Vector3d(c[0], c[1], c[2]);
      }
    }
    out.push_back(s / double(b - a));
    if (colours && out_colours) {
      rgb /= double(b - a);
      out_colours->push_back({static_cast<std::uint8_t>(std::lround(rgb.x())),
                              static_cast<std::uint8_t>(std::lround(rgb.y())),
                              static_cast<std::uint8_t>(std::lround(rgb.z()))});
    }
    a = b;
  }
  return out;
}

Cloud describe(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& viewpoint,
               const DescriptorParams& params, const std::vector<Rgb>* colours) {
  if (colours && colours->size() != points.size())
    throw InputError("describe: expected one colour per point");
  std::vector<Rgb> filtered_colours;
  auto filtered = voxel_filter(points, params.voxel_size, colours, &filtered_colours);
  return describe_filtered(filtered, viewpoint, params, std::move(filtered_colours));
}

Cloud describe_filtered(const std::vector<Eigen::Vector3d>& points,
                        const Eigen::Vector3d& viewpoint, const DescriptorParams& params,
                        std::vector<Rgb> colours) {
  if (!colours.empty() && colours.size() != points.size())
    throw InputError("describe: expected one colour per point");
  if (params.fpfh_radii.empty()) throw InputError("fpfh_radii: expected at least one radius");
  for (double r : params.fpfh_radii)
    if (!(r > 0)) throw InputError("fpfh_radii: expected radii > 0");
  if (!(params.normal_radius > 0)) throw InputError("normal_radius: expected > 0");
  std::vector<Eigen::Vector3d> kept;
  kept.reserve(points.size());
  std::vector<Rgb> kept_colours;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (points[i].allFinite()) {
      kept.push_back(round_to_float(points[i]));
      if (!colours.empty()) kept_colours.push_back(colours[i]);
    }
  if (kept.size() < 10)
    throw InputError("cloud has " + std::to_string(kept.size()) +
                     " points after the voxel filter (expected at least 10)");
  constexpr int kNormalNeighbours = 30;
  std::vector<Eigen::Vector3d> normals =
      estimate_normals(kept, params.normal_radius, kNormalNeighbours);
  stop_point();  // between the describing's dear steps (normals, FPFH), on the calling thread
  Cloud c;
  c.points = std::move(kept);
  c.colours = std::move(kept_colours);
  c.centroid = mean(c.points);
  c.viewpoint = viewpoint;
  const bool from_viewpoint = viewpoint.allFinite();
  for (std::size_t i = 0; i < c.size(); ++i) {
    Eigen::Vector3d& n = normals[i];
    const Eigen::Vector3d out = from_viewpoint ? Eigen::Vector3d(viewpoint - c.points[i])
                                               : Eigen::Vector3d(c.points[i] - c.centroid);
    if (n.dot(out) < 0) n = -n;
    n = round_to_float(n);
  }
  c.normals = std::move(normals);
  constexpr int kMaxNeighbours = 100;
  c.features =
      fpfh_features(c.points, c.normals, params.fpfh_radii, kMaxNeighbours).unaryExpr([](double x) {
        return to_float_precision(x);
      });
  stop_point();
  c.index = build_index(c);
  c.spacing = median_spacing(c);
  c.signature = make_signature(c);
  return c;
}

Cloud restore(std::vector<Eigen::Vector3d> points, std::vector<Eigen::Vector3d> normals,
              Eigen::MatrixXd features, const Eigen::Vector3d& viewpoint,
              std::vector<Rgb> colours) {
  if (!colours.empty() && colours.size() != points.size())
    throw InputError("restore: expected one colour per point");
  Cloud c;
  c.colours = std::move(colours);
  c.points = std::move(points);
  c.normals = std::move(normals);
  c.features = std::move(features);
  c.centroid = mean(c.points);
  c.viewpoint = viewpoint;
  c.index = build_index(c);
  c.spacing = median_spacing(c);
  c.signature = make_signature(c);
  return c;
}

Cloud subsample(const Cloud& cloud, int max_points) {
  if (max_points <= 0 || static_cast<int>(cloud.size()) <= max_points) return cloud;
  // Evenly spaced in voxel order: spread over the whole cloud, and deterministic.
  const int n = max_points;
  Cloud s;
  s.features.resize(cloud.features.rows(), n);
  for (int k = 0; k < n; ++k) {
    const std::size_t i = static_cast<std::size_t>(k) * cloud.size() / n;
    s.points.push_back(cloud.points[i]);
    s.normals.push_back(cloud.normals[i]);
    if (!cloud.colours.empty()) s.colours.push_back(cloud.colours[i]);
    s.features.col(k) = cloud.features.col(i);
  }
  s.centroid = mean(s.points);
  s.viewpoint = cloud.viewpoint;
  s.index = build_index(s);
  s.spacing = cloud.spacing;  // the surface sampling the descriptors were computed at
  s.signature = cloud.signature;
  return s;
}

}  // namespace proxseg
