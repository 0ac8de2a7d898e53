// Seeded cluttered tabletop scenes: layout on the table by 2D footprints with collision checks,
// procedural textures, baked Lambertian shading, rendering through render() (docs/clutter.md).
#include <proxseg/core/colour.hpp>
#include <proxseg/eval/clutter.hpp>
#include <proxseg/io/cloud_io.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>

#include "util/angles.hpp"
#include "util/splitmix.hpp"
#include "util/value_noise.hpp"

namespace proxseg {

const char* to_string(ClutterKind k) {
  switch (k) {
    case ClutterKind::mesh:
      return "mesh";
    case ClutterKind::box:
      return "box";
    case ClutterKind::cylinder:
      return "cylinder";
  }
  return "?";
}

const char* to_string(ClutterPose p) {
  switch (p) {
    case ClutterPose::standing:
      return "standing";
    case ClutterPose::lying:
      return "lying";
    case ClutterPose::stacked:
      return "stacked";
    case ClutterPose::leaning:
      return "leaning";
  }
  return "?";
}

namespace {

namespace fs = std::filesystem;
using detail::kPi;
constexpr double kBoxCell = 0.004;         // object tessellation, metres (textures are per vertex)
constexpr double kTableCell = 0.05;        // table tessellation (textured per pixel)
constexpr int kMaxCatalogueInstances = 2;  // of one catalogue entry per scene
using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Poly = std::vector<Vec2>;  // convex, counter-clockwise
using Col = Eigen::Vector3d;     // 0..255 per channel

// ---------------------------------------------------------------------------------------------
// Random numbers: splitmix64 only (std:: distributions differ between standard libraries).

struct Rng {
  SplitMix s;
  std::uint64_t next() { return s.next(); }
  double u() { return s.uniform(); }
  double u(double lo, double hi) { return s.uniform(lo, hi); }
  int i(int lo, int hi) {  // inclusive
    return lo + static_cast<int>(s.next() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  bool p(double probability) { return s.uniform() < probability; }
  double normal() { return s.normal(); }
};

// Independent sub-stream k of a seed.
Rng stream(std::uint32_t seed, std::uint64_t k) {
  return Rng{SplitMix{mix64(mix64(seed + 0x632be59bd9b4e019ull) ^ (k * 0x9e3779b97f4a7c15ull))}};
}

// Three octaves, in [0, 1]; scale = lattice spacing of the first octave (metres).
double fbm(const Vec3& p, double scale, std::uint64_t salt) {
  double sum = 0, amp = 1, norm = 0, f = 1 / scale;
  for (int o = 0; o < 3; ++o, amp *= 0.5, f *= 2) {
    sum += amp * vnoise(p * f, salt + static_cast<std::uint64_t>(o) * 0x51ed27ull);
    norm += amp;
  }
  return sum / norm;
}

double frac(double x) {
  return x - std::floor(x);
}

// ---------------------------------------------------------------------------------------------
// Colours.

Col hsv(double h, double s, double v) {
  return hsv_to_rgb({h, s, v});
}

// Packaging-like colours: a fifth nearly unsaturated (white, grey, black), the rest saturated.
Col random_colour(Rng& r) {
  if (r.p(0.2)) {
    const double v = r.p(0.5) ? r.u(0.75, 0.95) : r.u(0.1, 0.55);
    return hsv(r.u(), r.u(0, 0.12), v);
  }
  return hsv(r.u(), r.u(0.35, 0.95), r.u(0.35, 0.95));
}

Col mix(const Col& a, const Col& b, double t) {
  return a + (b - a) * t;
}

// A second colour that stands out from c (different hue or brightness).
Col contrast_colour(Rng& r, const Col& c) {
  for (int k = 0; k < 8; ++k) {
    const Col d = random_colour(r);
    if ((d - c).norm() > 110) return d;
  }
  return c.mean() > 128 ? Col(25, 25, 30) : Col(235, 235, 230);
}

// ---------------------------------------------------------------------------------------------
// 2D geometry of the footprints (table plane).

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

double seg_dist(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-30), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

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

// ---------------------------------------------------------------------------------------------
// LINEMOD meshes: listed per call, read once per process (cache keyed by path, size, mtime).

struct CachedMesh {
  std::uintmax_t size = 0;
  fs::file_time_type mtime;
  std::shared_ptr<const Mesh> mesh;
};

std::shared_ptr<const Mesh> cached_mesh(const std::string& path) {
  static std::mutex m;
  static std::map<std::string, CachedMesh> cache;
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  const fs::file_time_type mtime = fs::last_write_time(path, ec);
  {
    std::lock_guard<std::mutex> lock(m);
    const auto it = cache.find(path);
    if (it != cache.end() && it->second.size == size && it->second.mtime == mtime)
      return it->second.mesh;
  }
  auto mesh = std::make_shared<const Mesh>(read_mesh(path, 0.001));  // millimetres
  std::lock_guard<std::mutex> lock(m);
  cache[path] = {size, mtime, mesh};
  return mesh;
}

std::vector<std::string> list_models(const std::string& dir) {
  std::vector<std::string> out;
  if (dir.empty()) return out;
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError(dir + ": models folder not found (expected LINEMOD obj_*.ply meshes)");
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("obj_", 0) == 0 && e.path().extension() == ".ply")
      out.push_back(e.path().string());
  }
  if (ec) throw InputError(dir + ": cannot list the models folder (" + ec.message() + ")");
  if (out.empty()) throw InputError(dir + ": no obj_*.ply meshes in the models folder");
  std::sort(out.begin(), out.end());
  return out;
}

// ---------------------------------------------------------------------------------------------
// Textures. Every ColourFn captures its parameters by value.

ColourFn plain_texture(Rng& r, const Col& base) {
  const std::uint64_t salt = r.next();
  const double scale = r.u(0.03, 0.08), amount = r.u(0.02, 0.06);
  return
      [=](const Vec3& p) { return to_rgb8(base * (1 + amount * (2 * fbm(p, scale, salt) - 1))); };
}

ColourFn stripes_texture(Rng& r, const Col& a) {
  const Col b = contrast_colour(r, a);
  static const std::array<Vec3, 6> dirs = {Vec3(1, 0, 0),
                                           Vec3(0, 1, 0),
                                           Vec3(0, 0, 1),
                                           Vec3(1, 1, 0).normalized(),
                                           Vec3(0, 1, 1).normalized(),
                                           Vec3(1, 0, 1).normalized()};
  const Vec3 d = dirs[static_cast<std::size_t>(r.i(0, 5))];
  const double width = r.u(0.012, 0.035), duty = r.u(0.3, 0.7),
               phase = r.u();  // period >= 3 vertices
  return [=](const Vec3& p) { return to_rgb8(frac(p.dot(d) / width + phase) < duty ? a : b); };
}

ColourFn checker_texture(Rng& r, const Col& a) {
  const Col b = r.p(0.5) ? contrast_colour(r, a) : Col(a * r.u(0.45, 0.7));
  const double c = r.u(0.012, 0.04);
  return [=](const Vec3& p) {
    const auto k =
        static_cast<long>(std::floor(p.x() / c) + std::floor(p.y() / c) + std::floor(p.z() / c));
    return to_rgb8((k & 1) ? a : b);
  };
}

ColourFn blotches_texture(Rng& r, const Col& a) {
  const Col b = contrast_colour(r, a), c = mix(a, b, r.u(0.3, 0.7)) * r.u(0.7, 1.0);
  const std::uint64_t salt = r.next();
  const double scale = r.u(0.015, 0.05), t1 = r.u(0.42, 0.52), t2 = t1 + r.u(0.06, 0.12);
  return [=](const Vec3& p) {
    const double n = fbm(p, scale, salt);
    const double w1 = std::clamp((n - t1) / 0.03 + 0.5, 0.0, 1.0);
    const double w2 = std::clamp((n - t2) / 0.03 + 0.5, 0.0, 1.0);
    return to_rgb8(mix(mix(a, b, w1), c, w2));
  };
}

// A printed label on a 2D patch: paper rectangle with rows of "text" (dark bars of random
// lengths) and a coloured logo square. Coordinates in metres relative to the rectangle's centre.
struct Label {
  bool on = false;
  double cu = 0, cv = 0, hu = 0, hv = 0;  // centre, half extents on the patch
  Col paper, ink, logo;
  bool rows_along_u = true;
  double pitch = 0.014, thick = 0.006, logo_u = 0, logo_v = 0, logo_r = 0;
  std::uint64_t salt = 0;

