// RANSAC [paper 3.4, Algorithm 2]: feature correspondences between a candidate and a view,
// two-point samples pre-rejected by their point-pair feature (the correspondence check), and the
// best distinct hypotheses refitted and judged by their overlap (ransac.hpp).
#include <proxseg/core/stop.hpp>
#include <proxseg/recognition/registration.hpp>

#include "colour_scores.hpp"
#include "coverage_bound.hpp"
#include "ransac.hpp"
#include "search_index.hpp"
#include "transformation_estimation.hpp"
#include "util/angles.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>

namespace proxseg::detail {

// Feature correspondences (candidate point, view point): each candidate point's nearest view
// feature, optionally kept only when the view point's nearest candidate feature is it. The
// distances are found a block of view points at a time: the whole matrix (a few hundred
// candidate points by thousands of view points) would be allocated, zeroed and paged in anew for
// every view, and would not stay in the cache.
std::vector<std::pair<int, int>> correspondences(const Cloud& cand, const Cloud& view, int block,
                                                 bool mutual) {
  constexpr Eigen::Index kColumns = 256;  // view points per block: 300 x 256 floats, in L2
  const std::size_t k = block < 0 ? 0 : 1 + block;
  const Eigen::MatrixXf& fc = cand.index->features[k];
  const Eigen::MatrixXf& fv = view.index->features[k];
  const Eigen::Index rows = fc.cols(), cols = fv.cols();
  if (rows == 0 || cols == 0) return {};
  std::vector<float> nearest_d(rows, std::numeric_limits<float>::infinity());
  std::vector<int> nearest(rows, 0), back(mutual ? cols : 0);
  Eigen::MatrixXf d(rows, std::min(kColumns, cols));
  for (Eigen::Index j0 = 0; j0 < cols; j0 += kColumns) {
    const Eigen::Index w = std::min(kColumns, cols - j0);
    auto dj = d.leftCols(w);
    // d2(i, j) = |c_i|^2 + |v_j|^2 - 2 c_i.v_j; |c_i|^2 does not change the argmin over j.
    dj.noalias() = fc.transpose() * fv.middleCols(j0, w);
    dj *= -2.0f;
    dj.rowwise() += view.index->norms2[k].segment(j0, w);
    for (Eigen::Index i = 0; i < rows; ++i) {  // the first nearest, as over the whole row
      Eigen::Index j = 0;
      const float m = dj.row(i).minCoeff(&j);
      if (m < nearest_d[i]) nearest_d[i] = m, nearest[i] = static_cast<int>(j0 + j);
    }
    for (Eigen::Index j = 0; j < (mutual ? w : 0); ++j) {
      Eigen::Index i = 0;
      (dj.col(j) + cand.index->norms2[k].transpose()).minCoeff(&i);
      back[j0 + j] = static_cast<int>(i);
    }
  }
  std::vector<std::pair<int, int>> out;
  for (Eigen::Index i = 0; i < rows; ++i) {
    if (mutual && back[nearest[i]] != i) continue;
    out.emplace_back(static_cast<int>(i), nearest[i]);
  }
  return out;
}

namespace {

// Two poses within 0.1 rad and `distance` of each other. The angle of the relative rotation R
// is compared through its trace (1 + 2 cos angle), without the trigonometry of an angle-axis:
// RANSAC asks this of every hypothesis against each one it keeps.
bool similar(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b, double distance) {
  constexpr double kMinTrace = 2.9900083305560516;  // 1 + 2 cos(0.1)
  if ((a.topRightCorner<3, 1>() - b.topRightCorner<3, 1>()).squaredNorm() >= distance * distance)
    return false;
  const double trace = (a.topLeftCorner<3, 3>().array() * b.topLeftCorner<3, 3>().array()).sum();
  return trace > kMinTrace;
}

// Judges hypotheses like the recognition score, best first: the share of the candidate the view
// explains and the share of the visible view the candidate explains (a box turned by 90 degrees
// can explain the candidate as well as the right pose, but not be explained by it). Only the best
// icp_starts go on to ICP, and sqrt(fitness) bounds the overlap (times a colour agreement of at
// most 1), so coverage and the colour agreement (the dearer parts) are computed in order of
// fitness only while a hypothesis can still enter them; the others keep overlap -1 and sort
// last, in their order.
void judge(std::vector<Hypothesis>& top, const Cloud& cand, const Cloud& view,
           const RegistrationParams& p) {
  std::vector<double> fit(top.size());
  const bool coloured = p.colour_alignment && !cand.colours.empty() && !view.colours.empty();
  for (std::size_t k = 0; k < top.size(); ++k) {
    top[k].overlap = -1;
    fit[k] = fitness(cand, view, top[k].pose, p.ransac_distance);
  }
  std::vector<std::size_t> order(top.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t x, std::size_t y) { return fit[x] > fit[y]; });
  const std::size_t kept = std::max(1, p.icp_starts);
  std::vector<double> best;  // the largest overlaps so far, descending, at most `kept`
  for (std::size_t k : order) {
    if (best.size() == kept && std::sqrt(fit[k]) < best.back()) break;
    // The colour agreement (at most 1) only for the hypotheses judged: the same bound holds.
    double agree = 1;
    if (coloured)
      explained_colour(cand, view, top[k].pose, p.ransac_distance, p.brightness_sigma, agree);
    // Once `kept` are judged, one that cannot beat the last of them need not be counted out.
    const auto overlap = [&](double cov) { return symmetric_overlap(fit[k], cov) * agree; };
    std::function<bool(double)> hopeless;
    if (best.size() == kept) hopeless = [&](double cov) { return overlap(cov) < best.back(); };
    top[k].overlap =
        overlap(coverage_unless(cand, view, top[k].pose, p.ransac_distance, 1, hopeless));
    best.insert(std::upper_bound(best.begin(), best.end(), top[k].overlap, std::greater<>()),
                top[k].overlap);
    if (best.size() > kept) best.pop_back();
  }
  std::stable_sort(top.begin(), top.end(),
                   [](const Hypothesis& x, const Hypothesis& y) { return x.overlap > y.overlap; });
}

using Correspondences = std::vector<std::pair<int, int>>;

// The correspondences' points side by side, coordinate by coordinate: RANSAC counts the inliers
// of every hypothesis over all of them, and this layout lets that loop vectorise.
struct CorrespondencePoints {
  std::vector<double> vx, vy, vz;  // view points
  std::vector<double> cx, cy, cz;  // candidate points

