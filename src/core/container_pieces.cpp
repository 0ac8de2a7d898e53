// The inside and the outside of one container. Seen from above, a mug shows the front of its
// outer wall and, through the opening, the inside of its back wall and its floor; the rim's edge
// between them is a depth step in front and a band of missing pixels at the sides (too thin for
// the sensor), so neither the components nor the convex links join them, and the meeting of the
// inner wall with the floor is a concave crease. What makes them one object is the shape of a
// solid of revolution standing on the table: the outer wall's footprint on the table is an arc of
// a circle, and everything else of the container lies inside that circle and below its rim.
#include "container_pieces.hpp"

#include "util/union_find.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace proxseg::detail {
namespace {

// The footprint (coordinates on the support plane) and heights above it of a component.
struct Piece {
  std::vector<Eigen::Vector2d> footprint;
  std::vector<double> height;
  double top = 0;     // rim: a high percentile of the heights (robust to a few stray pixels)
  double bottom = 0;  // a low percentile
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double radius = 0;
  bool round = false;  // the footprint lies on a circle
};

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[static_cast<std::size_t>(k)];
}

// Least-squares circle through the footprint (Kasa's algebraic fit): x^2 + y^2 = 2ax + 2by + c.
// Round when the radius is plausible for a container and the points lie on the circle within
// containers.circle_rms of the radius (a box's footprint, two lines, does not).
void fit_circle(Piece& s, const SelectionParams& params) {
  const std::size_t n = s.footprint.size();
  if (n < 3) return;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& x : s.footprint) mean += x;
  mean /= static_cast<double>(n);
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  for (const auto& x : s.footprint) {
    const Eigen::Vector2d d = x - mean;  // centred, for conditioning
    const Eigen::Vector3d row(2 * d.x(), 2 * d.y(), 1);
    ata += row * row.transpose();
    atb += row * d.squaredNorm();
  }
  const Eigen::Vector3d c = ata.ldlt().solve(atb);
  if (!c.allFinite()) return;
  const double r2 = c[2] + c[0] * c[0] + c[1] * c[1];
  if (r2 <= 0) return;
  s.centre = mean + c.head<2>();
  s.radius = std::sqrt(r2);
  double sq = 0;
  for (const auto& x : s.footprint) {
    const double e = (x - s.centre).norm() - s.radius;
    sq += e * e;
  }
  const double rms = std::sqrt(sq / static_cast<double>(n));
  s.round = s.radius >= params.containers.min_radius && s.radius <= params.containers.max_radius &&
            rms <= params.containers.circle_rms * s.radius;
}

// Whether `inner` is the inside of the container `outer`: its footprint within the circle (all
// but a few stray pixels), no higher than the rim and reaching below it.
bool inside_of(const Piece& inner, const Piece& outer, const SelectionParams& params) {
  const double tol = params.containers.rim_tolerance;
  if (!outer.round || inner.top > outer.top + tol ||
      inner.bottom > outer.top - params.containers.min_depth)
    return false;
  std::size_t in = 0;
  for (const auto& x : inner.footprint) in += (x - outer.centre).norm() <= outer.radius + tol;
  return in >= 0.9 * static_cast<double>(inner.footprint.size());
}

}  // namespace

// Each component's footprint on the support plane (axes e1, e2) and heights above it; the
// large ones with their top, bottom and fitted circle.
std::vector<Piece> plane_footprints(const Frame& f, const Plane& support, const Eigen::Vector3f& e1,
                                    const Eigen::Vector3f& e2, const SelectionParams& params,
                                    int count, const std::vector<int>& comp) {
  std::vector<Piece> pieces(count);
  for (std::size_t p = 0; p < comp.size(); ++p) {
    if (comp[p] < 0) continue;
    Piece& s = pieces[comp[p]];
    s.footprint.emplace_back(e1.dot(f.xyz[p]), e2.dot(f.xyz[p]));
    s.height.push_back(support.distance(f.xyz[p]));
  }
  for (Piece& s : pieces) {
    if (static_cast<int>(s.footprint.size()) < params.min_candidate_points) continue;
    s.top = percentile(s.height, 0.98);
    s.bottom = percentile(s.height, 0.05);
    fit_circle(s, params);
  }
  return pieces;
}

void join_container_pieces(const ImageGrid& g, const Plane& support, const SelectionParams& params,
                           int count, std::vector<int>& comp) {
  const Frame& f = g.frame;
  const Eigen::Vector3f e1 = support.normal.unitOrthogonal(), e2 = support.normal.cross(e1);
  const std::vector<Piece> pieces = plane_footprints(f, support, e1, e2, params, count, comp);
  UnionFind sets(static_cast<std::size_t>(count));
  std::vector<char> container(count, 0);  // a round component with an inside
  bool joined = false;
  for (int a = 0; a < count; ++a)
    for (int b = 0; b < count; ++b) {
      if (a == b || static_cast<int>(pieces[a].footprint.size()) < params.min_candidate_points ||
          !inside_of(pieces[a], pieces[b], params))
        continue;
      sets.unite(a, b);
      container[b] = 1;
      joined = true;
    }
  // The container's floor and rim. The support plane's pixels that the image encloses inside
  // the circle: a floor a few millimetres above the table lies in its noise band, and a patch of
  // plane that no path through plane pixels joins to the rest of the table, lying inside a
  // container's circle, can only be its floor (the table around a bowl's foot, also inside the
  // rim's circle, is joined to the rest). And the pixels left out of every component within the
  // circle and below the rim: the rim's own fragments, cut off by depth steps.
  std::vector<int> containers;
  for (int c = 0; c < count; ++c)
    if (container[c]) containers.push_back(c);
  const double tol = params.containers.rim_tolerance;
  auto within = [&](int p, double reach) {
    const Eigen::Vector2d x(e1.dot(f.xyz[p]), e2.dot(f.xyz[p]));
    const double h = support.distance(f.xyz[p]);
    for (int c : containers) {
      const Piece& s = pieces[c];
      if ((x - s.centre).norm() <= s.radius + reach && h <= s.top + tol) return c;
    }
    return static_cast<int>(kNone);
  };
  std::vector<char> seen(comp.size(), 0);
  std::vector<int> patch, stack;
  for (int seed = 0; seed < static_cast<int>(comp.size()); ++seed) {
    if (containers.empty()) break;
    if (comp[seed] == kNone && g.valid(seed)) {
      const int c = within(seed, tol);
      if (c != kNone) comp[seed] = c, joined = true;
      continue;
    }
    if (comp[seed] != kPlane || seen[seed]) continue;
    // One patch of plane pixels (4-neighbours, no depth step); it goes to the container whose
    // circle holds all of it.
    patch.assign(1, seed);
    stack.assign(1, seed);
    seen[seed] = 1;
    while (!stack.empty()) {
      const int p = stack.back();
      stack.pop_back();
      for (int q : g.neighbours(p))
        if (q >= 0 && comp[q] == kPlane && !seen[q] && g.continuous(p, q)) {
          seen[q] = 1;
          patch.push_back(q);
          stack.push_back(q);
        }
    }
    const int c = within(seed, 0);
    if (c == kNone) continue;
    bool enclosed = true;
    for (int p : patch) enclosed = enclosed && within(p, 0) == c;
    if (!enclosed) continue;
    for (int p : patch) comp[p] = c;
    joined = true;
  }
  if (!joined) return;
  for (int& c : comp)
    if (c >= 0) c = static_cast<int>(sets.find(c));
}

}  // namespace proxseg::detail
