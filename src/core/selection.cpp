// Selection [paper 3.3]: clusters are connected sets of same-label voxels; each is split at weak
// (low-density) connections by Euclidean clustering of its dense points; the large components
// become candidates, large supporting planes background.
#include <proxseg/core/selection.hpp>

#include "selection_detail.hpp"
#include "util/moments.hpp"
#include "util/nearest_points.hpp"
#include "util/parallel_for.hpp"
#include "util/union_find.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <numeric>
#include <unordered_map>
#include "util/angles.hpp"

namespace proxseg {
namespace {

// Points grouped by (cluster, cell): a sorted index with a hash from cell to its range, so that
// neighbourhood queries touch only nearby cells and never iterate a hash map (determinism).
struct CellKey {
  int group, x, y, z;
  bool operator==(const CellKey& o) const {
    return group == o.group && x == o.x && y == o.y && z == o.z;
  }
  bool operator<(const CellKey& o) const {
    return std::tie(group, z, y, x) < std::tie(o.group, o.z, o.y, o.x);
  }
};
// Open addressing with linear probing: most neighbourhood queries miss, and a miss here costs one
// or two probes of a flat array (std::unordered_map made the selection three times slower).
class CellMap {
 public:
  explicit CellMap(std::size_t n = 0) {
    std::size_t size = 16;
    while (size < 4 * n) size *= 2;  // load under 1/4: a miss usually ends at the first slot
    mask_ = size - 1;
    slots_.assign(size, Slot{});
  }
  void insert(const CellKey& k, int value) {
    std::size_t i = hash(k) & mask_;
    while (slots_[i].value >= 0) i = (i + 1) & mask_;
    slots_[i] = {k, value};
  }
  int find(const CellKey& k) const {
    for (std::size_t i = hash(k) & mask_;; i = (i + 1) & mask_) {
      const Slot& s = slots_[i];
      if (s.value < 0) return -1;
      if (s.key == k) return s.value;
    }
  }

 private:
  struct Slot {
    CellKey key{0, 0, 0, 0};
    int value = -1;
  };
  static std::size_t hash(const CellKey& k) {
    std::uint64_t h = static_cast<std::uint32_t>(k.group) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<std::uint32_t>(k.x) * 0xBF58476D1CE4E5B9ull;
    h ^= static_cast<std::uint32_t>(k.y) * 0x94D049BB133111EBull;
    h ^= static_cast<std::uint32_t>(k.z) * 0xD6E8FEB86659FD93ull;
    // MurmurHash3's finaliser: the products above leave the low bits (the ones the mask keeps)
    // poorly mixed, which made probe chains long.
    h ^= h >> 33;
    h *= 0xFF51AFD7ED558CCDull;
    h ^= h >> 33;
    h *= 0xC4CEB9FE1A85EC53ull;
    h ^= h >> 33;
    return static_cast<std::size_t>(h);
  }
  std::size_t mask_;
  std::vector<Slot> slots_;  // key and value side by side: one cache line per probe
};

class CellIndex {
 public:
  CellIndex(const Frame& frame, const std::vector<int>& points, const std::vector<int>& group,
            double cell)
      : frame_(frame), inv_(1.0 / cell) {
    std::vector<std::pair<CellKey, int>> keyed;
    keyed.reserve(points.size());
    for (int p : points) keyed.emplace_back(key(p, group[p]), p);
    std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) {
      return a.first < b.first || (a.first == b.first && a.second < b.second);
    });
    order_.reserve(keyed.size());
    for (std::size_t i = 0; i < keyed.size(); ++i) {
      if (i == 0 || !(keyed[i].first == keyed[i - 1].first)) {
        cells_.push_back(keyed[i].first);
        begin_.push_back(static_cast<int>(i));
      }
      order_.push_back(keyed[i].second);
    }
    begin_.push_back(static_cast<int>(keyed.size()));
    lookup_ = CellMap(cells_.size());
    for (std::size_t c = 0; c < cells_.size(); ++c) lookup_.insert(cells_[c], static_cast<int>(c));
  }

