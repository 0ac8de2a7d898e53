// The capture of a cluttered scene: the camera search, the full render, the table's pixels, the
// sensor's colour noise and the visible points (clutter/capture.hpp).
#include "eval/clutter/capture.hpp"

#include <proxseg/core/colour.hpp>
#include <proxseg/core/render.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "eval/clutter/objects.hpp"
#include "util/angles.hpp"

namespace proxseg::clutter {

using detail::kPi;

namespace {

constexpr double kTableCell = 0.05;  // table tessellation (textured per pixel)

// The camera at a quarter of the resolution: the quick render of the camera search.
Camera quarter(const Camera& cam) {
  Camera small = cam;
  small.width = cam.width / 4;
  small.height = cam.height / 4;
  small.fx = cam.fx / 4;
  small.fy = cam.fy / 4;
  small.cx = (cam.cx + 0.5) / 4 - 0.5;
  small.cy = (cam.cy + 0.5) / 4 - 0.5;
  return small;
}

// The nearest distance, in 2 cm steps from min_distance, at which every corner is in the image
// with a 12 px margin; max_distance if none is.
double nearest_in_view(const ClutterParams& P, const std::vector<Vec3>& corners, const Vec3& target,
                       const Vec3& back) {
  const Camera& cam = P.camera;
  auto all_in_view = [&](double d) {
    const Eigen::Isometry3d T = look_at(target + d * back, target);
    for (const Vec3& w : corners) {
      const Vec3 q = T * w;
      if (q.z() < 0.05) return false;
      const double u = cam.fx * q.x() / q.z() + cam.cx, v = cam.fy * q.y() / q.z() + cam.cy;
      if (u < 12 || u > cam.width - 13 || v < 12 || v > cam.height - 13) return false;
    }
    return true;
  };
  double d_lo = P.max_distance;
  for (double d = P.min_distance; d < P.max_distance; d += 0.02)
    if (all_in_view(d)) {
      d_lo = d;
      break;
    }
  return d_lo;
}

// Whether a quick render (camera small) shows every one of n objects with 1.2 x
// min_visible_points, scaled to the full resolution (x 16).
bool shows_every_object(const ClutterParams& P, const std::vector<Mesh>& meshes,
                        const Camera& small, const Vec3& eye, const Vec3& target, std::size_t n) {
  RenderParams quick;
  quick.camera = small;
  quick.camera_from_world = look_at(eye, target);
  const Frame q = render(meshes, quick);
  std::vector<std::size_t> count(n, 0);
  for (std::size_t i = 0; i < q.size(); ++i)
    if (const int o = object_index(q.label[i], n); o >= 0) ++count[static_cast<std::size_t>(o)];
  return *std::min_element(count.begin(), count.end()) * 16 >= 1.2 * P.min_visible_points;
}

// The table's colours, per pixel: the pixel's ray meets the plane z = 0 at p; the texture is
// filtered over the pixel's footprint there (its longer axis), then shaded (normal +z).
void colour_table(const Stage& stage, ClutterScene& out) {
  Frame& f = out.frame;
  const Camera& cam = out.render.camera;
  const Eigen::Matrix3d world_from_camera = out.render.camera_from_world.linear().transpose();
  const double table_b =
      stage.exposure * (stage.ambient + (1 - stage.ambient) * std::max(0.0, stage.light.z()));
  for (int v = 0; v < f.height; ++v)
    for (int u = 0; u < f.width; ++u) {
      const std::size_t k = static_cast<std::size_t>(v) * f.width + u;
      if (f.label[k] != 1) continue;
      const Vec3 dir = world_from_camera * Vec3((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
      if (dir.z() >= -1e-9) continue;
      const double t = -out.eye.z() / dir.z();
      const Vec3 p = out.eye + t * dir;
      const double range = t * dir.norm(), cos_inc = -dir.z() / dir.norm();
      const double w = range / (cam.fx * std::max(cos_inc, 0.02));
      f.rgb[k] = to_rgb8(stage.table_colour(Vec2(p.x(), p.y()), w) * table_b);
    }
}

// Sensor noise on the colours: normal draws of std colour_noise from a seeded table of 4096
// values.
void add_colour_noise(Frame& f, double colour_noise, std::uint64_t salt) {
  Rng noise{SplitMix{salt}};
  std::vector<double> gauss(4096);
  for (double& g : gauss) g = colour_noise * noise.normal();
  for (std::size_t k = 0; k < f.size(); ++k) {
    if (!f.valid(k)) continue;
    Rgb& c = f.rgb[k];
    const std::uint64_t bits = noise.next();
    for (int ch = 0; ch < 3; ++ch)
      c[ch] = static_cast<std::uint8_t>(
          std::clamp(std::lround(c[ch] + gauss[(bits >> (12 * ch)) & 4095]), 0L, 255L));
  }
}

// Every object's visible_points; false if some object shows fewer than min_visible_points.
bool count_visible(const ClutterParams& P, ClutterScene& out) {
  const Frame& f = out.frame;
  const std::size_t n = out.objects.size();
  std::vector<std::size_t> visible(n, 0);
  for (std::size_t k = 0; k < f.size(); ++k)
    if (f.valid(k))
      if (const int o = object_index(f.label[k], n); o >= 0) ++visible[static_cast<std::size_t>(o)];
  bool ok = true;
  for (std::size_t i = 0; i < n; ++i) {
    out.objects[i].visible_points = visible[i];
    ok = ok && visible[i] >= static_cast<std::size_t>(P.min_visible_points);
  }
  return ok;
}

}  // namespace

bool choose_camera(Rng& r, const ClutterParams& P, const std::vector<Mesh>& meshes,
                   const std::vector<Vec3>& corners, const Vec2& area_centre, double view_az,
                   ClutterScene& out) {
  constexpr int kCameras = 6;
  const Camera small = quarter(P.camera);
  bool found = false;
  for (int k = 0; k < kCameras && !found; ++k) {
    const double el = detail::radians(r.u(P.min_elevation_deg, P.max_elevation_deg));
    const double az = P.p_front > 0 ? view_az + r.u(-1, 1) * kPi / 12 : r.u(0, 2 * kPi);
    const Vec3 target(area_centre.x() + r.u(-1, 1) * P.target_jitter,
                      area_centre.y() + r.u(-1, 1) * P.target_jitter, r.u(0.02, 0.06));
    const Vec3 back(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    const double d_lo = nearest_in_view(P, corners, target, back);
    const double dist = r.u(d_lo, P.max_distance);
    found = shows_every_object(P, meshes, small, target + dist * back, target, out.objects.size());
    out.target = target;
    out.eye = target + dist * back;
    out.elevation_deg = detail::degrees(el);
    out.azimuth_deg = detail::degrees(az);
  }
  return found;
}

bool capture(Rng& r, const ClutterParams& P, const Stage& stage, std::vector<Mesh>& meshes,
             ClutterScene& out) {
  out.render = RenderParams{};
  out.render.camera = P.camera;
  out.render.camera_from_world = look_at(out.eye, out.target);
  out.render.depth_noise = P.depth_noise;
  out.render.disparity_step = P.disparity_step;
  out.render.seed = static_cast<std::uint32_t>(r.next() >> 32);
  const std::uint64_t colour_salt = r.next();
  // The table (centred on the world origin) only for depth and labels: its colours are set per
  // pixel by colour_table.
  meshes.push_back(make_plane(
      Eigen::Isometry3d::Identity(), {stage.table_w, stage.table_d},
      [](const Vec3&) {
        return Rgb{128, 128, 128};
      },
      kTableCell));
  meshes.back().label = 1;
  out.frame = render(meshes, out.render);
  colour_table(stage, out);
  if (P.colour_noise > 0) add_colour_noise(out.frame, P.colour_noise, colour_salt);
  return count_visible(P, out);
}

}  // namespace proxseg::clutter
