// Virtual depth camera: a z-buffer rasteriser of vertex-coloured triangle meshes, the mesh
// builders and the built-in synthetic tabletop scene.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/render.hpp>
#include "util/angles.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

namespace proxseg {
namespace {

constexpr double kNear = 0.01;  // metres; triangles with a vertex closer than this are skipped
using detail::kPi;

// Twice the signed area of (a, b, p). Evaluated with the endpoints in a canonical order so that
// two triangles sharing an edge get exactly opposite values: no cracks along shared edges.
inline double edge(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double px, double py) {
  const bool swap = b.x() < a.x() || (b.x() == a.x() && b.y() < a.y());
  const Eigen::Vector2d& s = swap ? b : a;
  const Eigen::Vector2d& t = swap ? a : b;
  const double e = (t.x() - s.x()) * (py - s.y()) - (t.y() - s.y()) * (px - s.x());
  return swap ? -e : e;
}

// Appends a (nu x nv)-quad grid patch: vertex (i, j) is at local point f(i / nu, j / nv).
template <class F>
void add_patch(Mesh& m, const Eigen::Isometry3d& pose, const ColourFn& colour, int nu, int nv,
               F f) {
  const int base = static_cast<int>(m.vertices.size());
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const Eigen::Vector3d p = f(double(i) / nu, double(j) / nv);
      m.vertices.push_back((pose * p).cast<float>());
      m.colours.push_back(colour(p));
    }
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int a = base + j * (nu + 1) + i, b = a + 1, c = a + nu + 2, d = a + nu + 1;
      m.triangles.emplace_back(a, b, c);
      m.triangles.emplace_back(a, c, d);
    }
}

int cells(double length, double cell) {
  if (!(cell > 0)) throw InputError("mesh builder: cell must be > 0");
  return std::max(1, static_cast<int>(std::ceil(length / cell - 1e-9)));
}

// Angle of the fraction u of a full turn; u = 1 maps exactly onto u = 0 (closed seam).
double turn(double u) {
  return 2 * kPi * (u < 1 ? u : 0);
}

}  // namespace

Mesh make_plane(const Eigen::Isometry3d& pose, const Eigen::Vector2d& size, const ColourFn& colour,
                double cell) {
  Mesh m;
  add_patch(m, pose, colour, cells(size.x(), cell), cells(size.y(), cell), [&](double u, double v) {
    return Eigen::Vector3d((u - 0.5) * size.x(), (v - 0.5) * size.y(), 0.0);
  });
  return m;
}

Mesh make_box(const Eigen::Isometry3d& pose, const Eigen::Vector3d& size, const ColourFn& colour,
              double cell) {
  Mesh m;
  for (int k = 0; k < 3; ++k)
    for (double side : {-0.5, 0.5}) {
      const int a = (k + 1) % 3, b = (k + 2) % 3;
      add_patch(m, pose, colour, cells(size[a], cell), cells(size[b], cell),
                [&](double u, double v) {
                  Eigen::Vector3d p;
                  p[k] = side * size[k];
                  p[a] = (u - 0.5) * size[a];
                  p[b] = (v - 0.5) * size[b];
                  return p;
                });
    }
  return m;
}

Mesh make_cylinder(const Eigen::Isometry3d& pose, double radius, double height,
                   const ColourFn& colour, double cell) {
  Mesh m;
  const int around = std::max(8, cells(2 * kPi * radius, cell));
  add_patch(m, pose, colour, around, cells(height, cell), [&](double u, double v) {
    return Eigen::Vector3d(radius * std::cos(turn(u)), radius * std::sin(turn(u)),
                           (v - 0.5) * height);
  });
  for (double side : {-0.5, 0.5})  // caps: polar grids (the centre triangles are degenerate)
    add_patch(m, pose, colour, cells(radius, cell), around, [&](double u, double v) {
      return Eigen::Vector3d(u * radius * std::cos(turn(v)), u * radius * std::sin(turn(v)),
                             side * height);
    });
  return m;
}

