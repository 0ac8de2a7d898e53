// db_scale_bench's distractors (db_scale_bench.hpp): seeded textured boxes and cylinders, and the
// tested meshes hue-turned (same shape, other colour: the hard negatives). splitmix64 draws: the
// same objects with every standard library (std:: distributions are not portable).
#include <proxseg/core/colour.hpp>
#include <proxseg/core/render.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "bench_util.hpp"
#include "db_scale_bench.hpp"

namespace proxseg::bench::dbscale {
namespace {

struct Rng {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t x = (state += 0x9e3779b97f4a7c15ull);
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
  }
  double u() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double u(double lo, double hi) { return lo + (hi - lo) * u(); }
};

// Distractor j's own stream: a distractor does not change when others are added or removed.
Rng stream(std::uint64_t seed, std::uint64_t j) {
  Rng s{seed + 0x632be59bd9b4e019ull};
  Rng r{s.next() ^ (j * 0x9e3779b97f4a7c15ull)};
  r.state = r.next();
  return r;
}

Rgb from_hsv(double h, double s, double v) {
  return to_rgb8(hsv_to_rgb({h, s, v}));
}

// Packaging-like colours as the clutter generator draws them: a fifth nearly unsaturated
// (white, grey, black), the rest saturated.
Eigen::Vector3d random_hsv(Rng& r) {
  if (r.u() < 0.2) return {r.u(), r.u(0, 0.12), r.u() < 0.5 ? r.u(0.75, 0.95) : r.u(0.1, 0.55)};
  return {r.u(), r.u(0.35, 0.95), r.u(0.35, 0.95)};
}

// A second colour that stands out from the first: the hue turned by a third to two thirds, or
// (for a grey) a much brighter or darker value.
Eigen::Vector3d contrast_hsv(Rng& r, const Eigen::Vector3d& a) {
  if (a[1] < 0.2) return {r.u(), r.u(0.4, 0.9), a[2] > 0.5 ? r.u(0.2, 0.4) : r.u(0.7, 0.95)};
  return {a[0] + r.u(1.0 / 3, 2.0 / 3), r.u(0.3, 0.95), r.u(0.35, 0.95)};
}

// The k-th box or cylinder (distractor j), 3-25 cm (cylinders 3-15 cm across: cans, jars,
// bottles), in one colour or textured with stripes, bands or a checkerboard of two contrasting
// colours. Kind and texture take turns (k even: box; texture k / 2 mod 4), so that even the
// smallest database holds each; sizes and colours are drawn.
Distractor primitive(std::uint64_t seed, int j, int k) {
  Rng r = stream(seed, static_cast<std::uint64_t>(j));
  Distractor d;
  const bool box = k % 2 == 0;
  d.kind = box ? "box" : "cylinder";
  if (box) {
    d.size = {r.u(0.03, 0.25), r.u(0.03, 0.25), r.u(0.03, 0.25)};
  } else {
    const double diameter = r.u(0.03, 0.15);
    d.size = {diameter, diameter, r.u(0.03, 0.25)};
  }
  const Eigen::Vector3d a = random_hsv(r), b = contrast_hsv(r, a);
  const Rgb ca = from_hsv(a[0], a[1], a[2]), cb = from_hsv(b[0], b[1], b[2]);
  static const char* const kTextures[] = {"plain", "stripes", "bands", "checker"};
  d.texture = kTextures[(k / 2) % 4];
  ColourFn colour;
  if (d.texture == "plain") {
    colour = [ca](const Eigen::Vector3d&) { return ca; };
  } else if (d.texture == "stripes") {  // along a random axis, 2-6 cm period
    const int axis = std::min<int>(2, static_cast<int>(r.u() * 3));
    const double period = r.u(0.02, 0.06);
    colour = [ca, cb, axis, period](const Eigen::Vector3d& p) {
      const double x = p[axis] / period;
      return x - std::floor(x) < 0.5 ? ca : cb;
    };
  } else if (d.texture == "bands") {               // 1-3 horizontal bands of 1-5 cm, like a label
    std::vector<std::pair<double, double>> bands;  // centre, half width
    const int n = 1 + std::min<int>(2, static_cast<int>(r.u() * 3));
    for (int k = 0; k < n; ++k) bands.emplace_back(r.u(-0.5, 0.5) * d.size.z(), r.u(0.005, 0.025));
    colour = [ca, cb, bands](const Eigen::Vector3d& p) {
      for (const auto& [c, w] : bands)
        if (std::abs(p.z() - c) < w) return cb;
      return ca;
    };
  } else {  // checker, 1.5-4 cm cells
    const double cell = r.u(0.015, 0.04);
    colour = [ca, cb, cell](const Eigen::Vector3d& p) {
      const auto i = static_cast<long>(std::floor(p.x() / cell) + std::floor(p.y() / cell) +
                                       std::floor(p.z() / cell));
      return i % 2 == 0 ? ca : cb;
    };
  }
  char name[32];
  std::snprintf(name, sizeof name, "%s-%02d", d.kind.c_str(), j + 1);
  d.object.name = name;
  d.object.file = std::string(name) + " (generated " + d.texture + ")";
  d.object.mesh =
      box ? make_box(Eigen::Isometry3d::Identity(), d.size, colour)
          : make_cylinder(Eigen::Isometry3d::Identity(), d.size.x() / 2, d.size.z(), colour);
  return d;
}

// The tested mesh with every vertex colour's hue turned by `turn` (saturation and value kept, so
// that shading and texture stay and only the colour differs; a nearly grey mesh's saturation is
// raised to kTintSaturation): same shape, other object.
Distractor lookalike(const TestObject& o, int original, double turn) {
  Distractor d;
  d.kind = "look-alike";
  d.original = original;
  d.hue_turn = turn;
  d.object = o;
  for (const Rgb& c : o.mesh.colours) {
    const Eigen::Vector3d hsv = rgb_to_hsv(c);
    d.chroma += hsv[1] * hsv[2];
  }
  if (!o.mesh.colours.empty()) d.chroma /= static_cast<double>(o.mesh.colours.size());
  const bool tint = d.chroma < kGreyChroma;
  d.texture = tint ? "hue-turned, tinted" : "hue-turned";
  d.object.name = o.name + "-hue" + fixed(360 * turn, 0);
  d.object.file = o.file + " (" + d.texture + " " + fixed(360 * turn, 0) + " deg)";
  for (Rgb& c : d.object.mesh.colours) {
    const Eigen::Vector3d hsv = rgb_to_hsv(c);
    c = from_hsv(hsv[0] + turn, tint ? std::max(hsv[1], kTintSaturation) : hsv[1], hsv[2]);
  }
  Eigen::Vector3d lo = o.mesh.vertices.at(0).cast<double>(), hi = lo;
  for (const auto& v : o.mesh.vertices)
    lo = lo.cwiseMin(v.cast<double>()), hi = hi.cwiseMax(v.cast<double>());
  d.size = hi - lo;
  return d;
}

}  // namespace

std::vector<Distractor> distractors(const std::vector<TestObject>& tested, int count,
                                    int lookalikes, std::uint64_t seed) {
  const int max_lookalikes = std::min<int>(lookalikes, static_cast<int>(tested.size()));
  std::vector<Distractor> out(std::max(count, 0));
#pragma omp parallel for schedule(dynamic, 1)
  for (int j = 0; j < count; ++j) {
    if (j % 7 == 0 && j / 7 < max_lookalikes) {
      Rng r = stream(seed, static_cast<std::uint64_t>(j));
      // A third to two thirds of a turn: far enough in hue that colour can tell them apart.
      out[j] = lookalike(tested[j / 7], j / 7, r.u(1.0 / 3, 2.0 / 3));
    } else {
      out[j] = primitive(seed, j, j - std::min(j / 7 + 1, max_lookalikes));
    }
  }
  return out;
}

}  // namespace proxseg::bench::dbscale
