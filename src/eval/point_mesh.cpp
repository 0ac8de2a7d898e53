// Meshes from bare surface samples: restricted-Voronoi surfels, a flood fill of the outside on a
// voxel grid, surface nets (point_mesh.hpp says why this and not Poisson or ball pivoting).
#include <proxseg/core/errors.hpp>
#include <proxseg/eval/point_mesh.hpp>
#include "util/angles.hpp"
#include "util/nearest_points.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace proxseg {
namespace {

using detail::kPi;
constexpr int kAreaNeighbour = 6;  // spacing of a point: distance to its 6th neighbour
constexpr int kEdgeNeighbour = 3;  // cap of an edge point's cell: distance to its 3rd neighbour
constexpr int kCapSides = 16;      // the cap of a cell is a regular 16-gon around its point
constexpr double kBandVoxels = 2;  // the layer's distance field is kept this far outside it
constexpr double kMaxNodes = 1e8;  // grid nodes refused beyond this (9 bytes each: 0.9 GB)

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Polygon = std::vector<Vec2>;  // convex, counter-clockwise

// Keeps the part of a convex polygon where x . q <= limit (Sutherland-Hodgman against one
// half-plane; the winding is preserved).
Polygon clip(const Polygon& poly, const Vec2& q, double limit) {
  Polygon out;
  for (std::size_t a = 0; a < poly.size(); ++a) {
    const Vec2& p = poly[a];
    const Vec2& r = poly[(a + 1) % poly.size()];
    const double sp = p.dot(q) - limit, sr = r.dot(q) - limit;
    if (sp <= 0) out.push_back(p);
    if ((sp <= 0) != (sr <= 0)) out.push_back(p + (sp / (sp - sr)) * (r - p));
  }
  return out;
}

// Convex hull, counter-clockwise, without collinear points (Andrew's monotone chain). Two
// points for collinear input, one for a single distinct point.
Polygon convex_hull(Polygon pts) {
  std::sort(pts.begin(), pts.end(), [](const Vec2& a, const Vec2& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 2) return pts;
  const auto cross = [](const Vec2& o, const Vec2& a, const Vec2& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  Polygon h(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  h.resize(k - 1);
  return h;
}

// A point's piece of the surface: its cell in its tangent plane (u, w), normal n.
struct Surfel {
  Vec3 p, n, u, w;
  Polygon cell;
  double radius = 0;  // farthest cell vertex from p
};

// Area-weighted plane fit (see PointMeshParams::normal_neighbours) of the first kn points of
// idx: s's normal n and tangent axes u, w. Returns the surface variation (the smallest
// eigenvalue over their sum).
double fit_plane(const std::vector<Vec3>& points, const std::vector<double>& area,
                 const std::vector<int>& idx, int kn, Surfel& s) {
  Vec3 mean = Vec3::Zero();
  double weight = 0;
  for (int k = 0; k < kn; ++k) {
    mean += area[idx[k]] * points[idx[k]];
    weight += area[idx[k]];
  }
  mean /= weight;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int k = 0; k < kn; ++k) {
    const Vec3 d = points[idx[k]] - mean;
    cov += area[idx[k]] * d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  s.n = eig.eigenvectors().col(0);
  s.u = eig.eigenvectors().col(2);
  s.w = s.n.cross(s.u);
  return eig.eigenvalues()(0) / std::max(eig.eigenvalues().sum(), 1e-300);
}

// The surfels of all points. The cell of p is the set of points x of its tangent plane that
// are nearer to p than to any neighbour q (|x - p| <= |x - q|, with q in 3D: neighbours off
// the plane cut it too, which keeps cells out of concavities), within its cap, cut to the hull
// of the neighbours that lie near the plane, then grown.
std::vector<Surfel> make_surfels(const std::vector<Vec3>& points, const PointMeshParams& params) {
  const detail::NearestPoints tree(points);
  const int k_max =
      std::max({params.normal_neighbours, params.cell_neighbours, kAreaNeighbour, kEdgeNeighbour});
  std::vector<int> idx;
  std::vector<double> d2;
  // The k nearest (the point itself first) into idx and d2.
  const auto search = [&](const Vec3& q, int k) {
    idx.clear(), d2.clear();
    for (const auto& [j, d] : tree.nearest(q, k)) idx.push_back(j), d2.push_back(d);
  };

  std::vector<double> area(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    search(points[i], kAreaNeighbour + 1);
    area[i] = d2.back();
  }

  const double support_tan = std::tan(detail::radians(params.support_angle_deg));
  std::vector<Surfel> surfels(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    search(points[i], k_max + 1);  // idx[0] is the point itself
    const auto neighbours = static_cast<int>(idx.size());
    const auto spacing = [&](int k) { return std::sqrt(d2[std::min(k, neighbours - 1)]); };

    Surfel& s = surfels[i];
    s.p = points[i];
    const double variation =
        fit_plane(points, area, idx, std::min(params.normal_neighbours + 1, neighbours), s);

    double cap = params.max_cell_radius;
    if (variation > params.edge_variation) cap = std::min(cap, spacing(kEdgeNeighbour));
    cap /= std::cos(kPi / kCapSides);  // the 16-gon circumscribes the cap's circle
    Polygon cell;
    for (int k = 0; k < kCapSides; ++k) {
      const double a = 2 * kPi * (k + 0.5) / kCapSides;
      cell.emplace_back(cap * std::cos(a), cap * std::sin(a));
    }

    const int kc = std::min(params.cell_neighbours + 1, neighbours);
    Polygon support{Vec2::Zero()};
    for (int k = 1; k < kc && !cell.empty(); ++k) {
      const Vec3 d = points[idx[k]] - s.p;
      const Vec2 q(d.dot(s.u), d.dot(s.w));
      if (std::abs(d.dot(s.n)) <= support_tan * q.norm()) support.push_back(q);
      // |x - p|^2 <= |x - q|^2 for x in the plane (p at its origin): x . q <= |d|^2 / 2.
      if (q.squaredNorm() > 1e-18) cell = clip(cell, q, 0.5 * d.squaredNorm());
    }

    const double margin = params.support_margin + params.support_spacing * spacing(kAreaNeighbour);
    const Polygon hull = convex_hull(support);
    if (hull.size() == 1) {  // no neighbour near the plane: a square of the margin
      for (const Vec2& q : {Vec2(1, 0), Vec2(-1, 0), Vec2(0, 1), Vec2(0, -1)})
        cell = clip(cell, q, margin);
    }
    for (std::size_t e = 0; hull.size() >= 2 && e < hull.size(); ++e) {
      const Vec2 edge = hull[(e + 1) % hull.size()] - hull[e];
      if (edge.squaredNorm() < 1e-24) continue;
      const Vec2 out = Vec2(edge.y(), -edge.x()).normalized();  // outward: hull is ccw
      cell = clip(cell, out, out.dot(hull[e]) + margin);
    }

    for (Vec2& v : cell) {
      v *= params.cell_growth;
      s.radius = std::max(s.radius, v.norm());
    }
    s.cell = std::move(cell);
  }
  return surfels;
}

// A grid of nodes origin + voxel * (x, y, z), x fastest.
struct Grid {
  Vec3 origin;
  double voxel = 0;
  std::array<int, 3> n{};
  std::size_t size() const { return std::size_t(n[0]) * n[1] * n[2]; }
  std::size_t at(int x, int y, int z) const { return (std::size_t(z) * n[1] + y) * n[0] + x; }
  Vec3 node(int x, int y, int z) const { return origin + voxel * Vec3(x, y, z); }
};

// Signed distance to the layer (the cells thickened by half_thickness), in voxels, at every
// node within kBandVoxels of it; +infinity elsewhere. Each cell's distance is the larger of the
// distance to its slab and to its polygon's edges (exact inside, a lower bound outside).
std::vector<float> layer_distance(const std::vector<Surfel>& surfels, const Grid& g,
                                  double half_thickness) {
  std::vector<float> phi(g.size(), std::numeric_limits<float>::infinity());
  const double band = kBandVoxels * g.voxel;
  for (const Surfel& s : surfels) {
    if (s.cell.size() < 3) continue;
    const std::size_t m = s.cell.size();
    std::vector<Vec2> normal(m);
    std::vector<double> offset(m);
    for (std::size_t a = 0; a < m; ++a) {
      const Vec2 e = s.cell[(a + 1) % m] - s.cell[a];
      normal[a] = e.squaredNorm() > 0 ? Vec2(e.y(), -e.x()).normalized() : Vec2::Zero();
      offset[a] = normal[a].dot(s.cell[a]);
    }
    const double reach = s.radius + half_thickness + band;
    std::array<int, 3> lo, hi;
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::max(0, int(std::floor((s.p[k] - reach - g.origin[k]) / g.voxel)));
      hi[k] = std::min(g.n[k] - 1, int(std::ceil((s.p[k] + reach - g.origin[k]) / g.voxel)));
    }
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int x = lo[0]; x <= hi[0]; ++x) {
          const Vec3 d = g.node(x, y, z) - s.p;
          const double slab = std::abs(d.dot(s.n)) - half_thickness;
          if (slab > band) continue;
          const Vec2 q(d.dot(s.u), d.dot(s.w));
          double edge = -std::numeric_limits<double>::infinity();
          for (std::size_t a = 0; a < m; ++a) edge = std::max(edge, q.dot(normal[a]) - offset[a]);
          if (edge > band) continue;
          float& slot = phi[g.at(x, y, z)];
          slot = std::min(slot, float(std::max(slab, edge) / g.voxel));
        }
  }
  return phi;
}

// Nodes reachable from the grid's border through nodes outside the layer (6-connected).
std::vector<std::uint8_t> outside(const std::vector<float>& phi, const Grid& g) {
  std::vector<std::uint8_t> out(g.size(), 0);
  std::vector<std::size_t> stack;
  const auto push = [&](std::size_t i) {
    if (!out[i] && phi[i] > 0) {
      out[i] = 1;
      stack.push_back(i);
    }
  };
  for (int z = 0; z < g.n[2]; ++z)
    for (int y = 0; y < g.n[1]; ++y)
      for (int x = 0; x < g.n[0]; ++x)
        if (x == 0 || y == 0 || z == 0 || x == g.n[0] - 1 || y == g.n[1] - 1 || z == g.n[2] - 1)
          push(g.at(x, y, z));
  const std::size_t sy = g.n[0], sz = std::size_t(g.n[0]) * g.n[1];
  while (!stack.empty()) {
    const std::size_t i = stack.back();
    stack.pop_back();
    const int x = int(i % g.n[0]), y = int(i / sy % g.n[1]), z = int(i / sz);
    if (x > 0) push(i - 1);
    if (x + 1 < g.n[0]) push(i + 1);
    if (y > 0) push(i - sy);
    if (y + 1 < g.n[1]) push(i + sy);
    if (z > 0) push(i - sz);
    if (z + 1 < g.n[2]) push(i + sz);
  }
  return out;
}

// Surface nets (Gibson 1998): a vertex per grid cell that the surface f = 0 crosses, at the mean
// of its edges' crossings; a quad (two triangles) per grid edge whose ends differ in sign,
// joining the vertices of the four cells around it. f > 0 is inside; triangles wind outwards.
Mesh surface_nets(const std::vector<float>& f, const Grid& g, const Rgb& colour) {
  static constexpr int kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                                        {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  static constexpr int kEdge[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                       {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  Mesh mesh;
  std::vector<int> vertex(g.size(), -1);  // of the cell whose lowest corner is the node
  for (int z = 0; z + 1 < g.n[2]; ++z)
    for (int y = 0; y + 1 < g.n[1]; ++y)
      for (int x = 0; x + 1 < g.n[0]; ++x) {
        float c[8];
        int inside = 0;
        for (int k = 0; k < 8; ++k) {
          c[k] = f[g.at(x + kCorner[k][0], y + kCorner[k][1], z + kCorner[k][2])];
          inside += c[k] > 0;
        }
        if (inside == 0 || inside == 8) continue;
        Vec3 sum = Vec3::Zero();
        int crossings = 0;
        for (const auto& e : kEdge) {
          const float a = c[e[0]], b = c[e[1]];
          if ((a > 0) == (b > 0)) continue;
          const Vec3 pa(kCorner[e[0]][0], kCorner[e[0]][1], kCorner[e[0]][2]);
          const Vec3 pb(kCorner[e[1]][0], kCorner[e[1]][1], kCorner[e[1]][2]);
          sum += pa + (double(a) / (double(a) - b)) * (pb - pa);
          ++crossings;
        }
        vertex[g.at(x, y, z)] = static_cast<int>(mesh.vertices.size());
        mesh.vertices.push_back(
            (g.origin + g.voxel * (Vec3(x, y, z) + sum / crossings)).cast<float>());
        mesh.colours.push_back(colour);
      }
  // The four cells around the edge from node (x, y, z) along axis a lie at offsets 0 and -1 in
  // the other two axes b, c; taken in this order they turn counter-clockwise seen from +a.
  static constexpr int kAround[4][2] = {{0, 0}, {-1, 0}, {-1, -1}, {0, -1}};
  for (int z = 1; z + 1 < g.n[2]; ++z)
    for (int y = 1; y + 1 < g.n[1]; ++y)
      for (int x = 1; x + 1 < g.n[0]; ++x) {
        const bool in0 = f[g.at(x, y, z)] > 0;
        for (int a = 0; a < 3; ++a) {
          const bool in1 = f[g.at(x + (a == 0), y + (a == 1), z + (a == 2))] > 0;
          if (in0 == in1) continue;
          const int b = (a + 1) % 3, c = (a + 2) % 3;
          std::array<int, 4> q;
          for (int k = 0; k < 4; ++k) {
            std::array<int, 3> cell{x, y, z};
            cell[b] += kAround[k][0];
            cell[c] += kAround[k][1];
            q[k] = vertex[g.at(cell[0], cell[1], cell[2])];
          }
          // Outward is +a when the inside is at the edge's lower end, -a otherwise.
          if (!in0) std::swap(q[1], q[3]);
          mesh.triangles.emplace_back(q[0], q[1], q[2]);
          mesh.triangles.emplace_back(q[0], q[2], q[3]);
        }
      }
  return mesh;
}

// Moves every vertex by `distance` against its normal (the area-weighted mean of its
// triangles' outward normals).
void move_inwards(Mesh& mesh, double distance) {
  std::vector<Vec3> normal(mesh.vertices.size(), Vec3::Zero());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]].cast<double>(), b = mesh.vertices[t[1]].cast<double>(),
               c = mesh.vertices[t[2]].cast<double>();
    const Vec3 n = (b - a).cross(c - a);  // length: twice the area
    for (int k = 0; k < 3; ++k) normal[t[k]] += n;
  }
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    if (normal[i].squaredNorm() > 0)
      mesh.vertices[i] -= (distance * normal[i].normalized()).cast<float>();
}

void validate(const std::vector<Vec3>& points, const PointMeshParams& p) {
  const auto bad = [](const std::string& what) { throw InputError("mesh_from_points: " + what); };
  if (!(p.voxel > 0) || !std::isfinite(p.voxel)) bad("voxel must be > 0");
  if (!(p.half_thickness >= 0.5) || !std::isfinite(p.half_thickness))
    bad("half_thickness must be >= 0.5 voxels (thinner layers leak)");
  if (p.normal_neighbours < 3) bad("normal_neighbours must be >= 3");
  if (p.cell_neighbours < 3) bad("cell_neighbours must be >= 3");
  if (!(p.max_cell_radius > 0) || !std::isfinite(p.max_cell_radius))
    bad("max_cell_radius must be > 0");
  if (!(p.edge_variation >= 0)) bad("edge_variation must be >= 0");
  if (!(p.support_angle_deg >= 0 && p.support_angle_deg < 90))
    bad("support_angle_deg must be in [0, 90)");
  if (!(p.support_margin >= 0) || !std::isfinite(p.support_margin))
    bad("support_margin must be >= 0");
  if (!(p.support_spacing >= 0) || !std::isfinite(p.support_spacing))
    bad("support_spacing must be >= 0");
  if (!(p.cell_growth >= 1) || !std::isfinite(p.cell_growth)) bad("cell_growth must be >= 1");
  if (points.size() < 4)
    throw InputError("mesh_from_points: " + std::to_string(points.size()) +
                     " points (expected at least 4 surface samples)");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw InputError("mesh_from_points: point " + std::to_string(i) +
                       " is not finite (expected x y z in metres)");
}

}  // namespace

Mesh mesh_from_points(const std::vector<Eigen::Vector3d>& points, const PointMeshParams& params) {
  validate(points, params);
  const std::vector<Surfel> surfels = make_surfels(points, params);

  Vec3 lo = points[0], hi = points[0];
  for (const Vec3& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  double reach = 0;
  for (const Surfel& s : surfels) reach = std::max(reach, s.radius);
  const double half_thickness = params.half_thickness * params.voxel;
  // Room for the largest cell, the layer, its band and a ring of free nodes for the flood fill.
  const double margin = reach + half_thickness + (kBandVoxels + 2) * params.voxel;
  Grid g;
  g.voxel = params.voxel;
  g.origin = lo - Vec3::Constant(margin);
  Vec3 nodes;
  for (int k = 0; k < 3; ++k) nodes[k] = std::ceil((hi[k] - lo[k] + 2 * margin) / params.voxel) + 1;
  if (nodes.prod() > kMaxNodes)
    throw InputError("mesh_from_points: the points span " +
                     std::to_string(static_cast<long long>(nodes.prod())) +
                     " grid nodes (at most 1e8; raise voxel)");
  for (int k = 0; k < 3; ++k) g.n[k] = static_cast<int>(nodes[k]);

  std::vector<float> field = layer_distance(surfels, g, half_thickness);
  const std::vector<std::uint8_t> out = outside(field, g);
  // Made inside-positive, in voxels: outside nodes carry minus their distance to the layer
  // (capped: beyond the band it is unknown), layer nodes their depth in it, and nodes the
  // flood fill did not reach (the interior of a closed object) are inside.
  const auto band = float(kBandVoxels);
  for (std::size_t i = 0; i < field.size(); ++i) {
    const float phi = field[i];
    field[i] = out[i] ? -std::min(phi, band) : (phi > 0 ? band : -phi);
  }

  Mesh mesh = surface_nets(field, g, params.colour);
  if (params.shrink) move_inwards(mesh, half_thickness);
  return mesh;
}

}  // namespace proxseg
