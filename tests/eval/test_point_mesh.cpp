// Meshes from bare point samples (point_mesh.hpp): shapes whose answer is known, determinism,
// input checks, and the quality of the meshes of the 21 YCB-Video models (points.xyz only),
// with a per-model table on stdout.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/eval/point_mesh.hpp>
#include <proxseg/io/cloud_io.hpp>

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace {

using Vec3 = Eigen::Vector3d;
constexpr double kPi = 3.14159265358979323846;
const std::string kYcb = std::string(PROXSEG_DATA_DIR) + "/ycbv";

// ------------------------------------------------------------------------------------------
// Measures

struct Box {
  Vec3 lo, hi;
};
Box bounds(const std::vector<Vec3>& p) {
  Box b{p[0], p[0]};
  for (const Vec3& q : p) b.lo = b.lo.cwiseMin(q), b.hi = b.hi.cwiseMax(q);
  return b;
}
std::vector<Vec3> vertices(const proxseg::Mesh& m) {
  std::vector<Vec3> v;
  for (const auto& x : m.vertices) v.push_back(x.cast<double>());
  return v;
}

// Items bucketed in a dense grid of cubes over a box, for radius queries.
class Buckets {
 public:
  Buckets(const Box& box, double cell) : lo_(box.lo), cell_(cell) {
    for (int k = 0; k < 3; ++k)
      n_[k] = std::max(1, int(std::ceil((box.hi[k] - box.lo[k]) / cell)) + 1);
    items_.resize(std::size_t(n_[0]) * n_[1] * n_[2]);
  }
  // Adds item to every cube that the box [a, b] touches.
  void add(int item, const Vec3& a, const Vec3& b) {
    each(a, b, [&](std::vector<int>& c) { c.push_back(item); });
  }
  // Calls f(item) for the items of every cube that [a, b] touches (an item may come twice).
  template <class F>
  void query(const Vec3& a, const Vec3& b, F f) {
    each(a, b, [&](std::vector<int>& c) {
      for (int i : c) f(i);
    });
  }

 private:
  template <class F>
  void each(const Vec3& a, const Vec3& b, F f) {
    std::array<int, 3> i0, i1;
    for (int k = 0; k < 3; ++k) {
      i0[k] = std::clamp(int(std::floor((a[k] - lo_[k]) / cell_)), 0, n_[k] - 1);
      i1[k] = std::clamp(int(std::floor((b[k] - lo_[k]) / cell_)), 0, n_[k] - 1);
    }
    for (int z = i0[2]; z <= i1[2]; ++z)
      for (int y = i0[1]; y <= i1[1]; ++y)
        for (int x = i0[0]; x <= i1[0]; ++x) f(items_[(std::size_t(z) * n_[1] + y) * n_[0] + x]);
  }
  Vec3 lo_;
  double cell_;
  std::array<int, 3> n_;
  std::vector<std::vector<int>> items_;
};

// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double s = 1 / (va + vb + vc);
  return a + ab * (vb * s) + ac * (vc * s);
}

// (a) Distance of every point to the mesh surface (exact point-to-triangle), capped at `cap`.
std::vector<double> point_to_mesh(const std::vector<Vec3>& points, const proxseg::Mesh& m,
                                  double cap) {
  const std::vector<Vec3> v = vertices(m);
  Box box = bounds(v);
  const Box pb = bounds(points);
  box.lo = box.lo.cwiseMin(pb.lo), box.hi = box.hi.cwiseMax(pb.hi);
  Buckets tri(box, 0.004);
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto& f = m.triangles[t];
    tri.add(int(t), v[f[0]].cwiseMin(v[f[1]]).cwiseMin(v[f[2]]),
            v[f[0]].cwiseMax(v[f[1]]).cwiseMax(v[f[2]]));
  }
  std::vector<double> d;
  for (const Vec3& p : points) {
    double best = cap;
    tri.query(p - Vec3::Constant(cap), p + Vec3::Constant(cap), [&](int t) {
      const auto& f = m.triangles[t];
      best = std::min(best, (closest_on_triangle(p, v[f[0]], v[f[1]], v[f[2]]) - p).norm());
    });
    d.push_back(best);
  }
  return d;
}