  // The colour at (u, v) if inside the label.
  bool colour(double u, double v, Col& out) const {
    if (!on || std::abs(u - cu) > hu || std::abs(v - cv) > hv) return false;
    const double lu = u - cu, lv = v - cv;
    if (std::abs(lu - logo_u) < logo_r && std::abs(lv - logo_v) < logo_r) {
      out = logo;
      return true;
    }
    const double across = rows_along_u ? lv + hv : lu + hu,
                 along = rows_along_u ? lu + hu : lv + hv;
    const double length = 2 * (rows_along_u ? hu : hv);
    const double row = std::floor(across / pitch);
    const double row_len =
        length * (0.35 + 0.55 * noise_lattice(static_cast<std::int64_t>(row), 0, 0, salt));
    const bool text = row >= 1 && frac(across / pitch) * pitch < thick && along > 0.1 * length &&
                      along < 0.1 * length + row_len * 0.85;
    out = text ? ink : paper;
    return true;
  }
};

Label random_label(Rng& r, double half_u, double half_v, const Col& base) {
  Label l;
  if (half_u < 0.015 || half_v < 0.015) return l;
  l.on = true;
  l.hu = half_u * r.u(0.5, 0.85);
  l.hv = half_v * r.u(0.5, 0.85);
  l.cu = r.u(-1, 1) * (half_u - l.hu - 0.003);
  l.cv = r.u(-1, 1) * (half_v - l.hv - 0.003);
  l.paper = r.p(0.7) ? hsv(r.u(), r.u(0, 0.15), r.u(0.8, 0.97)) : contrast_colour(r, base);
  l.ink = l.paper.mean() > 128 ? hsv(r.u(), r.u(0, 0.6), r.u(0.05, 0.3)) : Col(235, 235, 235);
  l.logo = contrast_colour(r, l.paper);
  l.rows_along_u = half_u >= half_v;
  l.pitch = r.u(0.011, 0.018);
  l.thick = l.pitch * r.u(0.35, 0.5);
  l.logo_r = std::min(l.hu, l.hv) * r.u(0.15, 0.35);
  l.logo_u = r.u(-1, 1) * (l.hu - l.logo_r);
  l.logo_v = r.u(-1, 1) * (l.hv - l.logo_r);
  l.salt = r.next();
  return l;
}

// Labels on the faces of a box: face f = 2 * axis + (positive side).
ColourFn label_box_texture(Rng& r, const Col& base, const Vec3& size) {
  const Vec3 half = size / 2;
  std::array<Label, 6> labels;
  for (int f = 0; f < 6; ++f) {
    const int k = f / 2, a = (k + 1) % 3, b = (k + 2) % 3;
    if (r.p(0.8)) labels[static_cast<std::size_t>(f)] = random_label(r, half[a], half[b], base);
  }
  const ColourFn background = plain_texture(r, base);
  return [=](const Vec3& p) {
    int k = 0;
    for (int j = 1; j < 3; ++j)
      if (std::abs(p[j]) / half[j] > std::abs(p[k]) / half[k]) k = j;
    const int a = (k + 1) % 3, b = (k + 2) % 3;
    Col c;
    if (labels[static_cast<std::size_t>(2 * k + (p[k] > 0))].colour(p[a], p[b], c))
      return to_rgb8(c);
    return background(p);
  };
}

// Box: plain, stripes, checker, blotches or label.
ColourFn box_texture(Rng& r, const Vec3& size, std::string& name) {
  const Col base = random_colour(r);
  const double u = r.u();
  if (u < 0.2) return name = "plain", plain_texture(r, base);
  if (u < 0.4) return name = "stripes", stripes_texture(r, base);
  if (u < 0.55) return name = "checker", checker_texture(r, base);
  if (u < 0.7) return name = "blotches", blotches_texture(r, base);
  return name = "label", label_box_texture(r, base, size);
}

// Cylinder (axis z, -h/2..h/2): plain, bands, vertical stripes, blotches or a label band; the
// caps may be a lid of another colour.
ColourFn cylinder_texture(Rng& r, double radius, double height, std::string& name) {
  const Col base = random_colour(r), other = contrast_colour(r, base);
  const bool lid = r.p(0.5);
  const Col lid_colour = r.p(0.5) ? hsv(0, 0, r.u(0.55, 0.8)) : other;
  const double u = r.u();
  ColourFn side;
  if (u < 0.2) {
    name = "plain";
    side = plain_texture(r, base);
  } else if (u < 0.4) {
    name = "bands";
    const double w = r.u(0.012, 0.035), duty = r.u(0.3, 0.7);
    side = [=](const Vec3& p) { return to_rgb8(frac(p.z() / w) < duty ? base : other); };
  } else if (u < 0.55) {
    name = "stripes";
    const int k = r.i(4, 12);
    side = [=](const Vec3& p) {
      const double a = std::atan2(p.y(), p.x()) / (2 * kPi) + 0.5;
      return to_rgb8(static_cast<int>(std::floor(a * 2 * k)) % 2 ? base : other);
    };
  } else if (u < 0.7) {
    name = "blotches";
    side = blotches_texture(r, base);
  } else {
    name = "label";
    const double circumference = 2 * kPi * radius;
    Label l = random_label(r, circumference / 2, height / 2, base);
    l.hu = circumference / 2 + 1;  // all around
    l.cu = 0;
    l.rows_along_u = true;
    const ColourFn background = plain_texture(r, base);
    side = [=](const Vec3& p) {
      const double s = std::atan2(p.y(), p.x()) * radius;  // arc length, -C/2..C/2
      Col c;
      if (l.colour(s, p.z(), c)) return to_rgb8(c);
      return background(p);
    };
  }
  const double cap = height / 2 - 1e-6;
  return [=](const Vec3& p) {
    if (lid && std::abs(p.z()) > cap && std::hypot(p.x(), p.y()) < radius * 0.999)
      return to_rgb8(lid_colour);
    return side(p);
  };
}

// Box-filtered periodic pulse: the mean over [x - w/2, x + w/2] of [frac(x) < duty] (period 1).
double pulse(double x, double duty, double w) {
  auto integral = [duty](double t) { return std::floor(t) * duty + std::min(frac(t), duty); };
  if (w < 1e-6) return frac(x) < duty ? 1.0 : 0.0;
  return (integral(x + w / 2) - integral(x - w / 2)) / w;
}

// Table colour at a point of the table plane, box-filtered over w metres (the pixel's footprint):
// the table is textured per pixel after rendering, so that fine patterns do not alias.
using TableFn = std::function<Col(const Vec2& p, double w)>;

// Table top: wood (planks, rings perturbed by noise), checked cloth (gingham) or plain.
TableFn table_texture(Rng& r, const std::string& kind) {
  if (kind == "wood") {
    const Col base = hsv(r.u(0.05, 0.1), r.u(0.35, 0.65), r.u(0.45, 0.85));
    const double plank = r.u(0.09, 0.2), period = r.u(0.012, 0.03), yaw = r.p(0.5) ? 0 : kPi / 2;
    const double contrast = r.u(0.1, 0.22);
    const std::uint64_t salt = r.next();
    const Eigen::Matrix2d R = rot2(yaw);
    return [=](const Vec2& p, double w) {
      const Vec2 q = R * p;  // q.x along the planks
      const double row = std::floor(q.y() / plank), v = q.y() - row * plank;
      const auto ri = static_cast<std::int64_t>(row);
      // Each plank: its own ring axis (offset across, depth below the surface), shift, tint.
      const double axis = plank * (noise_lattice(ri, 1, 0, salt) * 1.6 - 0.3);
      const double depth = 0.01 + 0.08 * noise_lattice(ri, 2, 0, salt);
      const double tint = 1 + 0.12 * (noise_lattice(ri, 3, 0, salt) - 0.5);
      const double shift = 3 * noise_lattice(ri, 4, 0, salt);
      const Vec3 s(q.x() + shift, v + row * 7.3, 0);
      const double wobble = 0.02 * (fbm(Vec3(s.x() * 0.15, s.y(), 0), 0.05, salt + 5) - 0.5);
      const double rr = std::hypot(v - axis + wobble, depth);
      // Rings: a cosine of rr (whose period on the surface is >= period), attenuated as a
      // Gaussian of std w / 2 would.
      const double fade = std::exp(-0.5 * std::pow(kPi * w / period, 2));
      const double ring =
          0.5 + 0.5 * fade * std::cos(2 * kPi * (rr / period + 2.5 * fbm(s, 0.2, salt + 9)));
      const double streak = (fbm(Vec3(s.x() * 0.05, s.y() * 2, 0), 0.01, salt + 11) - 0.5) *
                            std::exp(-std::pow(w / 0.005, 2));
      const double seam = pulse((q.y() + 0.002) / plank, 0.004 / plank, w / plank);
      const double b = tint * (1 - contrast * ring + 0.1 * streak) * (1 - 0.45 * seam);
      return Col(base * b);
    };
  }
  if (kind == "cloth") {
    const Col ground = hsv(r.u(), r.u(0, 0.08), r.u(0.85, 0.97));
    const Col colour = hsv(r.u(), r.u(0.5, 0.9), r.u(0.35, 0.8));
    const double check = r.u(0.015, 0.04), yaw = r.u(0, kPi / 2);
    const std::uint64_t salt = r.next();
    const Eigen::Matrix2d R = rot2(yaw);
    return [=](const Vec2& p, double w) {
      const Vec2 q = R * p / check;
      // Gingham: 0, 1 or 2 coloured stripes over a point -> ground, half, full colour.
      const double n = pulse(q.x(), 0.5, w / check) + pulse(q.y(), 0.5, w / check);
      const double weave = 1 + 0.05 * (fbm(Vec3(p.x(), p.y(), 0), 0.004, salt) - 0.5) *
                                   std::exp(-std::pow(w / 0.004, 2));
      return Col(mix(ground, colour, n / 2) * weave);
    };
  }
  const Col base = r.p(0.5) ? hsv(r.u(), r.u(0, 0.15), r.u(0.45, 0.9))    // grey, white, beige
                            : hsv(r.u(), r.u(0.25, 0.6), r.u(0.3, 0.6));  // felt, laminate
  const std::uint64_t salt = r.next();
  return [=](const Vec2& p, double) {
    return Col(base * (1 + 0.05 * (fbm(Vec3(p.x(), p.y(), 0), 0.2, salt) - 0.5)));
  };
}

// ---------------------------------------------------------------------------------------------
// Objects: a prototype (its mesh in its own frame) and its resting shape.

struct Proto {
  ClutterKind kind = ClutterKind::box;
  std::string name, texture;
  Vec3 size = Vec3::Zero();
  Mesh mesh;           // object frame, unshaded colours
  bool convex = true;  // box or cylinder: normals face away from the centre
  int catalogue = -1;  // ClutterParams::catalogue entry, -1 = drawn at random
};

Proto box_proto(Rng& r, const Vec3& size, const std::string& name) {
  Proto p;
  p.kind = ClutterKind::box;
  p.name = name;
  p.size = size;
  const ColourFn tex = box_texture(r, size, p.texture);
  p.mesh = make_box(Eigen::Isometry3d::Identity(), size, tex, kBoxCell);
  return p;
}

Proto cylinder_proto(Rng& r, double radius, double height, const std::string& name) {
  Proto p;
  p.kind = ClutterKind::cylinder;
  p.name = name;
  p.size = Vec3(2 * radius, 2 * radius, height);
  const ColourFn tex = cylinder_texture(r, radius, height, p.texture);
  p.mesh = make_cylinder(Eigen::Isometry3d::Identity(), radius, height, tex, kBoxCell);
  return p;
}

Proto mesh_proto(Rng& r, const std::string& path, double jitter, double recolour) {
  Proto p;
  p.kind = ClutterKind::mesh;
  p.name = fs::path(path).stem().string();
  p.texture = "scan";
  p.convex = false;
  p.mesh = *cached_mesh(path);
  const double scale = r.u(1 - jitter, 1 + jitter);
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (auto& v : p.mesh.vertices) {
    v *= static_cast<float>(scale);
    lo = lo.cwiseMin(v.cast<double>());
    hi = hi.cwiseMax(v.cast<double>());
  }
  p.size = hi - lo;
  if (r.p(recolour)) {
    const Col gain(r.u(0.6, 1.4), r.u(0.6, 1.4), r.u(0.6, 1.4));
    p.texture = "scan, tinted";
    for (auto& c : p.mesh.colours) c = to_rgb8(Col(c[0], c[1], c[2]).cwiseProduct(gain));
  }
  return p;
}

// A catalogue entry exactly as given: no scale jitter, no recolouring.
Proto catalogue_proto(const std::vector<CatalogueObject>& catalogue, int index) {
  const CatalogueObject& e = catalogue[static_cast<std::size_t>(index)];
  Proto p;
  p.kind = e.kind;
  p.name = e.name;
  p.texture = "catalogue";
  p.convex = e.convex;
  p.catalogue = index;
  p.mesh = e.mesh;
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const auto& v : p.mesh.vertices) {
    lo = lo.cwiseMin(v.cast<double>());
    hi = hi.cwiseMax(v.cast<double>());
  }
  p.size = hi - lo;
  return p;
}

// Resting shape for a tilt R0: lowest point at z = 0, footprint (convex hull of the vertices'
// projection) centred on its vertex mean.
struct Rest {
  Eigen::Isometry3d rest_from_object = Eigen::Isometry3d::Identity();
  Poly hull;
  double height = 0;
  double radius = 0;  // of the hull around the origin
};

Rest make_rest(const Proto& p, const Eigen::Matrix3d& R0) {
  std::vector<Vec2> pts;
  double zmin = 1e300, zmax = -1e300;
  if (p.kind == ClutterKind::box) {  // the corners are exact
    for (int c = 0; c < 8; ++c) {
      const Vec3 v = R0 * Vec3((c & 1 ? 0.5 : -0.5) * p.size.x(), (c & 2 ? 0.5 : -0.5) * p.size.y(),
                               (c & 4 ? 0.5 : -0.5) * p.size.z());
      pts.emplace_back(v.x(), v.y());
    }
  } else {
    pts.reserve(p.mesh.vertices.size());
    for (const auto& vf : p.mesh.vertices) {
      const Vec3 v = R0 * vf.cast<double>();
      pts.emplace_back(v.x(), v.y());
    }
  }
  for (const auto& vf : p.mesh.vertices) {
    const double z = (R0 * vf.cast<double>()).z();
    zmin = std::min(zmin, z);
    zmax = std::max(zmax, z);
  }
  Rest r;
  r.hull = convex_hull(std::move(pts));
  Vec2 c = Vec2::Zero();
  for (const Vec2& v : r.hull) c += v;
  c /= static_cast<double>(r.hull.size());
  for (Vec2& v : r.hull) {
    v -= c;
    r.radius = std::max(r.radius, v.norm());
  }
  r.height = zmax - zmin;
  r.rest_from_object.linear() = R0;
  r.rest_from_object.translation() = Vec3(-c.x(), -c.y(), -zmin);
  return r;
}

// One object as placed: world_from_rest = translate(t, z0) * yaw.
struct Placed {
  int proto = 0;
  Rest rest;
  ClutterPose pose = ClutterPose::standing;
  double yaw = 0, z0 = 0, z1 = 0;
  Vec2 t = Vec2::Zero();
  Poly foot;
  int on = -1, nb = -1;  // supporting object (-1 = table), neighbour (touching, leaning)
  double gap = 0, tilt_deg = 0;
  bool can_support = false;  // a box resting level: its top face is horizontal