Mesh make_lathe(const Eigen::Isometry3d& pose, const std::vector<Eigen::Vector2d>& profile,
                const ColourFn& colour, double cell) {
  if (profile.size() < 2) throw InputError("make_lathe: the profile needs 2 points");
  // The profile resampled into pieces of about `cell`, so that rings are as dense as the
  // other builders' grids.
  std::vector<Eigen::Vector2d> rz = {profile[0]};
  double widest = 0;
  for (std::size_t i = 1; i < profile.size(); ++i) {
    if (profile[i].x() < 0) throw InputError("make_lathe: radius must be >= 0");
    const int n = cells((profile[i] - profile[i - 1]).norm(), cell);
    for (int k = 1; k <= n; ++k)
      rz.push_back(profile[i - 1] + (profile[i] - profile[i - 1]) * k / n);
    widest = std::max(widest, profile[i].x());
  }
  Mesh m;
  const int around = std::max(8, cells(2 * kPi * widest, cell));
  const int segments = static_cast<int>(rz.size()) - 1;
  add_patch(m, pose, colour, around, segments, [&](double u, double v) {
    const Eigen::Vector2d& q = rz[static_cast<std::size_t>(std::lround(v * segments))];
    return Eigen::Vector3d(q.x() * std::cos(turn(u)), q.x() * std::sin(turn(u)), q.y());
  });
  return m;
}