// Nearest-point queries over the model points.
class NearestPoint {
 public:
  NearestPoint(const std::vector<Vec3>& points, double cell)
      : points_(points), cell_(cell), grid_(grown(bounds(points), 0.05), cell) {
    for (std::size_t i = 0; i < points.size(); ++i) grid_.add(int(i), points[i], points[i]);
  }
  // Distance to the nearest point other than `skip`, or +infinity when none is within `reach`
  // (at most the 5 cm the grid extends beyond the points).
  double distance(const Vec3& q, double reach, int skip = -1) {
    double best = std::numeric_limits<double>::infinity();
    grid_.query(q - Vec3::Constant(reach), q + Vec3::Constant(reach), [&](int i) {
      if (i != skip) best = std::min(best, (points_[i] - q).squaredNorm());
    });
    return std::sqrt(best) <= reach ? std::sqrt(best) : std::numeric_limits<double>::infinity();
  }

 private:
  static Box grown(Box b, double by) {
    b.lo -= Vec3::Constant(by), b.hi += Vec3::Constant(by);
    return b;
  }
  const std::vector<Vec3>& points_;
  double cell_;
  Buckets grid_;
};

// (b) How much of the mesh lies far from every point: the triangles sampled on a grid of about
// 1 mm, the area share of the samples farther than `far` from the nearest point, and the largest
// such distance (up to 5 cm).
struct FarSurface {
  double share = 0, max = 0;
};
FarSurface far_surface(const proxseg::Mesh& m, const std::vector<Vec3>& points, double far) {
  NearestPoint nearest(points, far), coarse(points, 0.01);  // the second for the far samples
  const std::vector<Vec3> v = vertices(m);
  FarSurface out;
  double area = 0, far_area = 0;
  for (const auto& f : m.triangles) {
    const Vec3 &a = v[f[0]], &b = v[f[1]], &c = v[f[2]];
    const double longest = std::max({(b - a).norm(), (c - a).norm(), (c - b).norm()});
    const int steps = std::max(1, int(std::ceil(longest / 0.001)));
    int samples = 0, far_samples = 0;
    for (int i = 0; i <= steps; ++i)
      for (int j = 0; i + j <= steps; ++j) {
        const Vec3 s = a + (b - a) * (double(i) / steps) + (c - a) * (double(j) / steps);
        double d = nearest.distance(s, far);
        if (!std::isfinite(d)) d = std::min(coarse.distance(s, 0.05), 0.05);
        ++samples;
        far_samples += d > far;
        out.max = std::max(out.max, d);
      }
    const double t = 0.5 * (b - a).cross(c - a).norm();
    area += t;
    far_area += t * far_samples / samples;
  }
  out.share = area > 0 ? far_area / area : 0;
  return out;
}

// What (b) would give for the true surface: the points are samples of it, so the points whose
// nearest other point is farther than `far` estimate the true surface farther than `far` from
// the samples (leave one out), each weighted by the area it stands for (squared distance to
// its 6th neighbour: the samples are dense on edges and sparse on flat faces, and a plain count
// halves the estimate for the boxes). Large for the boxes and the pitcher, whose faces have
// gaps of 2-3 cm: no mesh of them can do better.
double reference_far_share(const std::vector<Vec3>& points, double far) {
  NearestPoint nearest(points, far);
  double n = 0, total = 0;
  std::vector<double> d2(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t j = 0; j < points.size(); ++j) d2[j] = (points[j] - points[i]).squaredNorm();
    const auto sixth = d2.begin() + std::min<std::ptrdiff_t>(6, d2.size() - 1);
    std::nth_element(d2.begin(), sixth, d2.end());
    total += *sixth;
    n += *sixth * !(nearest.distance(points[i], far, int(i)) <= far);
  }
  return n / total;
}