  void place(double yaw_, const Vec2& t_, double z0_) {
    yaw = yaw_;
    t = t_;
    z0 = z0_;
    z1 = z0 + rest.height;
    const Eigen::Matrix2d R = rot2(yaw);
    foot.resize(rest.hull.size());
    for (std::size_t i = 0; i < foot.size(); ++i) foot[i] = R * rest.hull[i] + t;
  }
  Eigen::Isometry3d world_from_object() const {
    return Eigen::Translation3d(t.x(), t.y(), z0) * Eigen::AngleAxisd(yaw, Vec3::UnitZ()) *
           rest.rest_from_object;
  }
};

void check_params(const ClutterParams& p) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("clutter: " + what); };
  if (p.min_objects < 1 || p.max_objects < p.min_objects || p.max_objects > 40)
    bad("object count range must satisfy 1 <= min <= max <= 40");
  if (!(p.min_size > 0.005 && p.max_size >= p.min_size && p.max_size <= 0.6))
    bad("size range must satisfy 0.005 < min <= max <= 0.6 m");
  if (!(p.min_distance > 0.2 && p.max_distance >= p.min_distance))
    bad("camera distance range must satisfy 0.2 < min <= max");
  if (!(p.min_elevation_deg > 5 && p.max_elevation_deg >= p.min_elevation_deg &&
        p.max_elevation_deg <= 89))
    bad("camera elevation range must satisfy 5 < min <= max <= 89 degrees");
  if (!(p.min_table_width > 0.4 && p.max_table_width >= p.min_table_width &&
        p.min_table_depth > 0.4 && p.max_table_depth >= p.min_table_depth))
    bad("table ranges must be > 0.4 m and ordered");
  if (!(p.min_density > 0 && p.max_density >= p.min_density && p.max_density < 1))
    bad("density range must satisfy 0 < min <= max < 1");
  for (double q : {p.mesh_share, p.box_share, p.flat_share, p.p_touching, p.p_stacked, p.p_leaning,
                   p.p_lying, p.mesh_recolour, p.p_flush, p.p_front})
    if (!(q >= 0 && q <= 1)) bad("probabilities and shares must be in [0, 1]");
  if (!(p.depth_noise >= 0 && p.disparity_step >= 0 && p.colour_noise >= 0))
    bad("noise must be >= 0");
  if (!(p.min_front_gap >= 0 && p.max_front_gap >= p.min_front_gap && p.max_front_gap < 1))
    bad("front gaps must satisfy 0 <= min <= max < 1 m");
  if (p.min_visible_points < 0 || p.max_layouts < 1)
    bad("min_visible_points >= 0, max_layouts >= 1");
  if (!(p.catalogue_share >= 0 && p.catalogue_share <= 1))
    bad("probabilities and shares must be in [0, 1]");
  for (const CatalogueObject& e : p.catalogue)
    if (e.name.empty() || e.mesh.vertices.empty() || e.mesh.triangles.empty() ||
        e.mesh.colours.size() != e.mesh.vertices.size())
      bad("catalogue entry '" + e.name + "' needs a name and a mesh with one colour per vertex");
}

