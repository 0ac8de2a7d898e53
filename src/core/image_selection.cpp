// Selection on the image grid [extension of 3.3; docs/method.md, "Selection on the image grid"]:
// on an organized frame the geometry is read between neighbouring pixels, at the sensor's own
// resolution, instead of between 2 cm voxels where a small object has one or two cells.
#include <proxseg/core/features.hpp>

#include <proxseg/core/selection.hpp>
#include "util/parallel_for.hpp"

#include "container_pieces.hpp"
#include "image_grid.hpp"
#include "image_selection_detail.hpp"
#include "occluded_pieces.hpp"
#include "selection_detail.hpp"
#include "util/angles.hpp"
#include "util/moments.hpp"
#include "util/stopwatch.hpp"
#include "util/union_find.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>

namespace proxseg {
namespace {

using detail::has_normal;
using detail::ImageGrid;
using detail::kNone;
using detail::kPlane;
using detail::Plane;

Plane fit_plane(const Frame& frame, const std::vector<int>& pixels) {
  const auto [mean, scatter] =
      detail::moments(pixels.size(), [&](std::size_t j) { return frame.xyz[pixels[j]]; });
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(scatter);
  Eigen::Vector3d n = eig.eigenvectors().col(0);
  if (n.dot(mean) > 0) n = -n;  // towards the sensor
  return {n.cast<float>(), static_cast<float>(-n.dot(mean))};
}

// The pixel of the best plane hypothesis: hypotheses from an even spread of the samples, each
// the plane through the pixel along its normal, scored by the footprint of its inliers (k: the
// band's sigmas times the noise at 1 m).
int best_plane_pixel(const ImageGrid& g, const std::vector<Eigen::Vector3f>& normals,
                     const std::vector<int>& samples, float cos_tol, float k, float band_min) {
  const Frame& f = g.frame;
  const int hypotheses = std::min<int>(256, static_cast<int>(samples.size()));
  // The samples packed side by side (each hypothesis reads them all), with the inlier test's
  // band and the footprint weight precomputed: the same arithmetic as inlier(), without the
  // scattered reads.
  const std::size_t n = samples.size();
  std::vector<float> x(n), y(n), z(n), nx(n), ny(n), nz(n), band(n), weight(n);
  for (std::size_t j = 0; j < n; ++j) {
    const int p = samples[j];
    x[j] = f.xyz[p].x(), y[j] = f.xyz[p].y(), z[j] = f.xyz[p].z();
    nx[j] = normals[p].x(), ny[j] = normals[p].y(), nz[j] = normals[p].z();
    band[j] = std::max(band_min, k * g.z(p) * g.z(p));
    weight[j] = g.z(p) * g.z(p);
  }
  // Support of hypothesis i over every stride-th sample: four running sums in a fixed order (no
  // chain of dependent additions; the same value whatever the threads), without branches.
  auto support_of = [&](int i, std::size_t stride) {
    const int h = samples[static_cast<std::size_t>(i) * n / hypotheses];
    const Eigen::Vector3f& m = normals[h];
    const float offset = -m.dot(f.xyz[h]);
    auto term = [&](std::size_t j) {
      const float d = m.x() * x[j] + m.y() * y[j] + m.z() * z[j] + offset;
      const float c = m.x() * nx[j] + m.y() * ny[j] + m.z() * nz[j];
      return (std::abs(d) <= band[j]) & (std::abs(c) >= cos_tol) ? weight[j] : 0.f;
    };
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    std::size_t j = 0;
    for (; j + 4 * stride <= n; j += 4 * stride)
      s0 += term(j), s1 += term(j + stride), s2 += term(j + 2 * stride), s3 += term(j + 3 * stride);
    for (; j < n; j += stride) s0 += term(j);
    return (s0 + s1) + (s2 + s3);
  };
  // Every hypothesis on a quarter of the samples; the best of them on all (the one with the most
  // support wins, ties to the first).
  constexpr std::size_t kPreviewStride = 4;
  constexpr int kFinalists = 16;
  std::vector<double> preview(hypotheses);
  detail::parallel_for(
      hypotheses, g.threads, [&](int i) { preview[i] = support_of(i, kPreviewStride); }, 8);
  std::vector<int> finalists(hypotheses);
  std::iota(finalists.begin(), finalists.end(), 0);
  const int kept = std::min(kFinalists, hypotheses);
  std::partial_sort(
      finalists.begin(), finalists.begin() + kept, finalists.end(),
      [&](int a, int b) { return preview[a] > preview[b] || (preview[a] == preview[b] && a < b); });
  finalists.resize(kept);
  std::sort(finalists.begin(), finalists.end());
  std::vector<double> support(kept);
  detail::parallel_for(kept, g.threads, [&](int i) { support[i] = support_of(finalists[i], 1); });
  const int best = finalists[std::max_element(support.begin(), support.end()) - support.begin()];
  return samples[static_cast<std::size_t>(best) * samples.size() / hypotheses];
}

// The support plane (table, floor): hypotheses from an even spread of pixels with a normal, each
// the plane through the pixel along its normal; the one whose inliers cover the most surface
// (pixels weighted by z^2, their footprint) wins and is refitted to its inliers. A pixel is an
// inlier within the sensor's noise at its range and with a parallel normal. Returns per pixel
// whether it lies in the plane; all false when the plane spans less than background_min_area.
struct SupportPlane {
  Plane plane;
  std::vector<char> in_plane;  // per pixel
  bool found = false;
};

SupportPlane support_plane(const ImageGrid& g, const std::vector<Eigen::Vector3f>& normals,
                           const SelectionParams& params) {
  const Frame& f = g.frame;
  const float cos_tol =
      static_cast<float>(std::cos(detail::radians(params.support_normal_tolerance_deg)));
  const float k =
      static_cast<float>(params.image.plane_band_sigmas * params.image.sensor_noise_at_1m);
  const float band_min = static_cast<float>(params.image.plane_band_min);
  auto inlier = [&](const Plane& pl, int p) {
    const float z = g.z(p);
    if (std::abs(pl.distance(f.xyz[p])) > std::max(band_min, k * z * z)) return false;
    return !has_normal(normals[p]) || std::abs(pl.normal.dot(normals[p])) >= cos_tol;
  };
  constexpr int kSampleStride = 6;
  std::vector<int> samples;
  for (int v = kSampleStride / 2; v < g.h(); v += kSampleStride)
    for (int u = kSampleStride / 2; u < g.w(); u += kSampleStride) {
      const int p = v * g.w() + u;
      if (g.valid(p) && has_normal(normals[p])) samples.push_back(p);
    }
  SupportPlane out;
  out.in_plane.assign(f.size(), 0);
  if (samples.size() < 3) return out;
  const int h = best_plane_pixel(g, normals, samples, cos_tol, k, band_min);
  Plane plane{normals[h], -normals[h].dot(f.xyz[h])};
  std::vector<int> inliers;
  for (int round = 0; round < 2; ++round) {  // refit to the inliers, twice
    inliers.clear();
    for (int p : samples)
      if (inlier(plane, p)) inliers.push_back(p);
    if (inliers.size() < 3) return out;
    plane = fit_plane(f, inliers);
  }
  // Extent of the plane's inliers along two in-plane axes: too small a plane is no support.
  const Eigen::Vector3f a = plane.normal.unitOrthogonal(), b = plane.normal.cross(a);
  Eigen::Vector2f lo = Eigen::Vector2f::Constant(INFINITY), hi = -lo;
  for (int p : inliers) {
    const Eigen::Vector2f q(a.dot(f.xyz[p]), b.dot(f.xyz[p]));
    lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  }
  if ((hi - lo).prod() < params.background_min_area) return out;
  out.plane = plane;
  out.found = true;
  std::vector<char>& in_plane = out.in_plane;
  detail::parallel_for(static_cast<int>(f.size()), g.threads,
                       [&](int p) { in_plane[p] = g.valid(p) && inlier(plane, p); });
  return out;
}

// Pixels on a concave crease: the normals `step` pixels to either side (along the row, the
// column or a diagonal) differ by more than the tolerance and turn towards each other, the
// convexity criterion of Stein et al. (LCCP, CVPR 2014). Objects meet their support and each
// other in concave creases; the faces of one object meet in convex ones.
std::vector<char> concave_pixels(const ImageGrid& g, const std::vector<Eigen::Vector3f>& normals,
                                 const SelectionParams& params) {
  const Frame& f = g.frame;
  const int s = params.image.concavity_step;
  const float cos_tol =
      static_cast<float>(std::cos(detail::radians(params.image.crease_tolerance_deg)));
  std::vector<char> concave(f.size(), 0);
  static constexpr int kDirs[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
  detail::parallel_for(g.h(), g.threads, [&](int v) {
    for (int u = 0; u < g.w(); ++u) {
      const int p = v * g.w() + u;
      if (!g.valid(p)) continue;
      for (const auto& d : kDirs) {
        const int ua = u - s * d[0], va = v - s * d[1], ub = u + s * d[0], vb = v + s * d[1];
        if (ua < 0 || ub < 0 || ua >= g.w() || ub >= g.w() || va < 0 || vb < 0 || va >= g.h() ||
            vb >= g.h())
          continue;
        const int a = va * g.w() + ua, b = vb * g.w() + ub;
        // The normals first: parallel ones (most pairs) end the test. A pixel without a normal
        // (missing ones have none) makes the product NaN, which fails here and below.
        const float cos_ab = normals[a].dot(normals[b]);
        if (!(cos_ab < cos_tol)) continue;
        if (!g.continuous(a, p, s) || !g.continuous(p, b, s)) continue;
        if ((normals[a] - normals[b]).dot(f.xyz[a] - f.xyz[b]) < 0) {
          concave[p] = 1;
          break;
        }
      }
    }
  });
  return concave;
}

// Connected components (4-neighbours, no depth step) of the pixels where open[p]; ids in the
// order of their first pixel. Returns the component of every pixel (kNone elsewhere).
std::vector<int> components(const ImageGrid& g, const std::vector<char>& open, int& count) {
  std::vector<int> comp(g.frame.size(), kNone);
  std::vector<int> stack;
  count = 0;
  for (int seed = 0; seed < static_cast<int>(comp.size()); ++seed) {
    if (!open[seed] || comp[seed] != kNone) continue;
    comp[seed] = count;
    stack.push_back(seed);
    while (!stack.empty()) {
      const int p = stack.back();
      stack.pop_back();
      for (int q : g.neighbours(p))
        if (q >= 0 && open[q] && comp[q] == kNone && g.continuous(p, q)) {
          comp[q] = count;
          stack.push_back(q);
        }
    }
    ++count;
  }
  return comp;
}

// Valid pixels left out of every component (the creases themselves, specks) take the component
// of the nearest labelled pixel they reach without crossing a depth step (breadth first, so the
// nearest in steps; ties to the earlier pixel). The plane does not grow.
void fill(const ImageGrid& g, std::vector<int>& comp) {
  std::deque<int> queue;
  for (int p = 0; p < static_cast<int>(comp.size()); ++p)
    if (comp[p] >= 0) queue.push_back(p);
  while (!queue.empty()) {
    const int p = queue.front();
    queue.pop_front();
    for (int q : g.neighbours(p))
      if (q >= 0 && comp[q] == kNone && g.valid(q) && g.continuous(p, q)) {
        comp[q] = comp[p];
        queue.push_back(q);
      }
  }
}

// Links between components that meet the way the parts of one surface do, across what the
// components could not bridge. Two kinds: pixel pairs at most image.merge_window pixels apart whose
// points lie within cluster_tolerance (a short depth step, a speck of missing pixels), and rays
// across a band of missing pixels (a mug's rim that the camera lost) of at most image.bridge_window
// pixels whose ends lie within image.bridge_tolerance. A link is concave when it starts or ends on
// a crease pixel or its normals fail LCCP's convexity test; it agrees when both ends have the same
// segmentation label (colour and texture [3.1-3.2]). Two components merge when they have at
// least image.merge_min_links links, at most merge_max_concave_share of them concave and at least
// image.merge_min_agreement of them agreeing. The plane takes no part.
struct LinkCount {
  int links = 0, concave = 0, agree = 0;  // window links
  int bridges = 0;                        // rays across missing pixels
};

// Whether points lie in the support plane within background_plane_distance (at least
// background_inlier_ratio of them): the test for a piece of the plane rather than of an object.
bool on_plane(const Frame& f, const SupportPlane& support, const std::vector<int>& points,
              const SelectionParams& params) {
  if (!support.found || points.empty()) return false;
  std::size_t near = 0;
  for (int p : points)
    near += std::abs(support.plane.distance(f.xyz[p])) <= params.background_plane_distance;
  return near >= params.background_inlier_ratio * points.size();
}

// A component that meets the support plane without a crease and lies in it is a piece of the
// plane that left the sensor-noise band (the lens bends depth towards the image corners): it
// joins it.
bool plane_piece(const Frame& f, const SupportPlane& support, const std::vector<int>& points,
                 const LinkCount& to_plane, const SelectionParams& params) {
  return to_plane.links >= params.image.merge_min_links &&
         to_plane.concave <= params.merge_max_concave_share * to_plane.links &&
         on_plane(f, support, points, params);
}

// The merges the links decide [docs/method.md, rule 6]: pieces of the support plane go back to
// it, components join where enough links agree and few are concave, islands in missing data join
// the component they have the most rays to.
void join_linked(const Frame& f, const SupportPlane& support, const SelectionParams& params,
                 const std::map<std::pair<int, int>, LinkCount>& links,
                 const std::vector<int>& border_pixels, const std::vector<int>& beside_missing,
                 int count, std::vector<int>& comp) {
  detail::UnionFind sets(static_cast<std::size_t>(count));
  std::vector<std::vector<int>> points(count);
  for (int p = 0; p < static_cast<int>(comp.size()); ++p)
    if (comp[p] >= 0) points[comp[p]].push_back(p);
  std::vector<char> to_plane(count, 0);
  for (const auto& [pair, e] : links)
    if (pair.second == kPlane)
      to_plane[pair.first] = plane_piece(f, support, points[pair.first], e, params);
  for (const auto& [pair, e] : links)
    if (pair.second != kPlane && e.links >= params.image.merge_min_links &&
        e.concave <= params.merge_max_concave_share * e.links &&
        e.agree >= params.image.merge_min_agreement * e.links)
      sets.unite(pair.first, pair.second);
  // An island in missing data (most of its border beside missing pixels: the inside of a mug
  // whose rim the camera lost all round) joins the component it has the most rays to.
  std::vector<std::pair<int, int>> best_bridge(count, {0, -1});  // (rays, component)
  for (const auto& [pair, e] : links)
    if (pair.second != kPlane)
      for (const auto& [x, y] : {pair, std::pair{pair.second, pair.first}})
        if (e.bridges > best_bridge[x].first) best_bridge[x] = {e.bridges, y};
  for (int c = 0; c < count; ++c)
    if (border_pixels[c] > 0 &&
        beside_missing[c] >= params.image.island_missing_share * border_pixels[c] &&
        best_bridge[c].first >= params.image.merge_min_links)
      sets.unite(c, best_bridge[c].second);
  for (int& c : comp)
    if (c >= 0) c = to_plane[c] ? kPlane : sets.find(c);
}

void merge_convex_links(const ImageGrid& g, const std::vector<Eigen::Vector3f>& normals,
                        const std::vector<char>& crease, const SupportPlane& support,
                        const std::vector<std::uint32_t>& point_labels,
                        const SelectionParams& params, int count, std::vector<int>& comp) {
  const Frame& f = g.frame;
  const float cos_tol =
      static_cast<float>(std::cos(detail::radians(params.image.crease_tolerance_deg)));
  std::map<std::pair<int, int>, LinkCount> links;
  auto bridge_link = [&](int p, int q) {
    ++links[{std::min(comp[p], comp[q]), std::max(comp[p], comp[q])}].bridges;
  };
  auto link = [&](int p, int q) {
    bool concave = crease[p] || crease[q];
    if (!concave && has_normal(normals[p]) && has_normal(normals[q]))
      concave = normals[p].dot(normals[q]) < cos_tol &&
                (normals[p] - normals[q]).dot(f.xyz[p] - f.xyz[q]) < 0;
    // The plane's links are kept under (component, kPlane).
    LinkCount& e = comp[q] == kPlane ? links[{comp[p], kPlane}]
                   : comp[p] == kPlane
                       ? links[{comp[q], kPlane}]
                       : links[{std::min(comp[p], comp[q]), std::max(comp[p], comp[q])}];
    ++e.links;
    e.concave += concave;
    e.agree += point_labels[p] == point_labels[q];
  };
  // Pixels at the border of their component: the only ones that can link to another.
  auto border = [&](int p) {
    for (int q : g.neighbours(p))
      if (q < 0 || comp[q] != comp[p]) return true;
    return false;
  };
  const int win = params.image.merge_window, bridge = params.image.bridge_window;
  const float t2 = static_cast<float>(params.cluster_tolerance * params.cluster_tolerance);
  const float b2 =
      static_cast<float>(params.image.bridge_tolerance * params.image.bridge_tolerance);
  static constexpr int kRays[4][2] = {{1, 0}, {0, 1}, {1, 1}, {-1, 1}};  // later pixels
  // Per component: border pixels, and those of them beside a missing pixel.
  std::vector<int> border_pixels(count, 0), beside_missing(count, 0);
  for (int v = 0; v < g.h(); ++v)
    for (int u = 0; u < g.w(); ++u) {
      const int p = v * g.w() + u, a = comp[p];
      if (a < 0 || !border(p)) continue;
      ++border_pixels[a];
      for (int q : g.neighbours(p))
        if (q >= 0 && !g.valid(q)) {
          ++beside_missing[a];
          break;
        }
      for (int dv = 0; dv <= win; ++dv)
        for (int du = -win; du <= win; ++du) {
          if (dv == 0 && du <= 0) continue;  // each unordered pair once
          const int uq = u + du, vq = v + dv;
          if (uq < 0 || uq >= g.w() || vq >= g.h()) continue;
          const int q = vq * g.w() + uq;
          if ((comp[q] >= 0 || comp[q] == kPlane) && comp[q] != a &&
              (f.xyz[p] - f.xyz[q]).squaredNorm() <= t2)
            link(p, q);
        }
      // Rays forward only: the ray from the far end back to p is the same ray.
      for (const auto& d : kRays)
        for (int k = 1; k <= bridge; ++k) {
          const int uq = u + k * d[0], vq = v + k * d[1];
          if (uq < 0 || uq >= g.w() || vq >= g.h()) break;
          const int q = vq * g.w() + uq;
          if (!g.valid(q)) continue;  // still in the band of missing pixels
          if (k > 1 && comp[q] >= 0 && comp[q] != a && (f.xyz[p] - f.xyz[q]).squaredNorm() <= b2)
            bridge_link(p, q);
          break;
        }
    }
  join_linked(f, support, params, links, border_pixels, beside_missing, count, comp);
}

// Components under min_points join the neighbour (another component or the plane) they share the
// longest depth-continuous border with (ties: the smaller id); two rounds, so a piece beside a
// piece also finds a home. The plane takes only pieces that lie in it: a small object on the
// table (a marker, a duck seen from far) is not table. With `drop`, pieces still small afterwards
// are left out of every instance.
void absorb_small(const ImageGrid& g, const SupportPlane& support, const SelectionParams& params,
                  int count, bool drop, std::vector<int>& comp) {
  const int min_points = params.min_candidate_points;
  auto small = [&](int size) { return size > 0 && size < min_points; };
  std::vector<int> size(count, 0);  // kept up to date as pieces move
  for (int c : comp)
    if (c >= 0) ++size[c];
  for (int round = 0; round < 2; ++round) {
    if (std::none_of(size.begin(), size.end(), small)) break;
    // Only the small components' pixels are needed (their border, their fit to the plane).
    std::vector<std::vector<int>> points(count);
    std::vector<std::map<int, int>> contact(count);  // small -> neighbour -> border length
    for (int p = 0; p < static_cast<int>(comp.size()); ++p) {
      const int a = comp[p];
      if (a < 0 || !small(size[a])) continue;
      points[a].push_back(p);
      for (int q : g.neighbours(p))
        if (q >= 0 && comp[q] != kNone && comp[q] != a && g.continuous(p, q)) ++contact[a][comp[q]];
    }
    // Every small piece moves at once, to where its neighbour was before this round.
    std::vector<int> arriving(count, 0);
    bool changed = false;
    for (int c = 0; c < count; ++c) {
      if (!small(size[c])) continue;
      const bool plane_ok = on_plane(g.frame, support, points[c], params);
      int best = kNone, longest = 0;
      for (const auto& [n, length] : contact[c])
        if (length > longest && (n != kPlane || plane_ok)) best = n, longest = length;
      if (best == kNone) continue;
      for (int p : points[c]) comp[p] = best;
      if (best >= 0) arriving[best] += size[c];
      size[c] = 0;
      changed = true;
    }
    for (int c = 0; c < count; ++c) size[c] += arriving[c];
    if (!changed) break;
  }
  if (!drop || std::none_of(size.begin(), size.end(), small)) return;
  for (int& c : comp)
    if (c >= 0 && small(size[c])) c = kNone;
}

// Pixels of a component that lie within image.plane_flat_sigmas of the sensor's noise of the
// support plane go to the plane. The normals of the table beside an object are bent by it over
// image.normal_step pixels, so that ring fails the plane's normal test and joins the object: as
// many table pixels as pen pixels around a pen lying on the table (IoU under 0.5). The structure
// (links, plane pieces, small pieces) was decided with the ring; only the instances lose it.
void trim_flat_base(const ImageGrid& g, const SupportPlane& support, const SelectionParams& params,
                    std::vector<int>& comp) {
  if (!support.found || params.image.plane_flat_sigmas <= 0) return;
  const float k =
      static_cast<float>(params.image.plane_flat_sigmas * params.image.sensor_noise_at_1m);
  detail::parallel_for(static_cast<int>(comp.size()), g.threads, [&](int p) {
    if (comp[p] < 0 || !g.valid(p)) return;
    const float z = g.z(p);
    if (std::abs(support.plane.distance(g.frame.xyz[p])) <= k * z * z) comp[p] = kPlane;
  });
}

}  // namespace

ImageSurfaces image_surfaces(const Frame& frame, const std::vector<char>& labelled,
                             const SelectionParams& params, int threads) {
  if (!frame.organized()) throw std::invalid_argument("image_surfaces: unorganized frame");
  const int nthreads = detail::thread_count(threads);
  detail::Stopwatch watch;
  const ImageGrid grid(frame, static_cast<float>(params.image.depth_step_ratio), nthreads);
  ImageSurfaces out;
  FeatureParams normal_params;
  normal_params.normal_step = params.image.normal_step;
  if (params.image.edge_aware_normals)
    normal_params.normal_edge_ratio = params.image.depth_step_ratio;
  out.normals = point_normals(frame, normal_params, nthreads);
  out.steps_ms.emplace_back("normals", watch.lap());

  // The support plane first: what lies in it within the sensor's noise is background.
  SupportPlane support;
  if (params.cut_support_plane)
    support = support_plane(grid, out.normals, params);
  else
    support.in_plane.assign(frame.size(), 0);
  out.steps_ms.emplace_back("support_plane", watch.lap());
  // Surfaces: what no depth step or concave crease separates.
  out.crease = params.split_concave ? concave_pixels(grid, out.normals, params)
                                    : std::vector<char>(frame.size(), 0);
  out.steps_ms.emplace_back("creases", watch.lap());
  std::vector<char> open(frame.size(), 0);
  for (std::size_t p = 0; p < frame.size(); ++p)
    open[p] = frame.valid(p) && labelled[p] && !support.in_plane[p] && !out.crease[p];
  out.surface = components(grid, open, out.count);
  for (std::size_t p = 0; p < frame.size(); ++p)
    if (support.in_plane[p] && labelled[p]) out.surface[p] = kPlane;
  fill(grid, out.surface);
  out.steps_ms.emplace_back("surfaces", watch.lap());
  if (params.absorb_small) absorb_small(grid, support, params, out.count, false, out.surface);
  out.steps_ms.emplace_back("small_pieces", watch.lap());
  out.plane_found = support.found;
  out.plane_normal = support.plane.normal;
  out.plane_offset = support.plane.offset;
  out.in_plane = std::move(support.in_plane);
  return out;
}

Selection select_candidates_on_image(const Frame& frame,
                                     const std::vector<std::uint32_t>& point_labels,
                                     const SelectionParams& params, int threads) {
  std::vector<char> labelled(frame.size(), 0);
  for (std::size_t p = 0; p < frame.size(); ++p) labelled[p] = point_labels[p] != 0;
  return select_on_image(frame, image_surfaces(frame, labelled, params, threads), point_labels,
                         params, threads);
}

Selection select_on_image(const Frame& frame, ImageSurfaces surfaces,
                          const std::vector<std::uint32_t>& point_labels,
                          const SelectionParams& params, int threads) {
  const int nthreads = detail::thread_count(threads);
  const ImageGrid grid(frame, static_cast<float>(params.image.depth_step_ratio), nthreads);
  SupportPlane support;
  support.found = surfaces.plane_found;
  support.plane = {surfaces.plane_normal, surfaces.plane_offset};
  support.in_plane = std::move(surfaces.in_plane);
  std::vector<int>& comp = surfaces.surface;
  const int count = surfaces.count;
  Selection s;
  s.instance.assign(frame.size(), 0);
  s.clusters = count;
  detail::Stopwatch watch;
  if (params.image.merge_links)
    merge_convex_links(grid, surfaces.normals, surfaces.crease, support, point_labels, params,
                       count, comp);
  s.steps_ms.emplace_back("convex_merge", watch.lap());
  if (params.absorb_small) absorb_small(grid, support, params, count, true, comp);
  s.steps_ms.emplace_back("small_pieces", watch.lap());
  if (params.occlusion.enabled)
    detail::join_occluded_pieces(grid, surfaces.normals, params, count, comp);
  s.steps_ms.emplace_back("occlusion_join", watch.lap());
  trim_flat_base(grid, support, params, comp);
  s.steps_ms.emplace_back("ring_trim", watch.lap());
  if (params.containers.enabled && support.found)
    detail::join_container_pieces(grid, support.plane, params, count, comp);
  s.steps_ms.emplace_back("container_join", watch.lap());

  // Instances in the order of their first pixel; the plane is one background instance.
  auto slot_of = [count](int c) { return c == kPlane ? count : c; };  // surfaces, then the plane
  std::vector<int> slot(static_cast<std::size_t>(count) + 1, -1);     // -> index in found
  std::vector<Candidate> found;
  for (std::size_t p = 0; p < frame.size(); ++p) {
    if (comp[p] == kNone) continue;
    int& i = slot[slot_of(comp[p])];
    if (i < 0) {
      i = static_cast<int>(found.size());
      found.emplace_back();
    }
    found[i].points.push_back(static_cast<int>(p));
  }
  std::vector<char> keep(found.size(), 0);
  // Each candidate is described by one iteration (boxes are the costly part): any thread.
  detail::parallel_for(
      count + 1, nthreads,
      [&](int c) {
        const int i = slot[c];
        if (i < 0) return;
        Candidate& cand = found[i];
        const bool plane = c == count;
        if (!plane && static_cast<int>(cand.points.size()) < params.min_candidate_points) return;
        keep[i] = 1;
        cand.label = point_labels[cand.points[0]];
        describe_shape(frame, cand);
        cand.background = plane || is_background(frame, cand, params);
      },
      1);
  for (std::size_t i = 0; i < found.size(); ++i) {
    if (!keep[i]) continue;
    Candidate& cand = found[i];
    cand.instance = static_cast<std::uint32_t>(s.components.size() + 1);
    for (int p : cand.points) s.instance[p] = cand.instance;
    s.components.push_back(std::move(cand));
  }
  s.steps_ms.emplace_back("candidates", watch.lap());
  return s;
}

}  // namespace proxseg