// The points as surfels (discs of radius = distance to the 6th neighbour, in the plane of their
// 10 nearest), the reference of what a view of the object should cover.
struct Surfels {
  std::vector<Vec3> normal;
  std::vector<double> radius;
};
Surfels point_surfels(const std::vector<Vec3>& points) {
  Surfels s;
  for (const Vec3& p : points) {
    std::vector<std::pair<double, const Vec3*>> near;
    for (const Vec3& q : points) near.emplace_back((q - p).squaredNorm(), &q);
    const std::size_t k = std::min<std::size_t>(11, near.size());  // the point and 10 nearest
    std::partial_sort(near.begin(), near.begin() + k, near.end(),
                      [](const auto& a, const auto& b) { return a.first < b.first; });
    Vec3 mean = Vec3::Zero();
    for (std::size_t i = 0; i < k; ++i) mean += *near[i].second;
    mean /= double(k);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (std::size_t i = 0; i < k; ++i) {
      const Vec3 d = *near[i].second - mean;
      cov += d * d.transpose();
    }
    s.normal.push_back(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0));
    s.radius.push_back(std::sqrt(near[std::min<std::size_t>(6, k - 1)].first));
  }
  return s;
}

// Binary image morphology with a disc (erosion when !dilate).
std::vector<std::uint8_t> morph(const std::vector<std::uint8_t>& in, int w, int h, int r,
                                bool dilate) {
  std::vector<std::uint8_t> out(in.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool hit = !dilate;
      for (int dy = -r; dy <= r && hit != dilate; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          if (dx * dx + dy * dy > r * r) continue;
          const int xx = x + dx, yy = y + dy;
          const bool set = xx >= 0 && yy >= 0 && xx < w && yy < h && in[yy * w + xx];
          if (set == dilate) {
            hit = dilate;
            break;
          }
        }
      out[y * w + x] = hit;
    }
  return out;
}

// (c) See-through holes in the views of render_views (8 around the object at each distance):
// within the points' silhouette (their surfels splatted, eroded by 2 px), the share of pixels
// where the mesh shows nothing although it surrounds the pixel (invalid, not connected to the
// image border through invalid pixels) or shows something more than 1 cm behind the points'
// surface (a hole in a front face through which its back face is seen). Pixels within 8 px of
// a jump of the points' depth are not judged there: the surfels overreach at occluding edges.
// Specks narrower than 5 px (an opening of radius 2) are not counted: the reference is coarser.
// Returns the share of every view.
std::vector<double> hole_shares(const proxseg::Mesh& mesh, const std::vector<Vec3>& points,
                                const Surfels& surfels, const std::vector<double>& distances) {
  const Box mb = bounds(vertices(mesh));
  const Vec3 centre = (mb.lo + mb.hi) / 2;  // render_views looks at the mesh's box centre
  std::vector<double> shares;
  for (double distance : distances) {
    proxseg::ViewSphereParams vp;
    vp.views = 8;
    vp.distance = distance;
    const proxseg::Camera cam = vp.camera;
    const int w = cam.width, h = cam.height;
    for (const proxseg::RenderedView& view : proxseg::render_views(mesh, vp)) {
      const Eigen::Isometry3d camera = proxseg::look_at(view.eye, centre);
      const auto project = [&](const Vec3& world, int& u, int& v, double& z) {
        const Vec3 c = camera * world;
        z = c.z();
        u = int(std::lround(cam.fx * c.x() / c.z() + cam.cx));
        v = int(std::lround(cam.fy * c.y() / c.z() + cam.cy));
        return z > 0 && u >= 0 && v >= 0 && u < w && v < h;
      };
      const float none = std::numeric_limits<float>::infinity();
      std::vector<float> mesh_z(w * h, none), ref_z(w * h, none);
      std::vector<std::uint8_t> valid(w * h, 0), splat(w * h, 0);
      int u, v;
      double z;
      for (const auto& p : view.points.xyz) {
        if (!project(p.cast<double>(), u, v, z)) continue;
        valid[v * w + u] = 1;
        mesh_z[v * w + u] = float(z);
      }
      for (std::size_t i = 0; i < points.size(); ++i) {
        const Vec3 a = surfels.normal[i].unitOrthogonal(), b = surfels.normal[i].cross(a);
        const double r = surfels.radius[i];
        const double r_px = r * cam.fx / (camera * points[i]).z();
        const int rings = std::max(1, int(std::ceil(2 * r_px)));  // half-pixel steps
        for (int j = 0; j <= rings; ++j) {
          const int around = std::max(1, int(std::ceil(4 * kPi * r_px * j / rings)));
          for (int k = 0; k < around; ++k) {
            const double angle = 2 * kPi * k / around, radius = r * j / rings;
            if (!project(points[i] + radius * (std::cos(angle) * a + std::sin(angle) * b), u, v, z))
              continue;
            splat[v * w + u] = 1;
            ref_z[v * w + u] = std::min(ref_z[v * w + u], float(z));
          }
        }
      }
      const std::vector<std::uint8_t> inside = morph(splat, w, h, 2, false);
      // Invalid pixels connected to the border: background, not holes.
      std::vector<std::uint8_t> background(w * h, 0);
      std::vector<int> stack;
      const auto reach = [&](int k) {
        if (valid[k] || background[k]) return;
        background[k] = 1;
        stack.push_back(k);
      };
      for (int x = 0; x < w; ++x) reach(x), reach((h - 1) * w + x);
      for (int y = 0; y < h; ++y) reach(y * w), reach(y * w + w - 1);
      while (!stack.empty()) {
        const int k = stack.back(), x = k % w, y = k / w;
        stack.pop_back();
        if (x > 0) reach(k - 1);
        if (x + 1 < w) reach(k + 1);
        if (y > 0) reach(k - w);
        if (y + 1 < h) reach(k + w);
      }
      // Range of the reference depth in a (2 * 8 + 1)^2 window (separable min and max).
      constexpr int kWindow = 8;
      const float behind = 0.01f;
      std::vector<float> lo_x(w * h), hi_x(w * h);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          float lo = none, hi = -none;
          for (int xx = std::max(0, x - kWindow); xx <= std::min(w - 1, x + kWindow); ++xx)
            if (std::isfinite(ref_z[y * w + xx]))
              lo = std::min(lo, ref_z[y * w + xx]), hi = std::max(hi, ref_z[y * w + xx]);
          lo_x[y * w + x] = lo, hi_x[y * w + x] = hi;
        }
      std::vector<std::uint8_t> hole(w * h, 0);
      std::size_t area = 0;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const int k = y * w + x;
          if (!inside[k]) continue;
          ++area;
          float lo = none, hi = -none;
          for (int yy = std::max(0, y - kWindow); yy <= std::min(h - 1, y + kWindow); ++yy)
            lo = std::min(lo, lo_x[yy * w + x]), hi = std::max(hi, hi_x[yy * w + x]);
          const bool edge = hi - lo > behind;
          hole[k] = valid[k] ? !edge && mesh_z[k] - ref_z[k] > behind : !background[k];
        }
      hole = morph(morph(hole, w, h, 2, false), w, h, 2, true);
      std::size_t holes = 0;
      for (int k = 0; k < w * h; ++k) holes += hole[k] && inside[k];
      shares.push_back(area ? double(holes) / area : 0);
    }
  }
  return shares;
}