// One layout draw (sub-stream `draw` of the seed). Returns false if the objects could not all be
// placed or some object shows fewer than min_visible_points.
class Layout {
 public:
  Layout(const ClutterParams& P, const std::vector<std::string>& models, int n, int draw)
      : P_(P),
        models_(models),
        n_(n),
        r_(stream(P.seed, 1 + static_cast<std::uint64_t>(draw))),
        catalogue_count_(P.catalogue.size(), 0) {
    unused_models_.resize(models.size());
    for (std::size_t i = 0; i < models.size(); ++i) unused_models_[i] = static_cast<int>(i);
  }

  bool run(ClutterScene& out);

 private:
  enum class Rel { free, touching, stacked, leaning };

  const ClutterParams& P_;
  const std::vector<std::string>& models_;
  int n_;
  Rng r_;
  std::vector<int> unused_models_;
  std::vector<int> catalogue_count_;  // instances of each catalogue entry drawn so far
  std::vector<Proto> protos_;
  std::vector<Placed> placed_;
  double table_hx_ = 0, table_hy_ = 0;
  Vec2 area_c_ = Vec2::Zero(), area_h_ = Vec2::Zero();
  double view_az_ = 0;  // with p_front: the camera's azimuth, drawn before the placement

  double size_u(double lo, double hi) {
    return r_.u(std::max(lo, P_.min_size), std::min(hi, P_.max_size));
  }

  int add_proto(Proto p) {
    protos_.push_back(std::move(p));
    return static_cast<int>(protos_.size()) - 1;
  }

  // Any object for the table: mesh, box or cylinder, with its pose (standing or lying).
  std::pair<int, ClutterPose> generic(bool allow_mesh = true) {
    // A catalogue entry. Without a catalogue nothing is drawn here, so that the draws below, and
    // so every scene of the generator without one, stay as they were.
    if (!P_.catalogue.empty() && P_.catalogue_share > 0 && r_.p(P_.catalogue_share)) {
      std::vector<int> open;  // entries with fewer than 2 instances
      for (std::size_t k = 0; k < catalogue_count_.size(); ++k)
        if (catalogue_count_[k] < kMaxCatalogueInstances) open.push_back(static_cast<int>(k));
      if (!open.empty()) {
        const int k = open[static_cast<std::size_t>(r_.i(0, static_cast<int>(open.size()) - 1))];
        ++catalogue_count_[static_cast<std::size_t>(k)];
        const bool lying = P_.catalogue[static_cast<std::size_t>(k)].lies || r_.p(P_.p_lying);
        return {add_proto(catalogue_proto(P_.catalogue, k)),
                lying ? ClutterPose::lying : ClutterPose::standing};
      }
    }
    const double u = r_.u();
    const double mesh_share = (allow_mesh && !unused_models_.empty()) ? P_.mesh_share : 0;
    const bool lying = r_.p(P_.p_lying);
    if (u < mesh_share) {
      const int k = r_.i(0, static_cast<int>(unused_models_.size()) - 1);
      const int model = unused_models_[static_cast<std::size_t>(k)];
      unused_models_.erase(unused_models_.begin() + k);
      return {add_proto(mesh_proto(r_, models_[static_cast<std::size_t>(model)],
                                   P_.mesh_scale_jitter, P_.mesh_recolour)),
              lying ? ClutterPose::lying : ClutterPose::standing};
    }
    const double box_share = P_.box_share / std::max(1e-9, 1 - P_.mesh_share);
    const bool box = r_.u() < std::min(1.0, box_share);
    if (r_.p(P_.flat_share)) {  // small flat things, lying
      if (box) {
        if (r_.p(0.5))
          return {add_proto(box_proto(r_,
                                      Vec3(r_.u(0.03, 0.035), r_.u(0.11, 0.14),
                                           r_.u(std::max(P_.flat_min_thickness, 0.012), 0.02)),
                                      "marker")),
                  ClutterPose::lying};
        return {add_proto(box_proto(r_,
                                    Vec3(r_.u(0.05, 0.07), r_.u(0.08, 0.1),
                                         r_.u(std::max(P_.flat_min_thickness, 0.02), 0.03)),
                                    "soap bar")),
                ClutterPose::lying};
      }
      return {add_proto(cylinder_proto(r_, r_.u(0.011, 0.015), r_.u(0.11, 0.15), "marker")),
              ClutterPose::lying};
    }
    if (box) {
      // Largest extent a, then b <= a, c <= b; standing: a or b vertical, lying: c vertical.
      const double a = size_u(0.06, P_.max_size), b = size_u(0.03, a), c = size_u(0.03, b);
      Vec3 s;
      if (lying)
        s = Vec3(a, b, c);
      else if (r_.p(0.5))
        s = Vec3(b, c, a);
      else
        s = Vec3(a, c, b);
      if (r_.p(0.5)) std::swap(s.x(), s.y());
      return {add_proto(box_proto(r_, s, "box")),
              lying ? ClutterPose::lying : ClutterPose::standing};
    }
    const double rr = size_u(0.03, 0.12) / 2;  // diameter 3-12 cm
    const double h =
        lying ? size_u(std::max(2.2 * rr, 0.06), P_.max_size * 0.8) : size_u(0.04, P_.max_size);
    return {add_proto(cylinder_proto(r_, rr, h, "cylinder")),
            lying ? ClutterPose::lying : ClutterPose::standing};
  }

