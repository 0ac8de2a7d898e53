// Selection [paper 3.3]: clusters are connected sets of same-label voxels; each is split at weak
// (low-density) connections by Euclidean clustering of its dense points; the large components
// become candidates, large supporting planes background.
#include <proxseg/core/selection.hpp>

#include "selection_detail.hpp"
#include "util/angles.hpp"
#include "util/moments.hpp"
#include "util/nearest_points.hpp"
#include "util/parallel_for.hpp"
#include "util/union_find.hpp"
#include "weak_links.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <numeric>
#include <unordered_map>

namespace proxseg {
namespace {

using detail::DensitySplit;
using detail::euclidean_components;
using detail::reattach_weak_points;
using detail::split_weak_points;

// Local surface of every voxel: centroid and normal (smallest principal axis of its points,
// turned towards the sensor at the origin); voxels with fewer than 3 points have no normal.
struct VoxelSurface {
  std::vector<Eigen::Vector3f> centroid, normal;
  std::vector<char> has_normal;
};

VoxelSurface voxel_surface(const Frame& frame, const VoxelGrid& grid, int threads) {
  VoxelSurface vs;
  vs.centroid.assign(grid.size(), Eigen::Vector3f::Zero());
  vs.normal.assign(grid.size(), Eigen::Vector3f::Zero());
  vs.has_normal.assign(grid.size(), 0);
  detail::parallel_for(
      static_cast<int>(grid.size()), detail::thread_count(threads),
      [&](int v) {
        const auto& pts = grid.points[v];
        const auto [mean, scatter] =
            detail::moments(pts.size(), [&](std::size_t j) { return frame.xyz[pts[j]]; });
        vs.centroid[v] = mean.cast<float>();
        if (pts.size() < 3) return;
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
        eig.computeDirect(scatter);
        // Points along a line (a voxel clipping an edge of the cloud) have no defined normal.
        if (eig.eigenvalues()[1] < 0.01 * eig.eigenvalues()[2]) return;
        Eigen::Vector3d n = eig.eigenvectors().col(0);
        if (n.dot(-mean) < 0) n = -n;
        vs.normal[v] = n.cast<float>();
        vs.has_normal[v] = 1;
      },
      64);
  return vs;
}

// The convexity criterion of Stein et al. (LCCP, CVPR 2014) on voxels: two neighbouring surface
// patches meet in a concave edge when their normals differ by more than the tolerance and turn
// towards each other, (n_u - n_v) . (x_u - x_v) < 0. Objects meet their support and each other in
// concave edges; the faces of one object meet in convex ones.
bool concave(const VoxelSurface& vs, int u, int v, float cos_tolerance) {
  if (!vs.has_normal[u] || !vs.has_normal[v]) return false;
  if (vs.normal[u].dot(vs.normal[v]) >= cos_tolerance) return false;
  return (vs.normal[u] - vs.normal[v]).dot(vs.centroid[u] - vs.centroid[v]) < 0;
}

// The dominant supporting plane (table, floor) as a set of voxels: the plane through a voxel's
// centroid along its normal that gathers the most points of voxels lying in it with a parallel
// normal. Hypotheses are an even spread of voxels, so there is no randomness. Returns per voxel
// whether it lies in the plane; all false if the best plane covers less than min_area.
std::vector<char> support_plane(const VoxelGrid& grid, const VoxelSurface& vs,
                                const SelectionParams& params, int threads) {
  std::vector<int> candidates;
  for (std::size_t v = 0; v < grid.size(); ++v)
    if (vs.has_normal[v]) candidates.push_back(static_cast<int>(v));
  std::vector<char> in_plane(grid.size(), 0);
  if (candidates.empty()) return in_plane;
  const float cos_tol =
      static_cast<float>(std::cos(detail::radians(params.support_normal_tolerance_deg)));
  const float dist = static_cast<float>(params.background_plane_distance);
  auto inlier = [&](int h, int v) {
    return std::abs(vs.normal[h].dot(vs.centroid[v] - vs.centroid[h])) <= dist &&
           std::abs(vs.normal[h].dot(vs.normal[v])) >= cos_tol;
  };
  const int hypotheses = std::min<int>(300, candidates.size());
  std::vector<std::size_t> support(hypotheses, 0);
  detail::parallel_for(
      hypotheses, detail::thread_count(threads),
      [&](int i) {
        const int h = candidates[static_cast<std::size_t>(i) * candidates.size() / hypotheses];
        for (int v : candidates)
          if (inlier(h, v)) support[i] += grid.points[v].size();
      },
      8);
  const int best =
      static_cast<int>(std::max_element(support.begin(), support.end()) - support.begin());
  const int h = candidates[static_cast<std::size_t>(best) * candidates.size() / hypotheses];
  std::size_t voxels = 0;
  for (int v : candidates)
    if (inlier(h, v)) in_plane[v] = 1, ++voxels;
  // Voxels without a normal (too few points, or collinear ones) join the plane by distance alone.
  for (std::size_t v = 0; v < grid.size(); ++v)
    if (!vs.has_normal[v] && !grid.points[v].empty() &&
        std::abs(vs.normal[h].dot(vs.centroid[v] - vs.centroid[h])) <= dist)
      in_plane[v] = 1;
  const double area = voxels * grid.voxel_size * grid.voxel_size;
  if (area < params.background_min_area) std::fill(in_plane.begin(), in_plane.end(), 0);
  return in_plane;
}

// Clusters [3.3]: connected components of same-label voxels over the 26-neighbourhood; with
// split_concave, concave edges do not connect either.
std::vector<int> voxel_clusters(const VoxelGrid& grid, const std::vector<std::uint32_t>& labels,
                                const VoxelSurface& surface, const std::vector<char>& in_plane,
                                const SelectionParams& params, int& count) {
  const float cos_tolerance =
      static_cast<float>(std::cos(detail::radians(params.voxels.concavity_tolerance_deg)));
  std::vector<std::uint32_t> voxel_label(grid.size(), 0);
  for (std::size_t v = 0; v < grid.size(); ++v)
    if (!grid.points[v].empty()) voxel_label[v] = labels[grid.points[v][0]];
  std::vector<int> cluster(grid.size(), -1);
  count = 0;
  std::deque<int> queue;
  for (std::size_t seed = 0; seed < grid.size(); ++seed) {
    if (cluster[seed] >= 0 || voxel_label[seed] == 0) continue;
    cluster[seed] = count;
    queue.push_back(static_cast<int>(seed));
    while (!queue.empty()) {
      const int v = queue.front();
      queue.pop_front();
      for (int n : grid.neighbours[v])
        if (cluster[n] < 0 && voxel_label[n] == voxel_label[v] && in_plane[n] == in_plane[v] &&
            !(params.split_concave && concave(surface, v, n, cos_tolerance))) {
          cluster[n] = count;
          queue.push_back(n);
        }
    }
    ++count;
  }
  return cluster;
}

// The component of every voxel: that of its first point (-1 for none). Voxels are almost never
// split between components, so one point speaks for the voxel.
std::vector<int> voxel_components(const VoxelGrid& grid, const std::vector<int>& component) {
  std::vector<int> out(grid.size(), -1);
  for (std::size_t v = 0; v < grid.size(); ++v)
    if (!grid.points[v].empty()) out[v] = component[grid.points[v][0]];
  return out;
}

// Merges neighbouring components whose common boundary is convex or flat (at most
// merge_max_concave_share of its voxel edges concave): the faces of one object that the
// features told apart. Returns the merged component of every point.
void merge_convex(const VoxelGrid& grid, const VoxelSurface& surface, const SelectionParams& params,
                  const std::map<int, const Candidate*>& background,
                  const std::map<int, const Candidate*>& pieces, std::vector<int>& component) {
  const float cos_tolerance =
      static_cast<float>(std::cos(detail::radians(params.voxels.concavity_tolerance_deg)));
  const std::vector<int> voxel_component = voxel_components(grid, component);
  std::map<std::pair<int, int>, std::pair<int, int>> boundary;  // (a, b) -> (edges, concave)
  for (std::size_t u = 0; u < grid.size(); ++u)
    for (int v : grid.neighbours[u]) {
      const int a = voxel_component[u], b = voxel_component[v];
      if (static_cast<int>(u) >= v || a < 0 || b < 0 || a == b) continue;
      auto& e = boundary[{std::min(a, b), std::max(a, b)}];
      ++e.first;
      e.second += concave(surface, static_cast<int>(u), v, cos_tolerance);
    }
  const int count =
      component.empty() ? 0 : *std::max_element(component.begin(), component.end()) + 1;
  detail::UnionFind sets(static_cast<std::size_t>(std::max(count, 0)));
  auto coplanar = [&](const Candidate& a, const Candidate& b) {
    const Eigen::Vector3d na = a.box.axes.col(2), nb = b.box.axes.col(2);
    return std::abs(na.dot(nb)) >= cos_tolerance &&
           std::abs(na.dot(b.centroid - a.centroid)) <= 2 * params.background_plane_distance;
  };
  for (const auto& [pair, e] : boundary) {
    const auto a = background.find(pair.first), b = background.find(pair.second);
    const int in_background = (a != background.end()) + (b != background.end());
    const bool join = in_background == 2 ? coplanar(*a->second, *b->second)
                      : in_background == 1
                          ? coplanar(*(a != background.end() ? a : b)->second,
                                     *pieces.at(a != background.end() ? pair.second : pair.first))
                          : e.first >= params.voxels.merge_min_boundary &&
                                e.second <= params.merge_max_concave_share * e.first;
    if (join) sets.unite(pair.first, pair.second);
  }
  for (int& c : component)
    if (c >= 0) c = sets.find(c);
}

}  // namespace

namespace {

// Section 3.3's clusters per point: every labelled point joins its voxel's cluster (-1: none).
std::vector<int> point_clusters(const Frame& frame, const VoxelGrid& grid,
                                const std::vector<std::uint32_t>& point_labels,
                                const std::vector<int>& voxel_cluster, std::vector<int>& labelled) {
  std::vector<int> cluster(frame.size(), -1);
  for (std::size_t p = 0; p < frame.size(); ++p) {
    const int v = grid.voxel_of_point[p];
    if (v >= 0 && point_labels[p] && voxel_cluster[v] >= 0) {
      cluster[p] = voxel_cluster[v];
      labelled.push_back(static_cast<int>(p));
    }
  }
  return cluster;
}

// The components' points, components in order of their smallest point index. Their box,
// centroid and background flag are computed only where a step needs them (describe_component).
std::vector<Candidate> group_components(const std::vector<int>& component) {
  std::unordered_map<int, int> slot;
  std::vector<Candidate> out;
  for (std::size_t p = 0; p < component.size(); ++p) {
    if (component[p] < 0) continue;
    const auto [it, added] = slot.emplace(component[p], static_cast<int>(out.size()));
    if (added) out.emplace_back();
    out[it->second].points.push_back(static_cast<int>(p));
  }
  return out;
}

void describe_component(const Frame& frame, const std::vector<std::uint32_t>& point_labels,
                        const SelectionParams& params, Candidate& c) {
  c.label = point_labels[c.points[0]];
  describe_shape(frame, c);
  c.background = static_cast<int>(c.points.size()) >= params.min_candidate_points &&
                 is_background(frame, c, params);
}

// Neighbouring components that meet in a convex or flat boundary are merged, and coplanar
// pieces of the background with each other; objects never join the background. Pieces of the
// support plane count as background here, whatever their size: an object must not reach the
// table through a small piece of it.
void merge_convex_components(const Frame& frame, const VoxelGrid& grid, const VoxelSurface& surface,
                             const std::vector<char>& in_plane,
                             const std::vector<std::uint32_t>& point_labels,
                             const SelectionParams& params, std::vector<Candidate>& components,
                             std::vector<int>& component) {
  std::map<int, const Candidate*> background, pieces;
  for (Candidate& c : components) {
    describe_component(frame, point_labels, params, c);
    std::size_t on_plane = 0;
    for (int p : c.points) on_plane += in_plane[grid.voxel_of_point[p]];
    pieces[component[c.points[0]]] = &c;
    if (c.background || 2 * on_plane > c.points.size()) background[component[c.points[0]]] = &c;
  }
  merge_convex(grid, surface, params, background, pieces, component);
  components = group_components(component);
}

// Small components join the large neighbour they share the most voxel edges with (two rounds,
// so that a fragment beside a fragment also finds a home); the rest stay unassigned.
void absorb_small_components(const VoxelGrid& grid, const SelectionParams& params,
                             std::vector<Candidate>& components, std::vector<int>& component) {
  for (int round = 0; round < 2; ++round) {
    std::map<int, bool> large;
    for (const Candidate& c : components)
      large[component[c.points[0]]] =
          static_cast<int>(c.points.size()) >= params.min_candidate_points;
    const std::vector<int> voxel_component = voxel_components(grid, component);
    std::map<int, std::map<int, int>> contact;  // small -> large -> voxel edges
    for (std::size_t u = 0; u < grid.size(); ++u) {
      const int a = voxel_component[u];
      if (a < 0 || large[a]) continue;
      for (int v : grid.neighbours[u]) {
        const int b = voxel_component[v];
        if (b >= 0 && b != a && large[b]) ++contact[a][b];
      }
    }
    std::map<int, int> target;
    for (const auto& [small, counts] : contact)
      target[small] = std::max_element(counts.begin(), counts.end(), [](auto& x, auto& y) {
                        return x.second < y.second;
                      })->first;
    if (target.empty()) break;
    for (int& c : component)
      if (c >= 0 && target.count(c)) c = target[c];
    components = group_components(component);
  }
}

}  // namespace

// Section 3.3 on the voxel grid: clusters of same-label voxels, their weak connections cut,
// Euclidean components of the rest, optionally merged across convex boundaries and with small
// fragments absorbed; the large ones become the candidates (instances 1..n).
Selection select_candidates(const Frame& frame, const VoxelGrid& grid,
                            const std::vector<std::uint32_t>& point_labels,
                            const SelectionParams& params, int threads) {
  Selection s;
  s.instance.assign(frame.size(), 0);
  const VoxelSurface surface = voxel_surface(frame, grid, threads);
  // The supporting plane, when cut out, separates the objects from what they stand on.
  const std::vector<char> in_plane = params.cut_support_plane
                                         ? support_plane(grid, surface, params, threads)
                                         : std::vector<char>(grid.size(), 0);
  const std::vector<int> voxel_cluster =
      voxel_clusters(grid, point_labels, surface, in_plane, params, s.clusters);
  std::vector<int> labelled;
  const std::vector<int> cluster =
      point_clusters(frame, grid, point_labels, voxel_cluster, labelled);
  const DensitySplit split =
      split_weak_points(frame, labelled, cluster, s.clusters, params, threads);
  s.weak_points = split.set_aside.size();
  std::vector<int> component =
      euclidean_components(frame, split.dense, cluster, params.cluster_tolerance);
  reattach_weak_points(frame, grid, split, cluster, s.clusters, component);
  std::vector<Candidate> components = group_components(component);
  if (params.voxels.merge_convex)
    merge_convex_components(frame, grid, surface, in_plane, point_labels, params, components,
                            component);
  if (params.absorb_small) absorb_small_components(grid, params, components, component);
  for (Candidate& c : components) {  // the large components become instances
    if (static_cast<int>(c.points.size()) < params.min_candidate_points) continue;
    describe_component(frame, point_labels, params, c);
    c.instance = static_cast<std::uint32_t>(s.components.size() + 1);
    for (int p : c.points) s.instance[p] = c.instance;
    s.components.push_back(std::move(c));
  }
  return s;
}

}  // namespace proxseg