  CorrespondencePoints(const Cloud& cand, const Cloud& view,
                       const std::vector<std::pair<int, int>>& c) {
    for (auto* v : {&vx, &vy, &vz, &cx, &cy, &cz}) v->reserve(c.size());
    for (const auto& [i, j] : c) {
      vx.push_back(view.points[j].x()), vy.push_back(view.points[j].y());
      vz.push_back(view.points[j].z());
      cx.push_back(cand.points[i].x()), cy.push_back(cand.points[i].y());
      cz.push_back(cand.points[i].z());
    }
  }
};

// The number of correspondences that pose t (candidate <- model) brings within sqrt(r2) of each
// other. The arithmetic is apply()'s and squaredNorm()'s, term by term in their order.
int count_inliers(const CorrespondencePoints& c, const Eigen::Matrix4d& t, double r2) {
  const double r00 = t(0, 0), r01 = t(0, 1), r02 = t(0, 2), tx = t(0, 3);
  const double r10 = t(1, 0), r11 = t(1, 1), r12 = t(1, 2), ty = t(1, 3);
  const double r20 = t(2, 0), r21 = t(2, 1), r22 = t(2, 2), tz = t(2, 3);
  const std::size_t m = c.vx.size();
  int n = 0;
  for (std::size_t k = 0; k < m; ++k) {
    const double dx = r00 * c.vx[k] + r01 * c.vy[k] + r02 * c.vz[k] + tx - c.cx[k];
    const double dy = r10 * c.vx[k] + r11 * c.vy[k] + r12 * c.vz[k] + ty - c.cy[k];
    const double dz = r20 * c.vx[k] + r21 * c.vy[k] + r22 * c.vz[k] + tz - c.cz[k];
    n += dx * dx + dy * dy + dz * dz < r2;
  }
  return n;
}

// The inliers of pose t: their view points to a, their candidate points to b.
void collect_inliers(const Cloud& cand, const Cloud& view, const Correspondences& c,
                     const Eigen::Matrix4d& t, double r2, std::vector<Eigen::Vector3d>& a,
                     std::vector<Eigen::Vector3d>& b) {
  for (const auto& [i, j] : c) {
    const Eigen::Vector3d q = apply(t, view.points[j]);
    if ((q - cand.points[i]).squaredNorm() >= r2) continue;
    a.push_back(view.points[j]);
    b.push_back(cand.points[i]);
  }
}

// Keeps h among the best ransac_candidates hypotheses (top: best first, pairwise distinct): it
// replaces a similar one with fewer inliers, and is dropped for a similar one with as many.
void keep(std::vector<Hypothesis>& top, const Hypothesis& h, const RegistrationParams& p) {
  const std::size_t k = std::max(1, p.ransac_candidates);
  if (top.size() == k && h.inliers <= top.back().inliers) return;
  for (std::size_t i = 0; i < top.size(); ++i)
    if (similar(top[i].pose, h.pose, p.ransac_distance)) {
      if (h.inliers > top[i].inliers) {
        top.erase(top.begin() + i);
        break;
      }
      return;
    }
  top.insert(std::upper_bound(
                 top.begin(), top.end(), h,
                 [](const Hypothesis& x, const Hypothesis& y) { return x.inliers > y.inliers; }),
             h);
  if (top.size() > k) top.pop_back();
}

// The frame of a point pair: x along the edge p0 -> p1, y the part of p0's normal across it.
Eigen::Matrix3d pair_frame(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                           const Eigen::Vector3d& n0) {
  const Eigen::Vector3d x = (p1 - p0).normalized();
  const Eigen::Vector3d y = (n0 - n0.dot(x) * x).normalized();
  Eigen::Matrix3d f;
  f << x, y, x.cross(y);
  return f;
}

// Whether two angles given by their cosines differ by at most the angle of cosine cos_tol.
bool angle_alike(double a, double b, double cos_tol) {
  // cos of the difference of two angles given by their cosines, without acos
  const double sa = std::sqrt(std::max(0.0, 1 - a * a)), sb = std::sqrt(std::max(0.0, 1 - b * b));
  return a * b + sa * sb >= cos_tol;
}

// The correspondence check of a sample of two correspondences with their normals: a point pair
// fixes a rotation, so the chance of drawing only right pairs is w^2 instead of w^3 for an inlier
// share w. It must look alike in both clouds (edge length, angle between the normals, angles of
// the normals with the edge: the point-pair feature) before it is scored.
bool alike_in_both(const Cloud& cand, const Cloud& view, const std::pair<int, int>& s0,
                   const std::pair<int, int>& s1, const RegistrationParams& p, double min_edge,
                   double cos_tol) {
  const auto& [i0, j0] = s0;
  const auto& [i1, j1] = s1;
  const Eigen::Vector3d dc = cand.points[i1] - cand.points[i0];
  const Eigen::Vector3d dv = view.points[j1] - view.points[j0];
  const double lc2 = dc.squaredNorm(), lv2 = dv.squaredNorm();
  // Most samples fail on their edge lengths: rejected first on the squared lengths, without a
  // square root, by a margin (1e-9) far above rounding, so that the test below decides the rest.
  constexpr double kMargin = 1 - 1e-9;
  const double shortest2 = min_edge * min_edge * kMargin;
  if (lc2 < shortest2 || lv2 < shortest2 ||
      std::min(lc2, lv2) < p.edge_similarity * p.edge_similarity * kMargin * std::max(lc2, lv2))
    return false;
  const double lc = std::sqrt(lc2), lv = std::sqrt(lv2);
  if (!(lc > min_edge && lv > min_edge && std::min(lc, lv) >= p.edge_similarity * std::max(lc, lv)))
    return false;
  const Eigen::Vector3d &nc0 = cand.normals[i0], &nc1 = cand.normals[i1];
  const Eigen::Vector3d &nv0 = view.normals[j0], &nv1 = view.normals[j1];
  if (!angle_alike(nc0.dot(nc1), nv0.dot(nv1), cos_tol) ||
      !angle_alike(nc0.dot(dc) / lc, nv0.dot(dv) / lv, cos_tol) ||
      !angle_alike(nc1.dot(dc) / lc, nv1.dot(dv) / lv, cos_tol))
    return false;
  return !(std::abs(nc0.dot(dc) / lc) > 0.99);  // normal along the edge: no frame
}

// The pose (candidate <- model) that puts the sample's view pair on its candidate pair.
Eigen::Matrix4d pair_pose(const Cloud& cand, const Cloud& view, const std::pair<int, int>& s0,
                          const std::pair<int, int>& s1) {
  const auto& [i0, j0] = s0;
  const auto& [i1, j1] = s1;
  Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
  const Eigen::Matrix3d r =
      pair_frame(cand.points[i0], cand.points[i1], cand.normals[i0]) *
      pair_frame(view.points[j0], view.points[j1], view.normals[j0]).transpose();
  t.topLeftCorner<3, 3>() = r;
  t.topRightCorner<3, 1>() =
      (cand.points[i0] + cand.points[i1]) / 2 - r * (view.points[j0] + view.points[j1]) / 2;
  return t;
}

}  // namespace