  Eigen::Matrix3d tilt_for(const Proto& p, ClutterPose pose) {
    // Random boxes are drawn with their lying extents already; a catalogue box is turned down
    // like a mesh (its longer horizontal axis: onto its largest face when z is its longest).
    if (pose != ClutterPose::lying || (p.kind == ClutterKind::box && p.catalogue < 0))
      return Eigen::Matrix3d::Identity();
    if (p.kind == ClutterKind::cylinder)
      return Eigen::AngleAxisd(kPi / 2, Vec3::UnitX()).toRotationMatrix();
    // On its side: turned about its longer horizontal axis (the flattest way down).
    const Vec3 axis = p.size.x() >= p.size.y() ? Vec3::UnitX() : Vec3::UnitY();
    return Eigen::AngleAxisd(r_.p(0.5) ? kPi / 2 : -kPi / 2, axis).toRotationMatrix();
  }

  // Collision-free against every placed object whose height range overlaps; on the table (if
  // resting on it) with a 2 cm margin.
  bool fits(const Placed& c) const {
    if (c.on < 0) {
      for (const Vec2& v : c.foot)
        if (std::abs(v.x()) > table_hx_ - 0.02 || std::abs(v.y()) > table_hy_ - 0.02) return false;
    }
    for (const Placed& o : placed_) {
      if (std::min(c.z1, o.z1) - std::max(c.z0, o.z0) <= 1e-4) continue;
      if ((c.t - o.t).norm() > c.rest.radius + o.rest.radius + 1e-6) continue;
      if (poly_gap(c.foot, o.foot) < 0) return false;
    }
    return true;
  }

  Placed start(int proto, ClutterPose pose, const Eigen::Matrix3d& R0) {
    Placed c;
    c.proto = proto;
    c.pose = pose;
    c.rest = make_rest(protos_[static_cast<std::size_t>(proto)], R0);
    // Stacking puts objects on the top face of the box's own extents: only a box that is not
    // turned (a lying catalogue box is) has it on top.
    c.can_support = protos_[static_cast<std::size_t>(proto)].kind == ClutterKind::box &&
                    pose != ClutterPose::leaning && R0 == Eigen::Matrix3d::Identity();
    return c;
  }

  bool place_free(Placed& c, int trials) {
    for (int k = 0; k < trials; ++k) {
      const Vec2 t(area_c_.x() + r_.u(-1, 1) * area_h_.x(),
                   area_c_.y() + r_.u(-1, 1) * area_h_.y());
      c.place(r_.u(0, 2 * kPi), t, 0);
      if (fits(c)) return true;
    }
    return false;
  }

  std::vector<int> table_level(bool boxes_only, double min_height) const {
    std::vector<int> out;
    for (std::size_t i = 0; i < placed_.size(); ++i) {
      const Placed& o = placed_[i];
      if (o.on >= 0 || o.pose == ClutterPose::leaning) continue;
      if (boxes_only && !o.can_support) continue;
      if (o.z1 < min_height) continue;
      out.push_back(static_cast<int>(i));
    }
    return out;
  }

  // Beside a placed object at a footprint gap in [0, max_touch_gap]: bisection along a random
  // direction from the neighbour's centre (the overlap set along a ray is an interval).
  bool is_box(const Placed& c) const {
    return protos_[static_cast<std::size_t>(c.proto)].kind == ClutterKind::box;
  }

  bool place_touching(Placed& c, int trials) {
    const std::vector<int> cand = table_level(false, 0);
    if (cand.empty()) return false;
    for (int k = 0; k < trials; ++k) {
      const int ni = cand[static_cast<std::size_t>(r_.i(0, static_cast<int>(cand.size()) - 1))];
      const Placed& nb = placed_[static_cast<std::size_t>(ni)];
      double yaw = r_.u(0, 2 * kPi), dir = r_.u(0, 2 * kPi);
      double gap = r_.u(0, P_.max_touch_gap);
      // In front: a few centimetres from the neighbour towards the camera, hiding part of it.
      if (P_.p_front > 0 && r_.p(P_.p_front)) {
        dir = view_az_ + r_.u(-1, 1) * kPi / 8;
        gap = r_.u(P_.min_front_gap, P_.max_front_gap);
      }
      Vec2 from = nb.t;
      // Flush: two boxes face to face, as in a pile (drawn only when asked for, so that scenes
      // without it stay bit-identical).
      if (P_.p_flush > 0 && is_box(c) && is_box(nb) && r_.p(P_.p_flush)) {
        yaw = nb.yaw + r_.i(0, 3) * kPi / 2 + detail::radians(r_.u(-1, 1));
        dir = nb.yaw + r_.i(0, 3) * kPi / 2;
        const Vec2 along(-std::sin(dir), std::cos(dir));
        from += r_.u(-0.5, 0.5) * std::min(c.rest.radius, nb.rest.radius) * along;
      }
      const Vec2 d(std::cos(dir), std::sin(dir));
      double lo = 0, hi = nb.rest.radius + c.rest.radius + gap + 0.01;
      for (int it = 0; it < 40; ++it) {
        const double mid = (lo + hi) / 2;
        c.place(yaw, from + mid * d, 0);
        (poly_gap(c.foot, nb.foot) >= gap ? hi : lo) = mid;
      }
      c.place(yaw, from + hi * d, 0);
      if ((c.t - area_c_).cwiseAbs().maxCoeff() > area_h_.maxCoeff() + 0.1) continue;  // stay near
      if (!fits(c)) continue;
      c.nb = ni;
      c.gap = poly_gap(c.foot, nb.foot);
      return true;
    }
    return false;
  }

