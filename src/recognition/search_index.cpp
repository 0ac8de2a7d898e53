// The search index of a described cloud [paper 3.4, Algorithm 2]: a dense point grid for exact
// nearest-point queries within a small radius, and the feature matrices (search_index.hpp).
#include "search_index.hpp"

#include <algorithm>
#include <cmath>

namespace proxseg {
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

// The cells of the box of half-width rc cells around q (cq: q in cell units), clamped to the
// grid: a..b inclusive; false when the box misses the grid. The box is widened by a millionth of
// a cell, far more than the rounding of cq and rc, so that every cell holding a point within rc
// cells of q is searched (the distance decides), without a division per bound. Inlined: it
// runs for every query, and as a call it cost 2.5 % of a frame's instructions.
[[gnu::always_inline]] inline bool box_cells(const PointGrid& g, const Eigen::Vector3d& cq,
                                             double rc, Eigen::Vector3i& a, Eigen::Vector3i& b) {
  constexpr double kSlack = 1e-6;
  for (int k = 0; k < 3; ++k) {
    const double lo = cq[k] - rc - kSlack, hi = cq[k] + rc + kSlack;
    if (!(hi >= 0 && lo < g.dims[k])) return false;  // off the grid (or not a number)
    // floor() of the clamped, non-negative bounds as a truncation.
    a[k] = static_cast<int>(std::max(lo, 0.0));
    b[k] = static_cast<int>(std::min(hi, static_cast<double>(g.dims[k] - 1)));
  }
  return true;
}

// Calls visit(k) for the points of the box's cells in cell order (k: the place in the grid's
// order) until it returns true; whether one did.
template <typename Visit>
bool visit_box(const PointGrid& g, const Eigen::Vector3i& a, const Eigen::Vector3i& b,
               Visit visit) {
  for (int z = a.z(); z <= b.z(); ++z)
    for (int y = a.y(); y <= b.y(); ++y) {
      const std::size_t row = (static_cast<std::size_t>(z) * g.dims.y() + y) * g.dims.x();
      for (int k = g.start[row + a.x()], e = g.start[row + b.x() + 1]; k < e; ++k)
        if (visit(k)) return true;
    }
  return false;
}

// The nearest point of the grid to q among the cells of the box of half-width rc cells around
// it with a squared distance of at most best, the last in cell order of those as near: its
// place in the grid's order, or -1 (best then unchanged).
int nearest_in_box(const PointGrid& g, const Eigen::Vector3d& q, const Eigen::Vector3d& cq,
                   double rc, double& best) {
  Eigen::Vector3i a, b;
  if (!box_cells(g, cq, rc, a, b)) return -1;
  int found = -1;
  visit_box(g, a, b, [&](int k) {
    const double d = (g.points[k] - q).squaredNorm();
    if (d <= best) {
      best = d;
      found = k;
    }
    return false;
  });
  return found;
}

// Whether a point of the box of half-width rc cells around q lies within squared distance r2 of
// q: the first one found answers.
bool any_in_box(const PointGrid& g, const Eigen::Vector3d& q, const Eigen::Vector3d& cq, double rc,
                double r2) {
  Eigen::Vector3i a, b;
  return box_cells(g, cq, rc, a, b) &&
         visit_box(g, a, b, [&](int k) { return (g.points[k] - q).squaredNorm() <= r2; });
}

}  // namespace

namespace detail {

int nearest_within(const PointGrid& g, const Eigen::Vector3d& q, double bound2, double& d2) {
  if (g.order.empty()) return -1;
  const double inverse = 1 / g.cell;
  const Eigen::Vector3d cq = (q - g.origin) * inverse;
  double best = bound2;
  const int k = nearest_in_box(g, q, cq, std::sqrt(bound2) * inverse, best);
  if (k < 0) return -1;
  d2 = best;
  return g.order[k];
}

bool any_within(const PointGrid& g, const Eigen::Vector3d& q, double r) {
  if (g.order.empty()) return false;
  const double inverse = 1 / g.cell;
  const Eigen::Vector3d cq = (q - g.origin) * inverse;
  const double r2 = r * r;
  // The box of half a cell first, as nearest(): most queries that have a point within r have one
  // there, and any point within r lies in the box of r too.
  if (r > 0.5 * g.cell && any_in_box(g, q, cq, 0.5, r2)) return true;
  return any_in_box(g, q, cq, r * inverse, r2);
}

int nearest(const PointGrid& g, const Eigen::Vector3d& q, double r, double& d2) {
  if (g.order.empty()) return -1;
  const double inverse = 1 / g.cell;
  const Eigen::Vector3d cq = (q - g.origin) * inverse;
  double best = r * r;
  int k = -1;
  // The box of half a cell first: a point found in it within half a cell is the nearest (a
  // nearer one would lie in the box too); one farther bounds the search instead of r. Every
  // point as near as the nearest lies in the smaller box, which is searched in the same cell
  // order: the same point as from the box of r.
  if (r > 0.5 * g.cell) {
    k = nearest_in_box(g, q, cq, 0.5, best);
    if (k >= 0 && best <= 0.25 * g.cell * g.cell) {
      d2 = best;
      return g.order[k];
    }
  }
  const int j = nearest_in_box(g, q, cq, (k >= 0 ? std::sqrt(best) : r) * inverse, best);
  if (j >= 0) k = j;
  if (k < 0) return -1;
  d2 = best;
  return g.order[k];
}

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

}  // namespace detail
}  // namespace proxseg
