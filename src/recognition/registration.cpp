// Registration [paper 3.4, Algorithm 2] and the fitness of eq. 4-5.
#include <proxseg/core/frame.hpp>
#include <proxseg/recognition/registration.hpp>

#include "util/stopwatch.hpp"

#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Feature.h>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include "util/angles.hpp"

namespace proxseg {

constexpr int kFpfhBins = 33;

// Nearest-point queries all have a small radius (ICP, fitness, overlap: about 1 cm), so a dense
// grid of 1 cm cells over the cloud's bounding box answers them by looking at a few cells; it is
// several times faster than a kd-tree here and is exact.
struct PointGrid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double cell = 0.01;
  Eigen::Vector3i dims = Eigen::Vector3i::Zero();
  std::vector<int> start;  // points of cell c: order[start[c] .. start[c + 1])
  std::vector<int> order;
  std::vector<Eigen::Vector3d> points;  // in cell order, for locality
};

// Feature matching is brute force on floats (one matrix product per pair of clouds): with 33-99
// dimensions and a few hundred points a kd-tree visits most leaves anyway, and the product
// vectorises.
struct SearchIndex {
  PointGrid points;
  std::vector<Eigen::MatrixXf> features;   // [0]: all radii; [1 + b]: radius block b
  std::vector<Eigen::RowVectorXf> norms2;  // squared norms of their columns
};

namespace {

PointGrid make_grid(const std::vector<Eigen::Vector3d>& points) {
  PointGrid g;
  if (points.empty()) return g;
  Eigen::Vector3d lo = points[0], hi = points[0];
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // Coarser cells for very large clouds keep the grid within ~4M cells.
  while (((hi - lo) / g.cell).array().floor().prod() > 4e6) g.cell *= 2;
  g.origin = lo;
  g.dims = ((hi - lo) / g.cell).array().floor().cast<int>() + 1;
  const auto cell_of = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3i c = ((p - g.origin) / g.cell).array().floor().cast<int>();
    return (static_cast<std::size_t>(c.z()) * g.dims.y() + c.y()) * g.dims.x() + c.x();
  };
  const std::size_t cells = static_cast<std::size_t>(g.dims.prod());
  g.start.assign(cells + 1, 0);
  for (const auto& p : points) ++g.start[cell_of(p) + 1];
  for (std::size_t c = 0; c < cells; ++c) g.start[c + 1] += g.start[c];
  g.order.resize(points.size());
  std::vector<int> fill(g.start.begin(), g.start.end() - 1);
  for (int i = 0; i < static_cast<int>(points.size()); ++i) g.order[fill[cell_of(points[i])]++] = i;
  for (int i : g.order) g.points.push_back(points[i]);
  return g;
}

// Nearest point of the grid to q among the cells of the box of half-width r (-1 if none in the
// ball of radius r), squared distance in d2.
int nearest_in_box(const PointGrid& g, const Eigen::Vector3d& q, double r, double& d2) {
  const Eigen::Vector3d lo = (q.array() - r - g.origin.array()) / g.cell;
  const Eigen::Vector3d hi = (q.array() + r - g.origin.array()) / g.cell;
  Eigen::Vector3i a, b;
  for (int k = 0; k < 3; ++k) {
    if (hi[k] < 0 || lo[k] >= g.dims[k]) return -1;
    a[k] = std::max(0, static_cast<int>(std::floor(lo[k])));
    b[k] = std::min(g.dims[k] - 1, static_cast<int>(std::floor(hi[k])));
  }
  double best = r * r;
  int found = -1;
  for (int z = a.z(); z <= b.z(); ++z)
    for (int y = a.y(); y <= b.y(); ++y) {
      const std::size_t row = (static_cast<std::size_t>(z) * g.dims.y() + y) * g.dims.x();
      for (int k = g.start[row + a.x()], e = g.start[row + b.x() + 1]; k < e; ++k) {
        const double d = (g.points[k] - q).squaredNorm();
        if (d <= best) {
          best = d;
          found = k;
        }
      }
    }
  if (found < 0) return -1;
  d2 = best;
  return g.order[found];
}