  // Cell coordinates are clamped to the int range: points that far out are garbage anyway, and
  // clamping keeps the arithmetic defined.
  CellKey key(int p, int group) const {
    const Eigen::Vector3f& q = frame_.xyz[p];
    auto cell = [this](float v) {
      return static_cast<int>(std::clamp(std::floor(v * inv_), -1e9, 1e9));
    };
    return {group, cell(q.x()), cell(q.y()), cell(q.z())};
  }
  std::size_t cells() const { return cells_.size(); }
  const CellKey& cell(std::size_t c) const { return cells_[c]; }
  // Index of the cell at key, or -1.
  int find(const CellKey& k) const { return lookup_.find(k); }
  // Points of cell c: order()[begin(c) .. end(c)).
  int begin(std::size_t c) const { return begin_[c]; }
  int end(std::size_t c) const { return begin_[c + 1]; }
  const std::vector<int>& order() const { return order_; }

 private:
  const Frame& frame_;
  double inv_;
  std::vector<CellKey> cells_;
  std::vector<int> begin_, order_;
  CellMap lookup_;
};

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
      static_cast<float>(std::cos(detail::radians(params.concavity_tolerance_deg)));
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
      static_cast<float>(std::cos(detail::radians(params.concavity_tolerance_deg)));
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
                          : e.first >= params.merge_min_boundary &&
                                e.second <= params.merge_max_concave_share * e.first;
    if (join) sets.unite(pair.first, pair.second);
  }
  for (int& c : component)
    if (c >= 0) c = sets.find(c);
}

// Per point, the number of points of its own cluster within radius (itself included), scaled by
// the squared range on organized frames.
std::vector<float> point_density(const Frame& frame, const std::vector<int>& points,
                                 const std::vector<int>& group, double radius, int threads) {
  const CellIndex index(frame, points, group, radius);
  const float r2 = static_cast<float>(radius * radius);
  std::vector<float> density(frame.size(), 0.0f);
  const std::vector<int>& order = index.order();
  detail::parallel_for(
      static_cast<int>(index.cells()), detail::thread_count(threads),
      [&](int c) {
        const CellKey k = index.cell(c);
        std::vector<int> near;
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int n = index.find({k.group, k.x + dx, k.y + dy, k.z + dz});
              if (n >= 0) near.push_back(n);
            }
        for (int i = index.begin(c); i < index.end(c); ++i) {
          const int p = order[i];
          int count = 0;
          for (int n : near)
            for (int j = index.begin(n); j < index.end(n); ++j)
              count += (frame.xyz[order[j]] - frame.xyz[p]).squaredNorm() <= r2;
          density[p] =
              static_cast<float>(count) * (frame.organized() ? frame.xyz[p].squaredNorm() : 1);
        }
      },
      64);
  return density;
}

