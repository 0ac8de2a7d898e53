// Per-voxel features [paper 3.1]: colour (HSV histograms), shape (normalised eigenvalues,
// curvature, normal-angle histogram), and the feature matrix with the texture block of the Gabor
// bank (gabor.cpp) and the normals (normals.cpp).
#include <proxseg/core/colour.hpp>
#include <proxseg/core/features.hpp>

#include "feature_bins.hpp"
#include "gabor_detail.hpp"
#include "util/angles.hpp"
#include "util/moments.hpp"
#include "util/parallel_for.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

namespace proxseg {
namespace {

using detail::bin_of;
using detail::gabor_filters;
using detail::kPi;
using detail::normalise;
using detail::ResponseGrid;
using detail::TextureEdges;

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

// The texture block [paper 3.1]: each filter's 10 bins of every row (row = voxels[row]), made by
// the task that computed the filter from its magnitude image (no bank of 24 full images is
// kept). A histogram sums to its point count exactly (integer counts), so normalise() divides
// each count by that count. `side` runs as one more task among the filters.
std::vector<std::vector<float>> texture_blocks_of(const Frame& frame, const VoxelGrid& grid,
                                                  const std::vector<int>& voxels,
                                                  const FeatureParams& params, int threads,
                                                  const std::function<void()>& side) {
  std::vector<std::vector<float>> texture_blocks(kGaborScales * kGaborOrientations);
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
          for (int u = cx * response.stride; u < std::min(frame.width, (cx + 1) * response.stride);
               ++u) {
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
      build_cells, side);
  return texture_blocks;
}

}  // namespace

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
  // Texture: the filters' histograms, with the normals computed beside them.
  std::vector<std::vector<float>> texture_blocks;
  if (texture)
    texture_blocks = texture_blocks_of(frame, grid, voxels, params, threads, compute_normals);
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
