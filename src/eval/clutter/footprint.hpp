// Footprints of the cluttered scene generator (docs/clutter.md, "no interpenetration"): convex
// polygons in the table plane, the convex hulls of the objects' vertices, and the tests that
// keep objects apart (overlap), bring them into contact (gap) and keep them on a box's top face
// (inside). Private to the library.
#pragma once
#include <Eigen/Core>
#include <vector>

namespace proxseg::clutter {

using Poly = std::vector<Eigen::Vector2d>;  // convex, counter-clockwise

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b);
Poly convex_hull(std::vector<Eigen::Vector2d> pts);
double poly_area(const Poly& p);
// True if the interiors overlap (touching edges do not count).
bool overlap(const Poly& a, const Poly& b);
// Distance between two convex polygons, -1 if they overlap.
double poly_gap(const Poly& a, const Poly& b);
// Every vertex of inner at least margin inside the (counter-clockwise) outer polygon.
bool inside(const Poly& inner, const Poly& outer, double margin);
Eigen::Matrix2d rot2(double yaw);

}  // namespace proxseg::clutter
