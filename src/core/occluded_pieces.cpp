// Pieces of one surface cut apart by an object in front of it: the object behind a bottle seen
// on both sides of it. Geometry alone sees two components; what joins them is that they continue
// one surface behind the occluder and look alike (Richtsfeld et al., IROS 2012, group surface
// patches that are not neighbours by such relations).
#include "occluded_pieces.hpp"

#include <proxseg/core/colour.hpp>

#include "util/angles.hpp"
#include "util/union_find.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace proxseg::detail {
namespace {

constexpr int kHueSatBins = 10;  // the paper's colour feature: 10 x 10 hue x saturation [3.1]

struct RayCount {
  int rays = 0;  // rays from one component to the other across an occluder
  int good = 0;  // of them, ending on one continuous surface
  int flat = 0;  // of those, continuing one face
};

enum Continuation { kNoSurface = 0, kConvexBody = 1, kOneFace = 2 };

// A pixel `steps` pixels back along (du, dv) from p that is still in component c and has a
// normal: the border pixel's own normal is bent by the occluder's depth edge.
int inside(const ImageGrid& g, const std::vector<Eigen::Vector3f>& normals,
           const std::vector<int>& comp, int p, int du, int dv, int steps) {
  const int u = p % g.w() + du * steps, v = p / g.w() + dv * steps;
  if (u < 0 || v < 0 || u >= g.w() || v >= g.h()) return p;
  const int q = v * g.w() + u;
  return comp[q] == comp[p] && has_normal(normals[q]) ? q : p;
}

// Hue-saturation histogram of every component's coloured pixels, normalised to sum 1.
std::vector<Eigen::VectorXf> hue_saturation(const Frame& f, const std::vector<int>& comp,
                                            int count) {
  std::vector<Eigen::VectorXf> h(count, Eigen::VectorXf::Zero(kHueSatBins * kHueSatBins));
  auto bin = [](double x) { return std::min(kHueSatBins - 1, static_cast<int>(x * kHueSatBins)); };
  for (std::size_t p = 0; p < comp.size(); ++p) {
    if (comp[p] < 0) continue;
    const Eigen::Vector3d hsv = rgb_to_hsv(f.rgb[p]);
    h[comp[p]](bin(hsv[0]) * kHueSatBins + bin(hsv[1])) += 1;
  }
  for (auto& x : h)
    if (x.sum() > 0) x /= x.sum();
  return h;
}

}  // namespace

void join_occluded_pieces(const ImageGrid& g, const std::vector<Eigen::Vector3f>& normals,
                          const SelectionParams& params, int count, std::vector<int>& comp) {
  const Frame& f = g.frame;
  const float cos_tol =
      static_cast<float>(std::cos(detail::radians(params.occlusion.normal_tolerance_deg)));
  const float tol = static_cast<float>(params.occlusion.surface_tolerance);
  const float noise = static_cast<float>(3 * params.image.sensor_noise_at_1m);
  static constexpr int kRays[4][2] = {{1, 0}, {0, 1}, {1, 1}, {-1, 1}};  // later pixels
  // How the ends p and q continue one surface, if they do.
  auto continues = [&](int p, int q, int du, int dv) {
    const int a = inside(g, normals, comp, p, -du, -dv, params.image.normal_step);
    const int b = inside(g, normals, comp, q, du, dv, params.image.normal_step);
    const Eigen::Vector3f &na = normals[a], &nb = normals[b];
    const Eigen::Vector3f gap = f.xyz[q] - f.xyz[p];
    const float allowed = tol + 0.05f * gap.norm();
    if (!has_normal(na) || !has_normal(nb)) return kNoSurface;
    // One face continued: parallel normals, each end near the other's tangent plane.
    if (na.dot(nb) >= cos_tol)
      return std::abs(na.dot(gap)) <= allowed && std::abs(nb.dot(gap)) <= allowed ? kOneFace
                                                                                  : kNoSurface;
    // Two faces of one convex body whose edge the occluder hides: each end behind the other's
    // tangent plane (the convex case of LCCP's criterion).
    return na.dot(gap) < -allowed && nb.dot(gap) > allowed ? kConvexBody : kNoSurface;
  };
  std::map<std::pair<int, int>, RayCount> pairs;
  for (int v = 0; v < g.h(); ++v)
    for (int u = 0; u < g.w(); ++u) {
      const int p = v * g.w() + u, a = comp[p];
      if (a < 0) continue;
      const float margin = std::max(tol, noise * g.z(p) * g.z(p));
      for (const auto& d : kRays) {
        int passed = 0;   // valid pixels of an occluder crossed
        float front = 0;  // the farthest of them
        for (int k = 1; k <= params.occlusion.window; ++k) {
          const int uq = u + k * d[0], vq = v + k * d[1];
          if (uq < 0 || uq >= g.w() || vq >= g.h()) break;
          const int q = vq * g.w() + uq;
          if (!g.valid(q)) continue;  // a shadow band beside the occluder
          if (comp[q] == a) break;    // still (or back) on the component itself
          if (g.z(q) < g.z(p) - margin) {
            ++passed, front = std::max(front, g.z(q));
            continue;
          }
          // The first pixel not in front of p: another component behind the same occluder?
          if (comp[q] >= 0 && passed >= 2 && front < g.z(q) - margin) {
            RayCount& c = pairs[{std::min(a, comp[q]), std::max(a, comp[q])}];
            ++c.rays;
            const Continuation how = continues(p, q, d[0], d[1]);
            c.good += how != kNoSurface;
            c.flat += how == kOneFace;
          }
          break;
        }
      }
    }
  detail::UnionFind sets(static_cast<std::size_t>(count));
  std::vector<Eigen::VectorXf> colour;
  if (f.coloured()) colour = hue_saturation(f, comp, count);
  bool joined = false;
  for (const auto& [pair, c] : pairs) {
    const double alike =
        colour.empty() ? 1.0 : colour[pair.first].cwiseMin(colour[pair.second]).sum();
    const bool face =
        c.flat >= params.occlusion.min_face_rays && alike >= params.occlusion.min_face_colour;
    const bool body = c.good >= params.occlusion.min_rays &&
                      c.good >= params.occlusion.min_share * c.rays &&
                      alike >= params.occlusion.min_colour;
    if (!face && !body) continue;
    sets.unite(pair.first, pair.second);
    joined = true;
  }
  if (!joined) return;
  for (int& c : comp)
    if (c >= 0) c = static_cast<int>(sets.find(c));
}

}  // namespace proxseg::detail