// (d) Largest difference between the corners of the mesh's and the points' bounding boxes.
double box_error(const proxseg::Mesh& m, const std::vector<Vec3>& points) {
  const Box a = bounds(vertices(m)), b = bounds(points);
  return std::max((a.lo - b.lo).cwiseAbs().maxCoeff(), (a.hi - b.hi).cwiseAbs().maxCoeff());
}

// ------------------------------------------------------------------------------------------
// Shapes

// n points spread evenly over a sphere of radius r at c (Fibonacci lattice), z <= z_max only.
std::vector<Vec3> sphere_points(int n, double r, const Vec3& c, double z_max = 1) {
  std::vector<Vec3> p;
  const double golden = kPi * (3 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1 - (2 * i + 1.0) / n, s = std::sqrt(1 - z * z);
    if (z <= z_max)
      p.push_back(c + r * Vec3(s * std::cos(golden * i), s * std::sin(golden * i), z));
  }
  return p;
}

// Volume enclosed by a mesh (sum of signed tetrahedra): positive when wound outwards.
double volume(const proxseg::Mesh& m) {
  double v = 0;
  for (const auto& t : m.triangles)
    v += m.vertices[t[0]].cast<double>().dot(
             m.vertices[t[1]].cast<double>().cross(m.vertices[t[2]].cast<double>())) /
         6;
  return v;
}

bool same(const proxseg::Mesh& a, const proxseg::Mesh& b) {
  return a.vertices == b.vertices && a.triangles == b.triangles && a.colours == b.colours;
}