namespace {

// The points the sensor reports for the depth buffer: Kinect-like noise (its standard deviation
// grows with z^2), millimetre or disparity steps, back-projected through the camera.
void sensor_points(const std::vector<double>& zbuf, const RenderParams& params, Frame& f) {
  const Camera& cam = params.camera;
  const int W = cam.width, H = cam.height;
  std::mt19937 rng(params.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const std::size_t idx = static_cast<std::size_t>(v) * W + u;
      double depth = zbuf[idx];
      if (!std::isfinite(depth)) continue;
      if (params.depth_noise > 0) {  // Kinect-like: std grows with z^2
        depth += params.depth_noise * depth * depth * gauss(rng);
        if (params.disparity_step <= 0)
          depth = std::max(kNear, std::round(depth * 1000.0) / 1000.0);
      }
      if (params.disparity_step > 0) {  // the sensor's disparity steps
        const double steps = std::max(1.0, std::round(1.0 / (depth * params.disparity_step)));
        depth = std::max(kNear, 1.0 / (steps * params.disparity_step));
      }
      const Eigen::Vector3d ray((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
      f.xyz[idx] = (ray * depth).cast<float>();
    }
}

}  // namespace

Frame render(const std::vector<Mesh>& meshes, const RenderParams& params) {
  const Camera& cam = params.camera;
  if (cam.width <= 0 || cam.height <= 0 || !(cam.fx > 0) || !(cam.fy > 0))
    throw InputError("render: camera width, height, fx and fy must be > 0");
  const int W = cam.width, H = cam.height;
  const std::size_t n = static_cast<std::size_t>(W) * H;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  Frame f;
  f.width = W;
  f.height = H;
  f.xyz.assign(n, Eigen::Vector3f(nan, nan, nan));
  f.rgb.assign(n, Rgb{0, 0, 0});
  f.label.assign(n, 0);
  std::vector<double> zbuf(n, std::numeric_limits<double>::infinity());

  std::vector<Eigen::Vector2d> uv;
  std::vector<double> z;
  for (const Mesh& mesh : meshes) {
    const std::size_t nv = mesh.vertices.size();
    if (mesh.colours.size() != nv) throw InputError("render: mesh needs one colour per vertex");
    uv.resize(nv);
    z.resize(nv);
    for (std::size_t i = 0; i < nv; ++i) {
      const Eigen::Vector3d p = params.camera_from_world * mesh.vertices[i].cast<double>();
      z[i] = p.z();
      if (p.z() > kNear) uv[i] = {cam.fx * p.x() / p.z() + cam.cx, cam.fy * p.y() / p.z() + cam.cy};
    }
    for (const Eigen::Vector3i& t : mesh.triangles) {
      for (int k = 0; k < 3; ++k)
        if (t[k] < 0 || static_cast<std::size_t>(t[k]) >= nv)
          throw InputError("render: triangle vertex index out of range");
      const int i0 = t[0], i1 = t[1], i2 = t[2];
      if (z[i0] <= kNear || z[i1] <= kNear || z[i2] <= kNear) continue;
      const Eigen::Vector2d &a = uv[i0], &b = uv[i1], &c = uv[i2];
      const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
      if (!(std::abs(area) > 1e-12)) continue;  // degenerate or seen edge-on
      const int u0 = std::max(0, static_cast<int>(std::ceil(std::min({a.x(), b.x(), c.x()}))));
      const int u1 = std::min(W - 1, static_cast<int>(std::floor(std::max({a.x(), b.x(), c.x()}))));
      const int v0 = std::max(0, static_cast<int>(std::ceil(std::min({a.y(), b.y(), c.y()}))));
      const int v1 = std::min(H - 1, static_cast<int>(std::floor(std::max({a.y(), b.y(), c.y()}))));
      if (u0 > u1 || v0 > v1) continue;
      const double inv_area = 1.0 / area;
      // Screen-space barycentrics divided by vertex depth: interpolating 1/z is exactly the
      // intersection of the pixel ray with the triangle's plane (perspective-correct).
      const double q0 = inv_area / z[i0], q1 = inv_area / z[i1], q2 = inv_area / z[i2];
      const double zmin = std::min({z[i0], z[i1], z[i2]}), zmax = std::max({z[i0], z[i1], z[i2]});
      for (int v = v0; v <= v1; ++v)
        for (int u = u0; u <= u1; ++u) {
          const double w0 = edge(b, c, u, v), w1 = edge(c, a, u, v), w2 = edge(a, b, u, v);
          if (area > 0 ? (w0 < 0 || w1 < 0 || w2 < 0) : (w0 > 0 || w1 > 0 || w2 > 0)) continue;
          const double p0 = w0 * q0, p1 = w1 * q1, p2 = w2 * q2, inv_z = p0 + p1 + p2;
          const double depth = std::clamp(1.0 / inv_z, zmin, zmax);
          const std::size_t idx = static_cast<std::size_t>(v) * W + u;
          if (depth >= zbuf[idx]) continue;
          zbuf[idx] = depth;
          Rgb& out = f.rgb[idx];
          for (int ch = 0; ch < 3; ++ch) {
            const double col = (p0 * mesh.colours[i0][ch] + p1 * mesh.colours[i1][ch] +
                                p2 * mesh.colours[i2][ch]) /
                               inv_z;
            out[ch] = static_cast<std::uint8_t>(std::clamp(std::lround(col), 0L, 255L));
          }
          f.label[idx] = mesh.label;
        }
    }
  }

  sensor_points(zbuf, params, f);
  return f;
}

// ---------------------------------------------------------------------------------------------
// The synthetic tabletop scene (world: table top at z = 0, z up, camera on the -y side).

namespace {

Rgb rgb(double r, double g, double b) {
  auto c = [](double x) { return static_cast<std::uint8_t>(std::clamp(std::lround(x), 0L, 255L)); };
  return {c(r), c(g), c(b)};
}

Eigen::Isometry3d standing(double x, double y, double height, double yaw_deg) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translate(Eigen::Vector3d(x, y, height / 2));
  T.rotate(Eigen::AngleAxisd(detail::radians(yaw_deg), Eigen::Vector3d::UnitZ()));
  return T;
}

}  // namespace

std::vector<Mesh> synth_meshes(const SynthParams& params) {
  // Small per-object colour jitter: the seed changes only this and the depth noise.
  std::mt19937 rng(params.seed ^ 0x5EEDu);
  std::uniform_real_distribution<double> jit(-8.0, 8.0);
  auto tint = [&](double r, double g, double b) {
    const double d = jit(rng);
    return Eigen::Vector3d(r + d + jit(rng) / 2, g + d + jit(rng) / 2, b + d + jit(rng) / 2);
  };
  std::vector<Mesh> out;
  auto add = [&](Mesh m, std::uint32_t label) {
    m.label = label;
    out.push_back(std::move(m));
  };

  // 1: table top 1.2 m x 0.8 m, wood-like: grain along x plus a slow brightness drift.
  const Eigen::Vector3d wood = tint(165, 115, 72);
  Eigen::Isometry3d table = Eigen::Isometry3d::Identity();
  table.translate(Eigen::Vector3d(0, 0.0, 0));
  add(make_plane(
          table, {1.2, 0.8},
          [&](const Eigen::Vector3d& p) {
            const double grain =
                0.06 * std::sin(2 * kPi * (p.y() + 0.01 * std::sin(6 * p.x())) / 0.045);
            const double drift = 0.08 * std::sin(2 * kPi * p.x() / 0.9 + 1.0) * std::cos(3 * p.y());
            const double s = 1 + grain + drift;
            return rgb(wood.x() * s, wood.y() * s, wood.z() * s);
          },
          0.01),
      1);

  // 2: red box, turned 25 degrees.
  const Eigen::Vector3d red = tint(200, 35, 30);
  add(make_box(standing(-0.26, 0.04, 0.16, 25), {0.10, 0.07, 0.16},
               [&](const Eigen::Vector3d&) { return rgb(red.x(), red.y(), red.z()); }),
      2);
  // 3: blue-and-white striped box (1.5 cm vertical stripes) ...
  const Eigen::Vector3d blue = tint(30, 60, 190);
  add(make_box(standing(-0.08, -0.02, 0.09, 0), {0.12, 0.09, 0.09},
               [&](const Eigen::Vector3d& p) {
                 const bool b = static_cast<int>(std::floor((p.x() + p.y()) / 0.015)) % 2 == 0;
                 return b ? rgb(blue.x(), blue.y(), blue.z()) : rgb(235, 235, 235);
               }),
      3);
  // 4: ... touching a green box with a 2 cm checkerboard.
  const Eigen::Vector3d green = tint(40, 150, 60);
  add(make_box(standing(0.05, -0.01, 0.07, 0), {0.14, 0.10, 0.07},
               [&](const Eigen::Vector3d& p) {
                 const int k =
                     static_cast<int>(std::floor(p.x() / 0.02) + std::floor(p.y() / 0.02) +
                                      std::floor(p.z() / 0.02));
                 const double s = (k & 1) ? 1.0 : 0.55;
                 return rgb(green.x() * s, green.y() * s, green.z() * s);
               }),
      4);
  // 5: yellow can with a silver lid.
  const Eigen::Vector3d yellow = tint(230, 200, 35);
  const double can_h = 0.12;
  add(make_cylinder(standing(0.18, 0.08, can_h, 0), 0.035, can_h,
                    [&](const Eigen::Vector3d& p) {
                      if (p.z() > can_h / 2 - 1e-6) return rgb(185, 185, 190);
                      return rgb(yellow.x(), yellow.y(), yellow.z());
                    }),
      5);
  // 6: white/grey bottle-like cylinder with a printed red band (with thin dark lines).
  const Eigen::Vector3d band = tint(190, 40, 45);
  const double cyl_h = 0.18;
  add(make_cylinder(standing(0.05, 0.16, cyl_h, 0), 0.04, cyl_h,
                    [&](const Eigen::Vector3d& p) {
                      const double h = p.z() + cyl_h / 2;
                      if (h > cyl_h - 1e-6) return rgb(150, 150, 155);
                      if (h > 0.07 && h < 0.12) {
                        const double a = std::atan2(p.y(), p.x());
                        const bool line = std::fmod(std::abs(a) * 6, 1.0) < 0.12;
                        return line ? rgb(60, 20, 20) : rgb(band.x(), band.y(), band.z());
                      }
                      return rgb(225, 225, 222);
                    }),
      6);
  return out;
}

Eigen::Isometry3d look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d forward = (target - eye).normalized();
  // Image x to the right of the world's z-up; straight up or down, the world's x is used.
  Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ());
  if (right.norm() < 1e-6) right = forward.cross(Eigen::Vector3d::UnitX());
  right.normalize();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Isometry3d world_from_camera = Eigen::Isometry3d::Identity();
  world_from_camera.linear().col(0) = right;
  world_from_camera.linear().col(1) = down;
  world_from_camera.linear().col(2) = forward;
  world_from_camera.translation() = eye;
  return world_from_camera.inverse();
}