// Euclidean clustering with tolerance t, exact: cells of side t / sqrt(3) hold points that are all
// within t of each other, so components are found between cells, with an early exit per pair.
// Returns, per point of `points`, a component id (the smallest cell index of the component).
std::vector<int> euclidean_components(const Frame& frame, const std::vector<int>& points,
                                      const std::vector<int>& group, double tolerance) {
  const double side = tolerance / std::sqrt(3.0) * (1 - 1e-9);
  const CellIndex index(frame, points, group, side);
  const float t2 = static_cast<float>(tolerance * tolerance);
  const std::vector<int>& order = index.order();
  const int reach = static_cast<int>(std::ceil(tolerance / side));
  // Per cell, the bounding box of its points: two cells whose boxes are farther apart than t
  // cannot link, two whose boxes are within t link without looking at points.
  std::vector<Eigen::Vector3f> lo(index.cells()), hi(index.cells());
  for (std::size_t c = 0; c < index.cells(); ++c) {
    lo[c] = hi[c] = frame.xyz[order[index.begin(c)]];
    for (int i = index.begin(c) + 1; i < index.end(c); ++i) {
      lo[c] = lo[c].cwiseMin(frame.xyz[order[i]]);
      hi[c] = hi[c].cwiseMax(frame.xyz[order[i]]);
    }
  }
  // Neighbour offsets nearest first: once the near cells are linked, the far ones are usually in
  // the same set already and are skipped without a look at their points.
  std::vector<Eigen::Vector3i> offsets;
  for (int dz = -reach; dz <= reach; ++dz)
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx)
        if (dx || dy || dz) offsets.emplace_back(dx, dy, dz);
  std::stable_sort(offsets.begin(), offsets.end(),
                   [](const auto& a, const auto& b) { return a.squaredNorm() < b.squaredNorm(); });
  detail::UnionFind sets(index.cells());
  for (int c = 0; c < static_cast<int>(index.cells()); ++c) {
    const CellKey k = index.cell(c);
    for (const Eigen::Vector3i& d : offsets) {
      const int n = index.find({k.group, k.x + d.x(), k.y + d.y(), k.z + d.z()});
      if (n <= c || sets.find(n) == sets.find(c)) continue;
      const Eigen::Vector3f gap =
          (lo[n] - hi[c]).cwiseMax(lo[c] - hi[n]).cwiseMax(Eigen::Vector3f::Zero());
      if (gap.squaredNorm() > t2) continue;
      const Eigen::Vector3f span = hi[c].cwiseMax(hi[n]) - lo[c].cwiseMin(lo[n]);
      bool linked = span.squaredNorm() <= t2;
      for (int i = index.begin(c); i < index.end(c) && !linked; ++i)
        for (int j = index.begin(n); j < index.end(n) && !linked; ++j)
          linked = (frame.xyz[order[i]] - frame.xyz[order[j]]).squaredNorm() <= t2;
      if (linked) sets.unite(c, n);
    }
  }
  std::vector<int> component(frame.size(), -1);
  for (std::size_t c = 0; c < index.cells(); ++c)
    for (int i = index.begin(c); i < index.end(c); ++i) component[order[i]] = sets.find(c);
  return component;
}

}  // namespace

bool is_background(const Frame& frame, const Candidate& c, const SelectionParams& params) {
  const Eigen::Vector3d& e = c.box.extent;
  if (e[0] * e[1] < params.background_min_area) return false;
  const Eigen::Vector3d normal = c.box.axes.col(2);
  std::size_t inliers = 0;
  for (int p : c.points)
    inliers += std::abs(normal.dot(frame.xyz[p].cast<double>() - c.centroid)) <=
               params.background_plane_distance;
  return inliers >= params.background_inlier_ratio * c.points.size();
}

namespace {

// The box about the points' principal axes (m: their moments).
OrientedBox box_from_moments(const Frame& frame, const std::vector<int>& points,
                             const detail::Moments3& m) {
  OrientedBox box;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m.scatter);
  // Largest variance first; each axis signed so its largest component is positive, the third
  // completing a right-handed frame, so the box does not flip between runs.
  Eigen::Matrix3d axes;
  for (int i = 0; i < 2; ++i) {
    Eigen::Vector3d a = eig.eigenvectors().col(2 - i);
    Eigen::Index k;
    a.cwiseAbs().maxCoeff(&k);
    axes.col(i) = a[k] < 0 ? Eigen::Vector3d(-a) : a;
  }
  axes.col(2) = axes.col(0).cross(axes.col(1)).normalized();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (int p : points) {
    const Eigen::Vector3d q = axes.transpose() * (frame.xyz[p].cast<double>() - m.mean);
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  box.axes = axes;
  box.extent = hi - lo;
  box.centre = m.mean + axes * ((lo + hi) / 2);
  return box;
}

detail::Moments3 point_moments(const Frame& frame, const std::vector<int>& points) {
  return detail::moments(points.size(), [&](std::size_t j) { return frame.xyz[points[j]]; });
}

}  // namespace

OrientedBox oriented_box(const Frame& frame, const std::vector<int>& points) {
  if (points.empty()) return {};
  return box_from_moments(frame, points, point_moments(frame, points));
}