std::vector<std::string> ycb_classes() {
  std::ifstream in(kYcb + "/classes.txt");
  std::vector<std::string> names;
  for (std::string name; in >> name;) names.push_back(name);
  return names;
}

}  // namespace

TEST(PointMesh, SphereIsClosedSolidAndWoundOutwards) {
  const double r = 0.04;
  const Vec3 c(0.1, -0.2, 0.7);
  const auto points = sphere_points(2000, r, c);
  const proxseg::Mesh m = proxseg::mesh_from_points(points);
  ASSERT_FALSE(m.triangles.empty());
  ASSERT_EQ(m.colours.size(), m.vertices.size());
  for (const auto& col : m.colours) EXPECT_EQ(col, (proxseg::Rgb{128, 128, 128}));
  // A solid ball, not a shell with an inside wall: the enclosed volume is the ball's.
  const double ball = 4.0 / 3 * kPi * r * r * r;
  EXPECT_NEAR(volume(m), ball, 0.05 * ball);
  for (const auto& v : m.vertices) EXPECT_NEAR((v.cast<double>() - c).norm(), r, 0.001);
  // Closed: every edge is shared by an even number of triangles (two where it is manifold).
  std::vector<std::pair<int, int>> edges;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k)
      edges.emplace_back(std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3]));
  std::sort(edges.begin(), edges.end());
  std::size_t odd = 0;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    odd += (j - i) % 2;
    i = j;
  }
  EXPECT_EQ(odd, 0u);
}

TEST(PointMesh, OpeningsStayOpen) {
  // A bowl: the lower half of a 6 cm sphere, points on it only (about 4 mm apart). The rim is
  // not closed by a lid: looking straight down at its centre, the camera sees the bottom, 6 cm
  // below the rim. The cells of the rim's points reach beyond it by about one spacing.
  const auto points = sphere_points(3000, 0.06, Vec3::Zero(), 0.0);
  const proxseg::Mesh m = proxseg::mesh_from_points(points);
  const Box b = bounds(vertices(m));
  EXPECT_LT(b.hi.z(), 0.007);
  proxseg::RenderParams rp;
  rp.camera_from_world = proxseg::look_at(Vec3(0, 0, 0.5), Vec3::Zero());
  const proxseg::Frame f = proxseg::render({m}, rp);
  const std::size_t centre = 240 * 640 + 320;
  ASSERT_TRUE(f.valid(centre));
  EXPECT_NEAR(f.xyz[centre].z(), 0.56, 0.003);
}

TEST(PointMesh, DeterministicAcrossRunsAndThreads) {
  const auto points = proxseg::read_xyz(kYcb + "/models/025_mug/points.xyz");
  const proxseg::Mesh first = proxseg::mesh_from_points(points);
  EXPECT_TRUE(same(first, proxseg::mesh_from_points(points)));
  // The same from two threads at once (no shared state, nothing depends on the thread).
  proxseg::Mesh a, b;
  std::thread ta([&] { a = proxseg::mesh_from_points(points); });
  std::thread tb([&] { b = proxseg::mesh_from_points(points); });
  ta.join();
  tb.join();
  EXPECT_TRUE(same(first, a));
  EXPECT_TRUE(same(first, b));
}

TEST(PointMesh, RejectsBadInputAndParameters) {
  const auto points = sphere_points(200, 0.05, Vec3::Zero());
  EXPECT_THROW(proxseg::mesh_from_points({}), proxseg::InputError);
  EXPECT_THROW(proxseg::mesh_from_points({Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY()}),
               proxseg::InputError);
  auto nan = points;
  nan[7].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(proxseg::mesh_from_points(nan), proxseg::InputError);
  const auto with = [&](auto change) {
    proxseg::PointMeshParams p;
    change(p);
    return p;
  };
  using P = proxseg::PointMeshParams;
  for (const P& p :
       {with([](P& p) { p.voxel = 0; }), with([](P& p) { p.half_thickness = 0.4; }),
        with([](P& p) { p.normal_neighbours = 2; }), with([](P& p) { p.cell_neighbours = 0; }),
        with([](P& p) { p.max_cell_radius = -1; }), with([](P& p) { p.support_angle_deg = 90; }),
        with([](P& p) { p.cell_growth = 0.9; })})
    EXPECT_THROW(proxseg::mesh_from_points(points, p), proxseg::InputError);
  // A grid too large for memory is refused up front, not allocated.
  EXPECT_THROW(proxseg::mesh_from_points(points, with([](P& p) { p.voxel = 1e-5; })),
               proxseg::InputError);
}