  // A small object (box, cylinder or mesh) on the top face of a placed box.
  bool place_stacked(int& proto, Placed& c) {
    std::vector<int> cand;
    for (std::size_t i = 0; i < placed_.size(); ++i) {
      const Placed& o = placed_[i];
      if (!o.can_support) continue;
      const Vec3 s = protos_[static_cast<std::size_t>(o.proto)].size;
      if (std::min(s.x(), s.y()) >= 0.05) cand.push_back(static_cast<int>(i));
    }
    if (cand.empty()) return false;
    const int bi = cand[static_cast<std::size_t>(r_.i(0, static_cast<int>(cand.size()) - 1))];
    const Placed& base = placed_[static_cast<std::size_t>(bi)];
    const Vec3 bs = protos_[static_cast<std::size_t>(base.proto)].size;
    const double room = std::min(bs.x(), bs.y()) - 0.008, room2 = std::max(bs.x(), bs.y()) - 0.008;
    // The object: a mesh that fits, or a box or a standing cylinder smaller than the top.
    const double u = r_.u();
    if (u < P_.mesh_share && !unused_models_.empty()) {
      const int k = r_.i(0, static_cast<int>(unused_models_.size()) - 1);
      const std::string& path =
          models_[static_cast<std::size_t>(unused_models_[static_cast<std::size_t>(k)])];
      Proto p = mesh_proto(r_, path, P_.mesh_scale_jitter, P_.mesh_recolour);
      if (std::max(p.size.x(), p.size.y()) < room) {
        unused_models_.erase(unused_models_.begin() + k);
        proto = add_proto(std::move(p));
      }
    }
    bool aligned = false;  // a box goes roughly along the box below (as stacked boxes do)
    if (proto < 0) {
      if (r_.p(0.7) || room < 0.035) {
        const double a = r_.u(std::min(0.03, room), std::min(0.9 * room2, 0.2));
        const double b = r_.u(std::min(0.03, room), std::min(0.9 * room, a));
        const double h = r_.u(std::max(P_.flat_min_thickness, 0.015), 0.12);
        proto = add_proto(box_proto(r_, Vec3(a, b, h), "box"));
        aligned = true;
      } else {
        const double rr = r_.u(0.015, std::max(0.016, std::min(0.05, room / 2)));
        proto = add_proto(cylinder_proto(r_, rr, r_.u(0.04, 0.15), "cylinder"));
      }
    }
    c = start(proto, ClutterPose::stacked, Eigen::Matrix3d::Identity());
    for (int k = 0; k < 30; ++k) {
      // A point of the base's top face, then the footprint must lie 3 mm inside it.
      const Eigen::Matrix2d R = rot2(base.yaw);
      const Vec2 local(r_.u(-0.5, 0.5) * (bs.x() - 0.006), r_.u(-0.5, 0.5) * (bs.y() - 0.006));
      const Vec2 centre = base.t + R * local;  // the base is a box centred on its footprint
      const double yaw = aligned ? base.yaw + (bs.x() >= bs.y() ? 0 : kPi / 2) + r_.u(-0.25, 0.25)
                                 : r_.u(0, 2 * kPi);
      c.place(yaw, centre, base.z1);
      if (!inside(c.foot, base.foot, 0.003)) continue;
      if (!fits(c)) continue;
      c.on = bi;
      return true;
    }
    return false;
  }

  // A board (thin box) or a cylinder tilted 10-30 degrees, its top resting against a vertical
  // face of a placed standing box, its lowest edge on the table.
  bool place_leaning(int& proto, Placed& c) {
    const std::vector<int> cand = table_level(true, 0.08);
    if (cand.empty()) return false;
    const int ni = cand[static_cast<std::size_t>(r_.i(0, static_cast<int>(cand.size()) - 1))];
    const Placed& nb = placed_[static_cast<std::size_t>(ni)];
    const Poly& f = nb.foot;
    std::vector<int> edges;
    for (std::size_t i = 0; i < f.size(); ++i)
      if ((f[(i + 1) % f.size()] - f[i]).norm() >= 0.05) edges.push_back(static_cast<int>(i));
    if (edges.empty()) return false;
    const auto e = static_cast<std::size_t>(
        edges[static_cast<std::size_t>(r_.i(0, static_cast<int>(edges.size()) - 1))]);
    const Vec2 a = f[e], b = f[(e + 1) % f.size()];
    const double len = (b - a).norm();
    const Vec2 tangent = (b - a) / len, normal(tangent.y(), -tangent.x());  // outward (CCW hull)
    const double theta = detail::radians(r_.u(P_.min_lean_deg, P_.max_lean_deg));
    const double contact = nb.z1 * r_.u(0.55, 0.9);  // height of the top edge on the face
    const double H = std::clamp(contact / std::cos(theta), P_.min_size, P_.max_size);
    if (r_.p(0.6)) {
      const double w = std::min(r_.u(0.06, 0.2), std::max(P_.min_size, len));
      proto = add_proto(
          box_proto(r_, Vec3(r_.u(std::max(P_.flat_min_thickness, 0.012), 0.035), w, H), "board"));
    } else {
      proto = add_proto(cylinder_proto(r_, r_.u(0.015, 0.04), H, "cylinder"));
    }
    // Tilt about y so that the top moves towards -x; then -x is turned towards the face.
    c = start(proto, ClutterPose::leaning,
              Eigen::AngleAxisd(-theta, Vec3::UnitY()).toRotationMatrix());
    c.can_support = false;
    double minx = 1e300;
    for (const Vec2& v : c.rest.hull) minx = std::min(minx, v.x());
    // The contact vertex must touch the face below its top edge.
    double zc = -1;
    const Proto& p = protos_[static_cast<std::size_t>(proto)];
    for (const auto& vf : p.mesh.vertices) {
      const Vec3 v = c.rest.rest_from_object * vf.cast<double>();
      if (v.x() < minx + 1e-4) zc = std::max(zc, v.z());
    }
    if (!(zc > 0.01 && zc < nb.z1 - 0.004)) return false;
    const double yaw = std::atan2(normal.y(), normal.x());
    for (int k = 0; k < 20; ++k) {
      const double gap = r_.u(0.1, 1.0) * P_.max_lean_gap;
      const double s = r_.u(-1, 1) * std::max(0.0, len / 2 - 0.015);
      const Vec2 t = (a + b) / 2 + s * tangent + normal * (gap - minx);
      c.place(yaw, t, 0);
      if (!fits(c)) continue;
      c.nb = ni;
      c.gap = poly_gap(c.foot, nb.foot);
      c.tilt_deg = detail::degrees(theta);
      return true;
    }
    return false;
  }
};

