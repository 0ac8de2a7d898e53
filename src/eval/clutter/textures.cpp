// The textures of the cluttered scene generator: colours, the boxes' and cylinders' textures per
// vertex and the table top's per pixel (clutter/textures.hpp). Every ColourFn captures its
// parameters by value.
#include "eval/clutter/textures.hpp"

#include <proxseg/core/colour.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

#include "eval/clutter/footprint.hpp"
#include "util/angles.hpp"

namespace proxseg::clutter {

using detail::kPi;

namespace {

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
// Object textures.

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

}  // namespace

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

// ---------------------------------------------------------------------------------------------
// The table top.

namespace {

// Box-filtered periodic pulse: the mean over [x - w/2, x + w/2] of [frac(x) < duty] (period 1).
double pulse(double x, double duty, double w) {
  auto integral = [duty](double t) { return std::floor(t) * duty + std::min(frac(t), duty); };
  if (w < 1e-6) return frac(x) < duty ? 1.0 : 0.0;
  return (integral(x + w / 2) - integral(x - w / 2)) / w;
}

}  // namespace

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

}  // namespace proxseg::clutter