void describe_shape(const Frame& frame, Candidate& c) {
  if (c.points.empty()) {
    c.box = {};
    c.centroid = Eigen::Vector3d::Zero();
    return;
  }
  const detail::Moments3 m = point_moments(frame, c.points);
  c.box = box_from_moments(frame, c.points, m);
  c.centroid = m.mean;
}

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

// The labelled points split by their density against their cluster's median [3.3, weak
// connections]: `dense` (sorted) are clustered, `set_aside` join them afterwards. A cluster that
// is weak everywhere is kept whole (all dense).
struct DensitySplit {
  std::vector<int> dense, set_aside;
  std::vector<char> is_weak;  // per frame point: set aside
};

DensitySplit split_weak_points(const Frame& frame, const std::vector<int>& labelled,
                               const std::vector<int>& cluster, int clusters,
                               const SelectionParams& params, int threads) {
  const std::vector<float> density =
      point_density(frame, labelled, cluster, params.density_radius, threads);
  std::vector<std::vector<float>> per_cluster(clusters);
  for (int p : labelled) per_cluster[cluster[p]].push_back(density[p]);
  std::vector<float> threshold(clusters, 0.0f);
  for (int c = 0; c < clusters; ++c) {
    auto& d = per_cluster[c];
    std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
    threshold[c] = static_cast<float>(params.weak_density_ratio) * d[d.size() / 2];
  }
  DensitySplit out;
  std::vector<int> weak;
  std::vector<char> cluster_has_dense(clusters, 0);
  for (int p : labelled) {
    if (density[p] >= threshold[cluster[p]]) {
      out.dense.push_back(p);
      cluster_has_dense[cluster[p]] = 1;
    } else {
      weak.push_back(p);
    }
  }
  out.is_weak.assign(frame.size(), 0);
  for (int p : weak) {
    (cluster_has_dense[cluster[p]] ? out.set_aside : out.dense).push_back(p);
    out.is_weak[p] = cluster_has_dense[cluster[p]];
  }
  std::sort(out.dense.begin(), out.dense.end());
  return out;
}

// Set-aside points go back to the component of the nearest dense point of their cluster,
// looked up in their own and neighbouring voxels; a kd-tree of the cluster is the fallback.
void reattach_weak_points(const Frame& frame, const VoxelGrid& grid, const DensitySplit& split,
                          const std::vector<int>& cluster, int clusters,
                          std::vector<int>& component) {
  std::vector<int> orphans;
  for (int p : split.set_aside) {
    const int v = grid.voxel_of_point[p];
    float best = INFINITY;
    int nearest = -1;
    auto scan = [&](int voxel) {
      for (int q : grid.points[voxel]) {
        if (cluster[q] != cluster[p] || component[q] < 0 || split.is_weak[q]) continue;
        const float d = (frame.xyz[q] - frame.xyz[p]).squaredNorm();
        if (d < best) best = d, nearest = q;
      }
    };
    scan(v);
    for (int n : grid.neighbours[v]) scan(n);
    if (nearest >= 0)
      component[p] = component[nearest];
    else
      orphans.push_back(p);
  }
  if (orphans.empty()) return;
  std::vector<std::vector<int>> dense_of(clusters), orphans_of(clusters);
  for (int p : split.dense) dense_of[cluster[p]].push_back(p);
  for (int p : orphans) orphans_of[cluster[p]].push_back(p);
  for (int c = 0; c < clusters; ++c) {
    if (orphans_of[c].empty()) continue;
    if (dense_of[c].empty()) continue;
    std::vector<Eigen::Vector3d> xyz(dense_of[c].size());
    for (std::size_t i = 0; i < dense_of[c].size(); ++i)
      xyz[i] = frame.xyz[dense_of[c][i]].cast<double>();
    const detail::NearestPoints index(std::move(xyz));
    for (int p : orphans_of[c]) {
      const int nearest = index.nearest(frame.xyz[p].cast<double>(), 1)[0].first;
      component[p] = component[dense_of[c][nearest]];
    }
  }
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
  if (params.merge_convex)
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