bool Layout::run(ClutterScene& out) {
  // Table and light. The table kind cycles with the seed: a third of any run of seeds each.
  const int table_kind = static_cast<int>(P_.seed % 3);
  out.table = table_kind == 0 ? "wood" : table_kind == 1 ? "cloth" : "plain";
  const double table_w = r_.u(P_.min_table_width, P_.max_table_width);
  const double table_d = r_.u(P_.min_table_depth, P_.max_table_depth);
  table_hx_ = table_w / 2;
  table_hy_ = table_d / 2;
  const TableFn table_colour = table_texture(r_, out.table);
  if (P_.p_front > 0) view_az_ = r_.u(0, 2 * kPi);  // drawn only then: other scenes unchanged
  const double light_el =
      detail::radians(r_.u(P_.min_light_elevation_deg, P_.max_light_elevation_deg));
  const double light_az = r_.u(0, 2 * kPi);
  const Vec3 light(std::cos(light_el) * std::cos(light_az), std::cos(light_el) * std::sin(light_az),
                   std::sin(light_el));
  const double ambient = r_.u(P_.min_ambient, P_.max_ambient);
  const double exposure = r_.u(0.9, 1.05) / (ambient + (1 - ambient) * light.z());
  out.light = light;

  // Relations, then the objects that go on the table on their own (for the layout area).
  std::vector<Rel> rel(static_cast<std::size_t>(n_), Rel::free);
  for (int i = 1; i < n_; ++i) {
    const double u = r_.u();
    rel[static_cast<std::size_t>(i)] = u < P_.p_stacked                  ? Rel::stacked
                                       : u < P_.p_stacked + P_.p_leaning ? Rel::leaning
                                       : u < P_.p_stacked + P_.p_leaning + P_.p_touching
                                           ? Rel::touching
                                           : Rel::free;
  }
  std::vector<std::pair<int, ClutterPose>> ground(static_cast<std::size_t>(n_),
                                                  {-1, ClutterPose::standing});
  double footprint_area = 0;
  for (int i = 0; i < n_; ++i) {
    if (rel[static_cast<std::size_t>(i)] == Rel::stacked ||
        rel[static_cast<std::size_t>(i)] == Rel::leaning)
      continue;
    ground[static_cast<std::size_t>(i)] = generic();
    const Proto& p = protos_[static_cast<std::size_t>(ground[static_cast<std::size_t>(i)].first)];
    footprint_area +=
        poly_area(make_rest(p, tilt_for(p, ground[static_cast<std::size_t>(i)].second)).hull);
  }
  const double density = r_.u(P_.min_density, P_.max_density), aspect = r_.u(1.0, 1.5);
  const double area = std::max(footprint_area / density, 0.04);
  const double cap_x = std::min(P_.max_area_half_extent, table_hx_ - 0.15);
  const double cap_y = std::min(P_.max_area_half_extent, table_hy_ - 0.15);
  area_h_ = Vec2(std::min(std::sqrt(area * aspect) / 2, cap_x),
                 std::min(std::sqrt(area / aspect) / 2, cap_y));
  if (r_.p(0.5)) std::swap(area_h_.x(), area_h_.y());
  area_h_ = area_h_.cwiseMin(Vec2(cap_x, cap_y));
  area_c_ = Vec2(r_.u(-0.03, 0.03), r_.u(-0.03, 0.03));

  // Placement, in order; a stacked or leaning object without a partner is placed touching.
  for (int i = 0; i < n_; ++i) {
    Rel want = rel[static_cast<std::size_t>(i)];
    Placed c;
    bool ok = false;
    if (want == Rel::stacked || want == Rel::leaning) {
      int proto = -1;
      ok = want == Rel::stacked ? place_stacked(proto, c) : place_leaning(proto, c);
      if (!ok) {
        if (proto >= 0) protos_.pop_back();  // its prototype was not placed
        want = Rel::touching;
        ground[static_cast<std::size_t>(i)] = generic();
      }
    }
    if (!ok) {
      const auto [proto, pose] = ground[static_cast<std::size_t>(i)];
      c = start(proto, pose, tilt_for(protos_[static_cast<std::size_t>(proto)], pose));
      ok = want == Rel::touching ? place_touching(c, 40) || place_free(c, 60)
                                 : place_free(c, 80) || place_touching(c, 40);
    }
    if (!ok) return false;
    placed_.push_back(std::move(c));
  }

  // World meshes, shaded (the light is fixed in the world, so they do not depend on the camera).
  std::vector<Mesh> meshes;
  meshes.reserve(placed_.size() + 1);
  auto label_of = [](int i) { return static_cast<std::uint32_t>(10 * (i + 2)); };
  out.objects.clear();
  for (std::size_t i = 0; i < placed_.size(); ++i) {
    const Placed& c = placed_[i];
    const Proto& p = protos_[static_cast<std::size_t>(c.proto)];
    ClutterObject o;
    o.label = label_of(static_cast<int>(i));
    o.kind = p.kind;
    o.name = p.name;
    o.catalogue = p.catalogue;
    o.texture = p.texture;
    o.pose = c.pose;
    o.size = p.size;
    o.world_from_object = c.world_from_object();
    o.support = c.on < 0 ? 1 : label_of(c.on);
    o.neighbour = c.nb < 0 ? 0 : label_of(c.nb);
    o.gap = c.gap;
    o.tilt_deg = c.tilt_deg;
    o.footprint = c.foot;
    Mesh m = p.mesh;
    o.z_min = 1e300;
    o.z_max = -1e300;
    for (auto& v : m.vertices) {
      v = (o.world_from_object * v.cast<double>()).cast<float>();
      o.z_min = std::min(o.z_min, static_cast<double>(v.z()));
      o.z_max = std::max(o.z_max, static_cast<double>(v.z()));
    }
    const Vec3 centre = o.world_from_object.translation();
    shade(m, light, ambient, exposure, p.convex ? &centre : nullptr);
    m.label = o.label;
    meshes.push_back(std::move(m));
    out.objects.push_back(std::move(o));
  }
  // Lateral contacts: footprints within max_touch_gap at overlapping heights.
  for (std::size_t i = 0; i < placed_.size(); ++i)
    for (std::size_t j = i + 1; j < placed_.size(); ++j) {
      const Placed &a = placed_[i], &b = placed_[j];
      if (std::min(a.z1, b.z1) - std::max(a.z0, b.z0) <= 1e-3) continue;
      if ((a.t - b.t).norm() > a.rest.radius + b.rest.radius + P_.max_touch_gap) continue;
      if (poly_gap(a.foot, b.foot) <= P_.max_touch_gap + 1e-9) {
        out.objects[i].touching.push_back(out.objects[j].label);
        out.objects[j].touching.push_back(out.objects[i].label);
      }
    }
  auto index_of = [&](std::uint32_t label) {  // object index of a frame label, -1 otherwise
    return label >= 20 && label % 10 == 0 && label / 10 - 2 < placed_.size()
               ? static_cast<int>(label / 10 - 2)
               : -1;
  };

  // Camera: elevation, azimuth and look-at point drawn, then the distance: uniform between the
  // nearest at which the whole layout (footprints at their low and high z) is in the image with a
  // 12 px margin, and max_distance. Up to kCameras cameras are tried; the first under which a
  // quarter-resolution render of the objects shows every object with min_visible_points (x 1.2,
  // scaled) is kept; if none does, the layout is redrawn.
  constexpr int kCameras = 6;
  std::vector<Vec3> corners;
  for (const Placed& c : placed_)
    for (std::size_t k = 0; k < c.foot.size(); k += std::max<std::size_t>(1, c.foot.size() / 12))
      for (double z : {c.z0, c.z1}) corners.emplace_back(c.foot[k].x(), c.foot[k].y(), z);
  const Camera& cam = P_.camera;
  Camera small = cam;
  small.width = cam.width / 4;
  small.height = cam.height / 4;
  small.fx = cam.fx / 4;
  small.fy = cam.fy / 4;
  small.cx = (cam.cx + 0.5) / 4 - 0.5;
  small.cy = (cam.cy + 0.5) / 4 - 0.5;
  bool found = false;
  for (int k = 0; k < kCameras && !found; ++k) {
    const double el = detail::radians(r_.u(P_.min_elevation_deg, P_.max_elevation_deg));
    const double az = P_.p_front > 0 ? view_az_ + r_.u(-1, 1) * kPi / 12 : r_.u(0, 2 * kPi);
    const Vec3 target(area_c_.x() + r_.u(-1, 1) * P_.target_jitter,
                      area_c_.y() + r_.u(-1, 1) * P_.target_jitter, r_.u(0.02, 0.06));
    const Vec3 back(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
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
    double d_lo = P_.max_distance;
    for (double d = P_.min_distance; d < P_.max_distance; d += 0.02)
      if (all_in_view(d)) {
        d_lo = d;
        break;
      }
    const double dist = r_.u(d_lo, P_.max_distance);
    RenderParams quick;
    quick.camera = small;
    quick.camera_from_world = look_at(target + dist * back, target);
    const Frame q = render(meshes, quick);
    std::vector<std::size_t> count(placed_.size(), 0);
    for (std::size_t i = 0; i < q.size(); ++i)
      if (const int o = index_of(q.label[i]); o >= 0) ++count[static_cast<std::size_t>(o)];
    found = *std::min_element(count.begin(), count.end()) * 16 >= 1.2 * P_.min_visible_points;
    out.target = target;
    out.eye = target + dist * back;
    out.elevation_deg = detail::degrees(el);
    out.azimuth_deg = detail::degrees(az);
  }
  if (!found) return false;
  out.render = RenderParams{};
  out.render.camera = cam;
  out.render.camera_from_world = look_at(out.eye, out.target);
  out.render.depth_noise = P_.depth_noise;
  out.render.disparity_step = P_.disparity_step;
  out.render.seed = static_cast<std::uint32_t>(r_.next() >> 32);
  const std::uint64_t colour_salt = r_.next();

  // The table (centred on the world origin) only for depth and labels: its colours are set per
  // pixel below.
  meshes.push_back(make_plane(
      Eigen::Isometry3d::Identity(), {table_w, table_d},
      [](const Vec3&) {
        return Rgb{128, 128, 128};
      },
      kTableCell));
  meshes.back().label = 1;
  out.frame = render(meshes, out.render);
  Frame& f = out.frame;
  // The table's colours, per pixel: the pixel's ray meets the plane z = 0 at p; the texture is
  // filtered over the pixel's footprint there (its longer axis), then shaded (normal +z).
  const Eigen::Matrix3d world_from_camera = out.render.camera_from_world.linear().transpose();
  const double table_b = exposure * (ambient + (1 - ambient) * std::max(0.0, light.z()));
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
      f.rgb[k] = to_rgb8(table_colour(Vec2(p.x(), p.y()), w) * table_b);
    }
  // Sensor noise on the colours: normal draws from a seeded table of 4096 values.
  if (P_.colour_noise > 0) {
    Rng noise{SplitMix{colour_salt}};
    std::vector<double> gauss(4096);
    for (double& g : gauss) g = P_.colour_noise * noise.normal();
    for (std::size_t k = 0; k < f.size(); ++k) {
      if (!f.valid(k)) continue;
      Rgb& c = f.rgb[k];
      const std::uint64_t bits = noise.next();
      for (int ch = 0; ch < 3; ++ch)
        c[ch] = static_cast<std::uint8_t>(
            std::clamp(std::lround(c[ch] + gauss[(bits >> (12 * ch)) & 4095]), 0L, 255L));
    }
  }
  std::vector<std::size_t> visible(placed_.size(), 0);
  for (std::size_t k = 0; k < f.size(); ++k)
    if (f.valid(k))
      if (const int o = index_of(f.label[k]); o >= 0) ++visible[static_cast<std::size_t>(o)];
  bool ok = true;
  for (std::size_t i = 0; i < placed_.size(); ++i) {
    out.objects[i].visible_points = visible[i];
    ok = ok && visible[i] >= static_cast<std::size_t>(P_.min_visible_points);
  }
  return ok;
}

}  // namespace

