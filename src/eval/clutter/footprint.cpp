// Footprints of the cluttered scene generator: convex polygons in the table plane (hull, area,
// overlap, gap, containment); see clutter/footprint.hpp.
#include "eval/clutter/footprint.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>

namespace proxseg::clutter {

using Vec2 = Eigen::Vector2d;

double cross2(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}

Poly convex_hull(std::vector<Vec2> pts) {
  std::sort(pts.begin(), pts.end(), [](const Vec2& a, const Vec2& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return pts;
  Poly h(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {  // lower
    while (k >= 2 && cross2(h[k - 1] - h[k - 2], pts[i] - h[k - 2]) <= 1e-12) --k;
    h[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {  // upper
    while (k >= t && cross2(h[k - 1] - h[k - 2], pts[i] - h[k - 2]) <= 1e-12) --k;
    h[k++] = pts[i];
  }
  h.resize(k - 1);
  return h;
}

double poly_area(const Poly& p) {
  double a = 0;
  for (std::size_t i = 0; i < p.size(); ++i) a += cross2(p[i], p[(i + 1) % p.size()]);
  return a / 2;
}

// True if the interiors overlap (touching edges do not count).
bool overlap(const Poly& a, const Poly& b) {
  for (const Poly* p : {&a, &b})
    for (std::size_t i = 0; i < p->size(); ++i) {
      const Vec2 e = (*p)[(i + 1) % p->size()] - (*p)[i];
      const Vec2 n(e.y(), -e.x());
      double amin = 1e300, amax = -1e300, bmin = 1e300, bmax = -1e300;
      for (const Vec2& v : a) amin = std::min(amin, n.dot(v)), amax = std::max(amax, n.dot(v));
      for (const Vec2& v : b) bmin = std::min(bmin, n.dot(v)), bmax = std::max(bmax, n.dot(v));
      const double tol = 1e-12 * n.norm();
      if (amax <= bmin + tol || bmax <= amin + tol) return false;
    }
  return true;
}

namespace {

double seg_dist(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-30), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

}  // namespace

// Distance between two convex polygons, -1 if they overlap.
double poly_gap(const Poly& a, const Poly& b) {
  if (overlap(a, b)) return -1;
  double d = std::numeric_limits<double>::infinity();
  for (int pass = 0; pass < 2; ++pass) {
    const Poly &p = pass ? b : a, &q = pass ? a : b;
    for (const Vec2& v : p)
      for (std::size_t i = 0; i < q.size(); ++i)
        d = std::min(d, seg_dist(v, q[i], q[(i + 1) % q.size()]));
  }
  return d;
}

// Every vertex of inner at least margin inside the (counter-clockwise) outer polygon.
bool inside(const Poly& inner, const Poly& outer, double margin) {
  for (std::size_t i = 0; i < outer.size(); ++i) {
    const Vec2 a = outer[i], e = outer[(i + 1) % outer.size()] - a;
    const double len = e.norm();
    for (const Vec2& v : inner)
      if (cross2(e, v - a) / len < margin) return false;
  }
  return true;
}

Eigen::Matrix2d rot2(double yaw) {
  return Eigen::Rotation2Dd(yaw).toRotationMatrix();
}

}  // namespace proxseg::clutter
