// Alignment scores [paper 3.4, eq. 4-5]: of a pose (candidate <- model), the share of the
// candidate the view explains (fitness), the share of the visible view the candidate explains
// (coverage, with the candidate's silhouette for occlusions), and all of them at once as
// align() reports them (score_pose()).
#include <proxseg/recognition/registration.hpp>
#include <proxseg/recognition/visibility.hpp>

#include "coverage_bound.hpp"
#include "search_index.hpp"
#include "transformation_estimation.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

namespace proxseg {

using detail::any_within;
using detail::apply;
using detail::nearest;

double fitness(const Cloud& candidate, const Cloud& view, const Eigen::Matrix4d& pose, double delta,
               double* rmse) {
  const Eigen::Matrix4d inv = pose.inverse();
  int n = 0;
  double sum = 0;
  for (const auto& c : candidate.points) {
    double d2 = 0;
    if (!rmse) {
      n += any_within(view.index->points, apply(inv, c), delta);
    } else if (nearest(view.index->points, apply(inv, c), delta, d2) >= 0 && d2 <= delta * delta) {
      ++n;
      sum += d2;
    }
  }
  if (rmse) *rmse = n ? std::sqrt(sum / n) : 0;
  return candidate.size() ? double(n) / candidate.size() : 0;
}

std::vector<char> explained(const std::vector<Eigen::Vector3d>& points, const Cloud& view,
                            const Eigen::Matrix4d& pose, double delta) {
  const Eigen::Matrix4d inv = pose.inverse();
  std::vector<char> out(points.size(), 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    out[i] = any_within(view.index->points, apply(inv, points[i]), delta);
  }
  return out;
}

// The view's points that the candidate's sensor would see: a z-buffer over viewing directions
// with cells about three point spacings wide at the object's range, keeping in each cell the
// points within a few spacings of the nearest one. Directions are taken on the plane tangent to
// the unit sphere at the object's direction (a gnomonic projection, within 1 % of the angles
// over an object's few degrees): no trigonometry, and a dense buffer over the object's cells.
// Without `silhouette`, every visible point counts as inside. With `scene`, outside points that it
// hides are counted apart (scene_hides()).
namespace {

// Whether the frame hides a point (sensor frame, metres): the sensor measured a surface more than
// tolerance + 0.005 z^2 nearer there, so that the point's absence from the candidate says
// nothing. Off the image or without a return there: not hidden (a missing return hides thin
// and dark objects' surroundings too, and made pieces of clutter fit thin models).
bool scene_hides(const DepthImage& scene, const Eigen::Vector3d& q, double tolerance) {
  if (!(q.z() > 0)) return false;
  const long u = std::lround(scene.fx * q.x() / q.z() + scene.cx);
  const long v = std::lround(scene.fy * q.y() / q.z() + scene.cy);
  if (u < 0 || v < 0 || u >= scene.width || v >= scene.height) return false;
  const float measured = scene.z[static_cast<std::size_t>(v) * scene.width + u];
  return std::isfinite(measured) && measured < q.z() - tolerance - 0.005 * q.z() * q.z();
}

// The counted view points q[counted[k]] (relative to the candidate's viewpoint) within delta of the
// candidate, into out.explained; with `hopeless`, as count_coverage() says below.
void count_explained(const Cloud& candidate, const std::vector<Eigen::Vector3d>& q,
                     const std::vector<int>& counted, double delta, double weight,
                     const std::function<bool(double)>* hopeless, CoverageCounts& out) {
  constexpr std::size_t kCheckEvery = 16;
  for (std::size_t k = 0; k < counted.size(); ++k) {
    if (hopeless && k % kCheckEvery == 0 && weight > 0 &&
        (*hopeless)(std::min(1.0, (out.explained + double(counted.size() - k)) / weight))) {
      out.explained += static_cast<int>(counted.size() - k);
      return;
    }
    out.explained +=
        any_within(candidate.index->points, q[counted[k]] + candidate.viewpoint, delta);
  }
}

// With `hopeless`, the count of explained points stops as soon as hopeless() holds for the
// coverage they would give if every point still to check were explained (an upper bound of it:
// counted is known before the nearest-point queries, the dear part); explained then holds
// that bound's count.
CoverageCounts count_coverage(const Cloud& candidate, const Cloud& view,
                              const Eigen::Matrix4d& pose, double delta, bool silhouette,
                              const DepthImage* scene = nullptr, double tolerance = 0,
                              double outside_weight = 1,
                              const std::function<bool(double)>* hopeless = nullptr) {
  CoverageCounts out;
  const Eigen::Vector3d axis = apply(pose, view.centroid) - candidate.viewpoint;
  const double range = axis.norm();
  const double spacing = std::max(view.spacing, candidate.spacing);
  if (view.size() == 0 || !(range > 0) || !(spacing > 0)) return out;
  const Eigen::Vector3d d = axis / range;
  const Eigen::Vector3d e1 = d.unitOrthogonal(), e2 = d.cross(e1);
  std::vector<Eigen::Vector3d> q(view.size());
  std::vector<Eigen::Vector2d> dir(view.size());
  std::vector<double> depth(view.size());
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector2d hi = -lo;
  for (std::size_t j = 0; j < view.size(); ++j) {
    q[j] = apply(pose, view.points[j]) - candidate.viewpoint;
    depth[j] = q[j].norm();
    const double ahead = q[j].dot(d);
    // Points 60 degrees or more off the object's direction (only under absurd poses) are not
    // seen: the projection grows without bound there.
    if (!(ahead > 0.5 * depth[j])) {
      depth[j] = -1;
      continue;
    }
    dir[j] = Eigen::Vector2d(q[j].dot(e1), q[j].dot(e2)) / ahead;
    lo = lo.cwiseMin(dir[j]);
    hi = hi.cwiseMax(dir[j]);
  }
  if (!(lo.x() <= hi.x())) return out;
  // Cells three spacings wide, coarser when a degenerate spacing would need over 1M cells.
  double cell = 3 * spacing / range;
  while (((hi - lo) / cell).array().floor().prod() > 1e6) cell *= 2;
  const Eigen::Vector2i dims = ((hi - lo) / cell).array().floor().cast<int>() + 1;
  std::vector<double> zbuf(static_cast<std::size_t>(dims.x()) * dims.y(),
                           std::numeric_limits<double>::infinity());
  std::vector<std::size_t> key(view.size(), 0);
  for (std::size_t j = 0; j < view.size(); ++j) {
    if (depth[j] < 0) continue;
    const Eigen::Vector2i c =
        ((dir[j] - lo) / cell).array().floor().cast<int>().min(dims.array() - 1).matrix();
    key[j] = static_cast<std::size_t>(c.y()) * dims.x() + c.x();
    zbuf[key[j]] = std::min(zbuf[key[j]], depth[j]);
  }
  // The candidate's silhouette on the same cells: where the sensor saw the candidate. A view
  // point outside it is one the sensor should have seen and did not: the model is wrong there,
  // or something (an occlusion) hid that part of the object.
  std::vector<char> seen(zbuf.size(), silhouette ? 0 : 1);
  for (std::size_t i = 0; silhouette && i < candidate.size(); ++i) {
    const Eigen::Vector3d c = candidate.points[i] - candidate.viewpoint;
    const double ahead = c.dot(d);
    if (!(ahead > 0.5 * c.norm())) continue;
    const Eigen::Vector2d x = (Eigen::Vector2d(c.dot(e1), c.dot(e2)) / ahead - lo) / cell;
    const int cx = static_cast<int>(std::floor(x.x())), cy = static_cast<int>(std::floor(x.y()));
    if (cx < 0 || cy < 0 || cx >= dims.x() || cy >= dims.y()) continue;
    seen[static_cast<std::size_t>(cy) * dims.x() + cx] = 1;
  }
  std::vector<int> counted;  // the visible points that count, in view order
  for (std::size_t j = 0; j < view.size(); ++j) {
    if (depth[j] < 0 || depth[j] > zbuf[key[j]] + 2 * spacing) continue;
    if (!seen[key[j]] && scene && scene_hides(*scene, q[j] + candidate.viewpoint, tolerance)) {
      ++out.hidden;
      continue;
    }
    ++(seen[key[j]] ? out.inside : out.outside);
    counted.push_back(static_cast<int>(j));
  }
  count_explained(candidate, q, counted, delta, out.inside + outside_weight * out.outside, hopeless,
                  out);
  return out;
}
}  // namespace

CoverageCounts coverage_counts(const Cloud& candidate, const Cloud& view,
                               const Eigen::Matrix4d& pose, double delta) {
  return count_coverage(candidate, view, pose, delta, true);
}

CoverageCounts coverage_counts(const Cloud& candidate, const Cloud& view,
                               const Eigen::Matrix4d& pose, double delta, const DepthImage& scene,
                               double tolerance) {
  return count_coverage(candidate, view, pose, delta, true, scene.empty() ? nullptr : &scene,
                        tolerance);
}

double coverage(const Cloud& candidate, const Cloud& view, const Eigen::Matrix4d& pose,
                double delta, double outside_weight) {
  return detail::coverage_unless(candidate, view, pose, delta, outside_weight, {});
}

double detail::coverage_unless(const Cloud& candidate, const Cloud& view,
                               const Eigen::Matrix4d& pose, double delta, double outside_weight,
                               const std::function<bool(double)>& hopeless) {
  const CoverageCounts c = count_coverage(candidate, view, pose, delta, outside_weight < 1, nullptr,
                                          0, outside_weight, hopeless ? &hopeless : nullptr);
  const double counted = c.inside + outside_weight * c.outside;
  return counted > 0 ? std::min(1.0, c.explained / counted) : 0;
}

std::vector<int> nearest_view_points(const Cloud& candidate, const Cloud& view,
                                     const Eigen::Matrix4d& pose, double delta) {
  const Eigen::Matrix4d inv = pose.inverse();
  std::vector<int> out(candidate.size(), -1);
  for (std::size_t i = 0; i < candidate.size(); ++i) {
    double d2 = 0;
    const int j = nearest(view.index->points, apply(inv, candidate.points[i]), delta, d2);
    if (j >= 0 && d2 <= delta * delta) out[i] = j;
  }
  return out;
}

Alignment score_pose(const Cloud& candidate, const Cloud& view, const Eigen::Matrix4d& pose,
                     const RegistrationParams& params) {
  // fitness(), close fitness and colour_agreement() in one pass: the nearest view point within
  // the larger distance is also the nearest within the smaller one when it lies inside it.
  Alignment a;
  a.pose = pose;
  const Eigen::Matrix4d inv = pose.inverse();
  const double fd2 = params.fitness_distance * params.fitness_distance;
  const double sd2 = params.score_distance * params.score_distance;
  const double reach = std::max(params.fitness_distance, params.score_distance);
  a.coloured = !candidate.colours.empty() && !view.colours.empty();
  int within_fitness = 0, within_score = 0;
  double sum_d2 = 0, sum_colour = 0;
  std::vector<Rgb> explained_colours;
  for (std::size_t i = 0; i < candidate.size(); ++i) {
    double d2 = 0;
    const int j = nearest(view.index->points, apply(inv, candidate.points[i]), reach, d2);
    if (j < 0) continue;
    if (d2 <= fd2) {
      ++within_fitness;
      sum_d2 += d2;
    }
    if (d2 <= sd2) {
      ++within_score;
      if (a.coloured) {
        sum_colour +=
            point_colour_agreement(candidate.colours[i], view.colours[j], params.brightness_sigma);
        explained_colours.push_back(candidate.colours[i]);
      }
    }
  }
  const double n = static_cast<double>(candidate.size());
  a.fitness = n > 0 ? within_fitness / n : 0;
  a.rmse = within_fitness ? std::sqrt(sum_d2 / within_fitness) : 0;
  a.close_fitness = n > 0 ? within_score / n : 0;
  a.colour = !a.coloured ? 1 : within_score ? sum_colour / within_score : 0;
  if (a.coloured && params.colour_compare != ColourCompare::kPoints) {
    // The view's side: its points that the candidate explains, within reach of a candidate point.
    std::vector<Rgb> shown;
    for (std::size_t j = 0; j < view.size(); ++j) {
      if (any_within(candidate.index->points, apply(pose, view.points[j]), params.score_distance))
        shown.push_back(view.colours[j]);
    }
    const double h = chromaticity_histogram_agreement(explained_colours, shown);
    a.colour = params.colour_compare == ColourCompare::kHistogram ? h : std::max(a.colour, h);
  }
  const double w = params.coverage_outside_weight;
  const CoverageCounts c = count_coverage(candidate, view, pose, params.score_distance, w < 1);
  const double visible = c.inside + c.outside;
  a.coverage = visible > 0 ? c.explained / visible : 0;
  const double counted = c.inside + w * c.outside;
  a.occluded_coverage = counted > 0 ? std::min(1.0, c.explained / counted) : 0;
  return a;
}

}  // namespace proxseg