// Nearest point of the grid to q within r (-1 if none), squared distance in d2. Most queries
// (ICP after its first steps, fitness, coverage) have a point within half a cell, and the box
// of that radius spans ~8 cells instead of ~64 for ICP's 1.5 cm: searching it first is exact (a
// nearer point would lie in it too) and about four times cheaper.
int nearest(const PointGrid& g, const Eigen::Vector3d& q, double r, double& d2) {
  if (g.order.empty()) return -1;
  const double first = 0.5 * g.cell;
  if (r > first) {
    const int j = nearest_in_box(g, q, first, d2);
    if (j >= 0) return j;
  }
  return nearest_in_box(g, q, r, d2);
}

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

Signature make_signature(const Cloud& c) {
  return signature_of(c, nullptr);
}

}  // namespace

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

namespace {

std::shared_ptr<const SearchIndex> build_index(const Cloud& c) {
  auto index = std::make_shared<SearchIndex>();
  index->points = make_grid(c.points);
  if (c.features.cols() > 0) {
    index->features.push_back(c.features.cast<float>());
    const int blocks = static_cast<int>(c.features.rows()) / kFpfhBins;
    for (int b = 0; blocks > 1 && b < blocks; ++b)
      index->features.push_back(c.features.middleRows(b * kFpfhBins, kFpfhBins).cast<float>());
    for (const auto& f : index->features) index->norms2.push_back(f.colwise().squaredNorm());
  }
  return index;
}

double median_spacing(const Cloud& c) {
  std::vector<double> d;
  d.reserve(c.size());
  open3d::geometry::KDTreeFlann tree;
  Eigen::MatrixXd data(3, c.size());  // must outlive the tree: Open3D keeps a view of it
  for (std::size_t i = 0; i < c.size(); ++i) data.col(i) = c.points[i];
  tree.SetMatrixData(data);
  std::vector<int> idx;
  std::vector<double> dist;
  for (const auto& p : c.points)
    if (tree.SearchKNN(p, 2, idx, dist) == 2) d.push_back(std::sqrt(dist[1]));
  if (d.empty()) return 0;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

// Rounds each coordinate to float precision and back: the precision a cloud has in a PCD file or
// in the database cache.
Eigen::Vector3d round_to_float(const Eigen::Vector3d& v) {
  return {static_cast<double>(static_cast<float>(v.x())),
          static_cast<double>(static_cast<float>(v.y())),
          static_cast<double>(static_cast<float>(v.z()))};
}

Eigen::Vector3d mean(const std::vector<Eigen::Vector3d>& p) {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (const auto& x : p) s += x;
  return p.empty() ? s : Eigen::Vector3d(s / double(p.size()));
}

// Rigid transform (no scale) taking src onto dst in the least-squares sense (Kabsch/Umeyama).
Eigen::Matrix4d kabsch(const std::vector<Eigen::Vector3d>& src,
                       const std::vector<Eigen::Vector3d>& dst) {
  Eigen::Matrix3Xd a(3, src.size()), b(3, dst.size());
  for (std::size_t i = 0; i < src.size(); ++i) {
    a.col(i) = src[i];
    b.col(i) = dst[i];
  }
  return Eigen::umeyama(a, b, false);
}

Eigen::Vector3d apply(const Eigen::Matrix4d& t, const Eigen::Vector3d& p) {
  return t.topLeftCorner<3, 3>() * p + t.topRightCorner<3, 1>();
}

// Point-to-plane step (linearised, small angles): the increment that moves src towards the
// planes (dst, normal) in the least-squares sense.
Eigen::Matrix4d point_to_plane(const std::vector<Eigen::Vector3d>& src,
                               const std::vector<Eigen::Vector3d>& dst,
                               const std::vector<Eigen::Vector3d>& normal) {
  Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> atb = Eigen::Matrix<double, 6, 1>::Zero();
  for (std::size_t i = 0; i < src.size(); ++i) {
    Eigen::Matrix<double, 6, 1> row;
    row << src[i].cross(normal[i]), normal[i];
    ata += row * row.transpose();
    atb += row * (dst[i] - src[i]).dot(normal[i]);
  }
  const Eigen::Matrix<double, 6, 1> x = ata.ldlt().solve(atb);
  Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
  t.topLeftCorner<3, 3>() = (Eigen::AngleAxisd(x(2), Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(x(1), Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(x(0), Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  t.topRightCorner<3, 1>() = x.tail<3>();
  return t;
}

// Feature correspondences (candidate point, view point): each candidate point's nearest view
// feature, optionally kept only when the view point's nearest candidate feature is it.
std::vector<std::pair<int, int>> correspondences(const Cloud& cand, const Cloud& view, int block,
                                                 bool mutual) {
  const std::size_t k = block < 0 ? 0 : 1 + block;
  const Eigen::MatrixXf& fc = cand.index->features[k];
  const Eigen::MatrixXf& fv = view.index->features[k];
  // d2(i, j) = |c_i|^2 + |v_j|^2 - 2 c_i.v_j; |c_i|^2 does not change the argmin over j.
  Eigen::MatrixXf d = fc.transpose() * fv;
  d *= -2.0f;
  d.rowwise() += view.index->norms2[k];
  std::vector<std::pair<int, int>> out;
  std::vector<int> back;
  if (mutual) {
    Eigen::MatrixXf dt = d;
    dt.colwise() += cand.index->norms2[k].transpose();
    back.resize(dt.cols());
    for (Eigen::Index j = 0; j < dt.cols(); ++j) dt.col(j).minCoeff(&back[j]);
  }
  for (Eigen::Index i = 0; i < d.rows(); ++i) {
    Eigen::Index j = 0;
    d.row(i).minCoeff(&j);
    if (mutual && back[j] != i) continue;
    out.emplace_back(static_cast<int>(i), static_cast<int>(j));
  }
  return out;
}

struct Hypothesis {
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  int inliers = 0;
  // sqrt(fitness x coverage) within ransac_distance; -1 when not judged (judge())
  double overlap = 0;
};

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

// fitness() within delta, and in `colour` the mean chromaticity agreement of the explained
// candidate points with the view points that explain them.
double explained_colour(const Cloud& cand, const Cloud& view, const Eigen::Matrix4d& pose,
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
    top[k].overlap =
        symmetric_overlap(fit[k], coverage(cand, view, top[k].pose, p.ransac_distance)) * agree;
    best.insert(std::upper_bound(best.begin(), best.end(), top[k].overlap, std::greater<>()),
                top[k].overlap);
    if (best.size() > kept) best.pop_back();
  }
  std::stable_sort(top.begin(), top.end(),
                   [](const Hypothesis& x, const Hypothesis& y) { return x.overlap > y.overlap; });
}

// RANSAC over feature correspondences. A sample of two pairs with their normals is pre-rejected
// unless it looks alike in both clouds (its point-pair feature; as PCL's prerejective alignment
// does with the edge lengths of three). Hypotheses are ranked by the
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
  const auto inliers = [&](const Eigen::Matrix4d& t, std::vector<Eigen::Vector3d>* a,
                           std::vector<Eigen::Vector3d>* b) {
    int n = 0;
    for (const auto& [i, j] : c) {
      const Eigen::Vector3d q = apply(t, view.points[j]);
      if ((q - cand.points[i]).squaredNorm() >= r2) continue;
      ++n;
      if (a) {
        a->push_back(view.points[j]);
        b->push_back(cand.points[i]);
      }
    }
    return n;
  };
  const auto keep = [&](const Hypothesis& h) {
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
  };
  // A sample is two correspondences with their normals: a point pair fixes a rotation, so the
  // chance of drawing only right pairs is w^2 instead of w^3 for an inlier share w. It must look
  // alike in both clouds (edge length, angle between the normals, angles of the normals with the
  // edge: the point-pair feature) before it is scored.
  const double cos_tol = std::cos(detail::radians(p.normal_tolerance_deg));
  const auto frame = [](const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                        const Eigen::Vector3d& n0) {
    const Eigen::Vector3d x = (p1 - p0).normalized();
    const Eigen::Vector3d y = (n0 - n0.dot(x) * x).normalized();
    Eigen::Matrix3d f;
    f << x, y, x.cross(y);
    return f;
  };
  const auto angle_alike = [&](double a, double b) {
    // cos of the difference of two angles given by their cosines, without acos
    const double sa = std::sqrt(std::max(0.0, 1 - a * a)), sb = std::sqrt(std::max(0.0, 1 - b * b));
    return a * b + sa * sb >= cos_tol;
  };
  int valid = 0;
  const long attempts = 50L * p.ransac_iterations;
  for (long a = 0; a < attempts && valid < p.ransac_iterations; ++a) {
    const std::size_t s0 = pick(rng), s1 = pick(rng);
    if (s0 == s1) continue;
    const auto& [i0, j0] = c[s0];
    const auto& [i1, j1] = c[s1];
    const Eigen::Vector3d dc = cand.points[i1] - cand.points[i0];
    const Eigen::Vector3d dv = view.points[j1] - view.points[j0];
    const double lc = dc.norm(), lv = dv.norm();
    if (!(lc > min_edge && lv > min_edge &&
          std::min(lc, lv) >= p.edge_similarity * std::max(lc, lv)))
      continue;
    const Eigen::Vector3d &nc0 = cand.normals[i0], &nc1 = cand.normals[i1];
    const Eigen::Vector3d &nv0 = view.normals[j0], &nv1 = view.normals[j1];
    if (!angle_alike(nc0.dot(nc1), nv0.dot(nv1)) ||
        !angle_alike(nc0.dot(dc) / lc, nv0.dot(dv) / lv) ||
        !angle_alike(nc1.dot(dc) / lc, nv1.dot(dv) / lv))
      continue;
    if (std::abs(nc0.dot(dc) / lc) > 0.99) continue;  // normal along the edge: no frame
    ++valid;
    Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
    const Eigen::Matrix3d r = frame(cand.points[i0], cand.points[i1], nc0) *
                              frame(view.points[j0], view.points[j1], nv0).transpose();
    t.topLeftCorner<3, 3>() = r;
    t.topRightCorner<3, 1>() =
        (cand.points[i0] + cand.points[i1]) / 2 - r * (view.points[j0] + view.points[j1]) / 2;
    const int n = inliers(t, nullptr, nullptr);
    if (n >= 3) keep({t, n, 0});
  }
  for (Hypothesis& h : top) {
    std::vector<Eigen::Vector3d> a, b;
    inliers(h.pose, &a, &b);
    const Eigen::Matrix4d refit = kabsch(a, b);
    if (inliers(refit, nullptr, nullptr) >= h.inliers) h.pose = refit;
  }
  judge(top, cand, view, p);
  return top;
}

// ICP refinement. The candidate's points are matched into the view's point grid (PointGrid, built
// once, when the view entered the database): every candidate point should lie on the model, while
// the view may show more of the object than the candidate does.
Eigen::Matrix4d icp(const Cloud& cand, const Cloud& view, Eigen::Matrix4d pose,
                    const RegistrationParams& p, int& iterations) {
  Eigen::Matrix4d inv = pose.inverse();  // model <- candidate
  const double r2 = p.icp_distance * p.icp_distance;
  std::vector<Eigen::Vector3d> src, dst, nrm;
  iterations = 0;
  for (int it = 0; it < p.icp_iterations; ++it) {
    src.clear();
    dst.clear();
    nrm.clear();
    for (const auto& c : cand.points) {
      const Eigen::Vector3d q = apply(inv, c);
      double d2 = 0;
      const int j = nearest(view.index->points, q, p.icp_distance, d2);
      if (j < 0 || d2 > r2) continue;
      src.push_back(q);
      dst.push_back(view.points[j]);
      nrm.push_back(view.normals[j]);
    }
    if (src.size() < 6) break;
    ++iterations;
    const Eigen::Matrix4d step =
        p.point_to_plane ? point_to_plane(src, dst, nrm) : kabsch(src, dst);
    inv = step * inv;
    // Converged: a step under 0.1 mm and 0.06 degrees (1e-3 rad: its rotation's trace, 1 + 2 cos
    // angle, above 1 + 2 cos 1e-3) changes no score at 5 mm.
    if (step.topLeftCorner<3, 3>().trace() > 2.999999000000083 &&
        step.topRightCorner<3, 1>().norm() < 1e-4)
      break;
  }
  return inv.inverse();
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
  open3d::geometry::PointCloud pc;
  pc.points_.reserve(points.size());
  std::vector<Rgb> kept_colours;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (points[i].allFinite()) {
      pc.points_.push_back(round_to_float(points[i]));
      if (!colours.empty()) kept_colours.push_back(colours[i]);
    }
  if (pc.points_.size() < 10)
    throw InputError("cloud has " + std::to_string(pc.points_.size()) +
                     " points after the voxel filter (expected at least 10)");
  pc.EstimateNormals(open3d::geometry::KDTreeSearchParamHybrid(params.normal_radius, 30), false);
  Cloud c;
  c.points = pc.points_;
  c.colours = std::move(kept_colours);
  c.centroid = mean(c.points);
  c.viewpoint = viewpoint;
  const bool from_viewpoint = viewpoint.allFinite();
  for (std::size_t i = 0; i < c.size(); ++i) {
    Eigen::Vector3d n = pc.normals_[i];
    const Eigen::Vector3d out = from_viewpoint ? Eigen::Vector3d(viewpoint - c.points[i])
                                               : Eigen::Vector3d(c.points[i] - c.centroid);
    if (n.dot(out) < 0) n = -n;
    pc.normals_[i] = round_to_float(n);
  }
  c.normals = pc.normals_;
  c.features.resize(kFpfhBins * params.fpfh_radii.size(), c.size());
  for (std::size_t b = 0; b < params.fpfh_radii.size(); ++b) {
    const auto f = open3d::pipelines::registration::ComputeFPFHFeature(
        pc, open3d::geometry::KDTreeSearchParamHybrid(params.fpfh_radii[b], 100));
    c.features.middleRows(b * kFpfhBins, kFpfhBins) =
        f->data_.unaryExpr([](double x) { return static_cast<double>(static_cast<float>(x)); });
  }
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

double fitness(const Cloud& candidate, const Cloud& view, const Eigen::Matrix4d& pose, double delta,
               double* rmse) {
  const Eigen::Matrix4d inv = pose.inverse();
  int n = 0;
  double sum = 0;
  for (const auto& c : candidate.points) {
    double d2 = 0;
    if (nearest(view.index->points, apply(inv, c), delta, d2) >= 0 && d2 <= delta * delta) {
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
    double d2 = 0;
    out[i] =
        nearest(view.index->points, apply(inv, points[i]), delta, d2) >= 0 && d2 <= delta * delta;
  }
  return out;
}

// The view's points that the candidate's sensor would see: a z-buffer over viewing directions
// with cells about three point spacings wide at the object's range, keeping in each cell the
// points within a few spacings of the nearest one. Directions are taken on the plane tangent to
// the unit sphere at the object's direction (a gnomonic projection, within 1 % of the angles
// over an object's few degrees): no trigonometry, and a dense buffer over the object's cells.
// Without `silhouette`, every visible point counts as inside.
namespace {
CoverageCounts count_coverage(const Cloud& candidate, const Cloud& view,
                              const Eigen::Matrix4d& pose, double delta, bool silhouette) {
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
  for (std::size_t j = 0; j < view.size(); ++j) {
    if (depth[j] < 0 || depth[j] > zbuf[key[j]] + 2 * spacing) continue;
    ++(seen[key[j]] ? out.inside : out.outside);
    double d2 = 0;
    out.explained += nearest(candidate.index->points, q[j] + candidate.viewpoint, delta, d2) >= 0 &&
                     d2 <= delta * delta;
  }
  return out;
}
}  // namespace

CoverageCounts coverage_counts(const Cloud& candidate, const Cloud& view,
                               const Eigen::Matrix4d& pose, double delta) {
  return count_coverage(candidate, view, pose, delta, true);
}

double coverage(const Cloud& candidate, const Cloud& view, const Eigen::Matrix4d& pose,
                double delta, double outside_weight) {
  const CoverageCounts c = count_coverage(candidate, view, pose, delta, outside_weight < 1);
  const double counted = c.inside + outside_weight * c.outside;
  return counted > 0 ? std::min(1.0, c.explained / counted) : 0;
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

Alignment align(const Cloud& candidate, const Cloud& view, const RegistrationParams& params,
                std::uint64_t seed) {
  return align(candidate, subsample(candidate, params.max_points), view, params, seed);
}

Alignment align(const Cloud& candidate_all, const Cloud& candidate, const Cloud& view,
                const RegistrationParams& params, std::uint64_t seed) {
  Alignment a;
  detail::Stopwatch watch;
  std::mt19937_64 rng(seed);
  const int blocks = static_cast<int>(view.features.rows()) / kFpfhBins;
  std::vector<Hypothesis> top;
  if (params.multi_radius == MultiRadius::kBestOf && blocks > 1) {
    for (int b = 0; b < blocks; ++b) {
      const auto corr = correspondences(candidate, view, b, params.mutual_filter);
      auto h = ransac(candidate, view, corr, params, rng);
      a.correspondences = std::max<int>(a.correspondences, corr.size());
      top.insert(top.end(), h.begin(), h.end());
    }
    std::stable_sort(top.begin(), top.end(), [](const Hypothesis& x, const Hypothesis& y) {
      return x.overlap > y.overlap;
    });
  } else {
    const auto corr = correspondences(candidate, view, -1, params.mutual_filter);
    a.correspondences = static_cast<int>(corr.size());
    top = ransac(candidate, view, corr, params, rng);
  }
  // Algorithm 2 starts from the centroid shift: without a RANSAC hypothesis, the view's
  // centroid is put on the candidate's and ICP starts from there.
  if (top.empty() || top[0].overlap <= 0) {
    Hypothesis h;
    h.pose.topRightCorner<3, 1>() = candidate.centroid - view.centroid;
    top.assign(1, h);
  }
  a.ransac_inliers = top[0].inliers;
  a.ransac_ms = watch.lap();
  // ICP from the best few hypotheses; near-symmetric objects (boxes, bricks) have several
  // hypotheses of almost equal overlap, and only after ICP does the right one stand out.
  double best = -1;
  const int starts = std::min<int>(std::max(1, params.icp_starts), static_cast<int>(top.size()));
  for (int k = 0; k < starts; ++k) {
    int iterations = 0;
    const Eigen::Matrix4d pose = icp(candidate, view, top[k].pose, params, iterations);
    double agree = 1;
    const bool coloured =
        params.colour_alignment && !candidate.colours.empty() && !view.colours.empty();
    const double explained = starts == 1 ? 0
                             : coloured
                                 ? explained_colour(candidate, view, pose, params.score_distance,
                                                    params.brightness_sigma, agree)
                                 : fitness(candidate, view, pose, params.score_distance);
    const double score =
        starts == 1
            ? 0
            : symmetric_overlap(explained, coverage(candidate, view, pose, params.score_distance)) *
                  agree;
    if (score > best) {
      best = score;
      a.pose = pose;
      a.icp_iterations = iterations;
    }
  }
  a.icp_ms = watch.lap();
  const Alignment scored = score_pose(candidate_all, view, a.pose, params);
  a.fitness = scored.fitness;
  a.close_fitness = scored.close_fitness;
  a.coverage = scored.coverage;
  a.occluded_coverage = scored.occluded_coverage;
  a.rmse = scored.rmse;
  a.colour = scored.colour;
  a.coloured = scored.coloured;
  a.score_ms = watch.lap();
  return a;
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
      double d2 = 0;
      if (nearest(candidate.index->points, apply(pose, view.points[j]), params.score_distance,
                  d2) >= 0 &&
          d2 <= sd2)
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