std::vector<Eigen::Vector3d> view_sphere(int n) {
  std::vector<Eigen::Vector3d> dirs;
  const double golden = kPi * (3 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1 - (2 * i + 1.0) / n, r = std::sqrt(std::max(0.0, 1 - z * z));
    dirs.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  return dirs;
}

std::vector<RenderedView> render_views(const Mesh& mesh, const ViewSphereParams& params) {
  if (params.views < 1) throw InputError("render_views: views must be >= 1");
  if (mesh.vertices.empty()) throw InputError("render_views: empty mesh");
  Eigen::Vector3d lo = mesh.vertices[0].cast<double>(), hi = lo;
  for (const auto& v : mesh.vertices) {
    lo = lo.cwiseMin(v.cast<double>());
    hi = hi.cwiseMax(v.cast<double>());
  }
  const Eigen::Vector3d centre = (lo + hi) / 2;
  const double distance =
      params.distance > 0 ? params.distance : std::max(0.6, 3 * (hi - lo).norm());
  std::vector<RenderedView> out;
  const auto dirs = view_sphere(params.views);
  for (int i = 0; i < params.views; ++i) {
    RenderParams rp;
    rp.camera = params.camera;
    rp.depth_noise = params.depth_noise;
    rp.disparity_step = params.disparity_step;
    rp.seed = params.seed + static_cast<std::uint32_t>(i);
    const Eigen::Vector3d eye = centre + distance * dirs[i];
    rp.camera_from_world = look_at(eye, centre);
    const Frame image = render({mesh}, rp);
    const Eigen::Isometry3d world_from_camera = rp.camera_from_world.inverse();
    RenderedView v;
    v.eye = eye;
    v.points.height = 1;
    for (std::size_t k = 0; k < image.size(); ++k) {
      if (!image.valid(k)) continue;
      v.points.xyz.push_back((world_from_camera * image.xyz[k].cast<double>()).cast<float>());
      v.points.rgb.push_back(image.rgb[k]);
    }
    v.points.width = static_cast<int>(v.points.xyz.size());
    out.push_back(std::move(v));
  }
  return out;
}

RenderParams synth_render_params(const SynthParams& params) {
  // Camera 1.05 m from a point just above the table centre, looking down at 40 degrees.
  const double tilt = detail::radians(40), dist = 1.05;
  const Eigen::Vector3d target(0.0, 0.0, 0.04);
  const Eigen::Vector3d forward(0, std::cos(tilt), -std::sin(tilt));
  RenderParams rp;
  rp.camera_from_world = look_at(target - dist * forward, target);
  rp.depth_noise = params.depth_noise;
  rp.seed = params.seed;
  return rp;
}

Frame synth_scene(const SynthParams& params) {
  return render(synth_meshes(params), synth_render_params(params));
}

}  // namespace proxseg