void shade(Mesh& m, const Vec3& light, double ambient, double exposure, const Vec3* centre) {
  std::vector<Vec3> n(m.vertices.size(), Vec3::Zero());
  double orientation = 0;
  Vec3 mean = Vec3::Zero();
  for (const auto& v : m.vertices) mean += v.cast<double>();
  mean /= std::max<double>(1, static_cast<double>(m.vertices.size()));
  for (const auto& t : m.triangles) {
    const Vec3 a = m.vertices[t[0]].cast<double>(), b = m.vertices[t[1]].cast<double>(),
               c = m.vertices[t[2]].cast<double>();
    const Vec3 f = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) n[t[k]] += f;
    orientation += f.dot((a + b + c) / 3 - mean);
  }
  const double flip = orientation < 0 ? -1 : 1;  // meshes wound inwards
  for (std::size_t i = 0; i < n.size(); ++i) {
    Vec3 normal = n[i] * flip;
    const Vec3 v = m.vertices[i].cast<double>();
    if (centre) {
      if (normal.squaredNorm() == 0) normal = v - *centre;
      if (normal.dot(v - *centre) < 0) normal = -normal;
    }
    const double len = normal.norm();
    const double lambert = len > 0 ? std::max(0.0, normal.dot(light) / len) : 0.5;
    const double b = exposure * (ambient + (1 - ambient) * lambert);
    const Rgb c = m.colours[i];
    m.colours[i] = to_rgb8(Col(c[0], c[1], c[2]) * b);
  }
}

ClutterParams clutter_kind(const std::string& kind) {
  ClutterParams p;
  if (kind == "clutter") return p;
  if (kind == "piles") {
    // Boxes face to face, stacked and side by side: where geometry alone sees one surface.
    p.min_objects = 6, p.max_objects = 14;
    p.mesh_share = 0.1, p.box_share = 0.8, p.flat_share = 0.05;
    p.p_touching = 0.65, p.p_stacked = 0.25, p.p_leaning = 0.05, p.p_flush = 0.85;
    p.max_touch_gap = 0.002;
    p.p_lying = 0.3;
    p.min_density = 0.4, p.max_density = 0.6;
    return p;
  }
  if (kind == "occlusion") {
    // A low camera over a dense layout: objects hidden in part, often in two pieces.
    p.min_elevation_deg = 12, p.max_elevation_deg = 30;
    p.min_density = 0.3, p.max_density = 0.45;
    p.mesh_share = 0.3, p.box_share = 0.35;  // more cylinders: narrow occluders
    p.p_touching = 0.6, p.p_front = 0.6;
    return p;
  }
  throw InputError("clutter kind: expected \"clutter\", \"piles\" or \"occlusion\", got \"" + kind +
                   "\"");
}

ClutterScene clutter_layout_scene(const ClutterParams& params) {
  check_params(params);
  const std::vector<std::string> models = list_models(params.models_dir);
  Rng count_rng = stream(params.seed, 0);
  const int n = count_rng.i(params.min_objects, params.max_objects);
  for (int draw = 0; draw < params.max_layouts; ++draw) {
    ClutterScene scene;
    Layout layout(params, models, n, draw);
    if (!layout.run(scene)) continue;
    scene.layout = draw;
    return scene;
  }
  throw std::runtime_error("clutter: no valid layout of " + std::to_string(n) +
                           " objects for seed " + std::to_string(params.seed) + " in " +
                           std::to_string(params.max_layouts) + " draws");
}

Frame clutter_scene(const ClutterParams& params) {
  return clutter_layout_scene(params).frame;
}

std::string clutter_summary(const ClutterScene& s) {
  int meshes = 0, boxes = 0, stacked = 0, leaning = 0, lying = 0, touching = 0;
  for (const ClutterObject& o : s.objects) {
    meshes += o.kind == ClutterKind::mesh;
    boxes += o.kind == ClutterKind::box;
    stacked += o.pose == ClutterPose::stacked;
    leaning += o.pose == ClutterPose::leaning;
    lying += o.pose == ClutterPose::lying;
    touching += static_cast<int>(o.touching.size());
  }
  char line[320];
  std::snprintf(line, sizeof line,
                "%zu objects (%d meshes, %d boxes, %d cylinders; %d stacked, %d leaning, %d lying, "
                "%d touching pairs), %s table, %zu valid points, camera %.2f m at %.0f deg",
                s.objects.size(), meshes, boxes,
                static_cast<int>(s.objects.size()) - meshes - boxes, stacked, leaning, lying,
                touching / 2, s.table.c_str(), s.frame.valid_count(), (s.eye - s.target).norm(),
                s.elevation_deg);
  return line;
}

}  // namespace proxseg