// RANSAC over feature correspondences. A sample of two pairs with their normals is pre-rejected
// unless it looks alike in both clouds (its point-pair feature, alike_in_both(); as PCL's
// prerejective alignment does with the edge lengths of three). Hypotheses are ranked by the
// correspondences they explain, which needs no nearest-neighbour search; the few best distinct
// ones are refitted on their inliers and judged by their true overlap with the view, because on
// boxes and cans many wrong poses explain as many feature pairs as the right one.
std::vector<Hypothesis> ransac(const Cloud& cand, const Cloud& view,
                               const std::vector<std::pair<int, int>>& c,
                               const RegistrationParams& p, std::mt19937_64& rng) {
  std::vector<Hypothesis> top;  // best first, pairwise distinct
  if (c.size() < 3) return {};
  std::uniform_int_distribution<std::size_t> pick(0, c.size() - 1);
  const double r2 = p.ransac_distance * p.ransac_distance;
  const double min_edge = 2 * std::max(cand.spacing, view.spacing);
  const double cos_tol = std::cos(detail::radians(p.normal_tolerance_deg));
  const CorrespondencePoints points(cand, view, c);
  int valid = 0;
  const long attempts = 50L * p.ransac_iterations;
  for (long a = 0; a < attempts && valid < p.ransac_iterations; ++a) {
    if (a % 256 == 0) stop_point();  // an alignment can take 100 ms: Ctrl-C within a few ms
    const std::size_t s0 = pick(rng), s1 = pick(rng);
    if (s0 == s1) continue;
    if (!alike_in_both(cand, view, c[s0], c[s1], p, min_edge, cos_tol)) continue;
    ++valid;
    const Eigen::Matrix4d t = pair_pose(cand, view, c[s0], c[s1]);
    const int n = count_inliers(points, t, r2);
    if (n >= 3) keep(top, {t, n, 0}, p);
  }
  for (Hypothesis& h : top) {
    std::vector<Eigen::Vector3d> a, b;
    collect_inliers(cand, view, c, h.pose, r2, a, b);
    const Eigen::Matrix4d refit = kabsch(a, b);
    if (count_inliers(points, refit, r2) >= h.inliers) h.pose = refit;
  }
  judge(top, cand, view, p);
  return top;
}

}  // namespace proxseg::detail