// The quality of the 21 YCB-Video models' meshes, one table row each (on stdout):
// (a) every point within 3 mm of the surface; (b) the share of the mesh farther than 4 mm from
// every point within 7 points (percentage) of what the true surface would give
// (reference_far_share), and at most 5 % farther than 1 cm (a lid over the mug or a filled
// handle would be far more; the widest sampling gaps, 2-3 cm across on the pitcher, give 3.4 %);
// (c) see-through holes in 8 views at 0.6 m and 8 at 0.8 m, at most 1.5 % of any silhouette;
// (d) the bounding box within 7 mm of the points'; and under a second per model (Release).
TEST(PointMesh, YcbVideoModelsQuality) {
  ASSERT_TRUE(std::filesystem::exists(kYcb + "/classes.txt"))
      << "missing real data: " << kYcb << "/classes.txt (the YCB-Video models, PROXSEG_DATA_DIR)";
  std::vector<std::string> names = ycb_classes();
  ASSERT_EQ(names.size(), 21u);
  std::vector<double> distances{0.6, 0.8};
#ifdef PROXSEG_SANITIZE
  // The sanitizer build runs several times slower: the hard cases only, one distance.
  names = {"024_bowl", "025_mug", "037_scissors", "051_large_clamp"};
  distances = {0.7};
#endif
  std::printf("%-22s %6s %7s | %5s %5s | %5s %5s %5s %5s | %6s %5s | %5s | %4s\n", "model",
              "points", "tris", "a:max", "p99", "b:far", "ref", "far", "max", "c:hole", "mean",
              "d:box", "ms");
  std::printf("%-22s %6s %7s | %5s %5s | %5s %5s %5s %5s | %6s %5s | %5s | %4s\n", "", "", "", "mm",
              "mm", ">4mm%", ">4mm%", ">1cm%", "mm", "max%", "%", "mm", "");
  for (const std::string& name : names) {
    const std::string path = kYcb + "/models/" + name + "/points.xyz";
    ASSERT_TRUE(std::filesystem::exists(path)) << "missing real data: " << path;
    const std::vector<Vec3> points = proxseg::read_xyz(path);
    const auto start = std::chrono::steady_clock::now();
    const proxseg::Mesh mesh = proxseg::mesh_from_points(points);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

    std::vector<double> near = point_to_mesh(points, mesh, 0.01);
    std::sort(near.begin(), near.end());
    const FarSurface far = far_surface(mesh, points, 0.004);
    const double far10 = far_surface(mesh, points, 0.010).share;
    const double reference = reference_far_share(points, 0.004);
    const std::vector<double> holes = hole_shares(mesh, points, point_surfels(points), distances);
    double hole_max = 0, hole_mean = 0;
    for (double h : holes) hole_max = std::max(hole_max, h), hole_mean += h / holes.size();
    const double box = box_error(mesh, points);
    std::printf(
        "%-22s %6zu %7zu | %5.2f %5.2f | %5.1f %5.1f %5.2f %5.1f | %6.2f %5.2f | %5.1f | %4.0f\n",
        name.c_str(), points.size(), mesh.triangles.size(), near.back() * 1e3,
        near[near.size() * 99 / 100] * 1e3, far.share * 100, reference * 100, far10 * 100,
        far.max * 1e3, hole_max * 100, hole_mean * 100, box * 1e3, ms);
    std::fflush(stdout);

    EXPECT_LE(near.back(), 0.003) << name;
    EXPECT_LE(far.share, reference + 0.07) << name;
    EXPECT_LE(far10, 0.05) << name;
    EXPECT_LE(hole_max, 0.015) << name;
    EXPECT_LE(box, 0.007) << name;
    // The time is printed, not asserted: on a loaded machine a bound fails for no fault of the
    // code (speed is the benchmarks' to judge).
  }
}
