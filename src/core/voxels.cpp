// Voxels [paper 3.1]. The paper indexes cells with an octree to reach neighbours quickly; a sorted
// array of integer keys with binary search gives the same neighbourhoods, deterministically.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/voxels.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <stdexcept>

namespace proxseg {
namespace {

bool key_less(const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
  if (a.z() != b.z()) return a.z() < b.z();
  if (a.y() != b.y()) return a.y() < b.y();
  return a.x() < b.x();
}

// Cell keys of one frame packed into 64-bit integers in the same (z, y, x) order, when their
// ranges fit (always, for a camera frame): integer keys sort by radix and compare in one step.
struct KeyPacker {
  Eigen::Vector3i lo = Eigen::Vector3i::Zero(), hi = Eigen::Vector3i::Constant(-1);
  int bits_x = 0, bits_y = 0, bits = 0;
  bool fits = false;
  explicit KeyPacker(const std::vector<Eigen::Vector3i>& keys) {
    if (keys.empty()) return;
    lo = hi = keys.front();
    for (const Eigen::Vector3i& key : keys) {
      lo = lo.cwiseMin(key);
      hi = hi.cwiseMax(key);
    }
    auto width = [](std::int64_t range) {  // bits for 0..range
      int b = 0;
      while (b < 63 && (std::int64_t{1} << b) <= range) ++b;
      return b;
    };
    bits_x = width(std::int64_t{hi.x()} - lo.x());
    bits_y = width(std::int64_t{hi.y()} - lo.y());
    bits = bits_x + bits_y + width(std::int64_t{hi.z()} - lo.z());
    fits = bits <= 62;
  }
  bool inside(const Eigen::Vector3i& k) const {
    return (k.array() >= lo.array()).all() && (k.array() <= hi.array()).all();
  }
  std::uint64_t pack(const Eigen::Vector3i& k) const {
    return (static_cast<std::uint64_t>(std::int64_t{k.z()} - lo.z()) << (bits_x + bits_y)) |
           (static_cast<std::uint64_t>(std::int64_t{k.y()} - lo.y()) << bits_x) |
           static_cast<std::uint64_t>(std::int64_t{k.x()} - lo.x());
  }
};

// The positions of `keys` sorted by key, equal keys in position order, by a stable LSD radix
// sort of the packed keys. Each item is one integer, packed key above the position. Empty if
// they do not fit in 64 bits.
std::vector<int> radix_order(const std::vector<Eigen::Vector3i>& keys, const KeyPacker& packer) {
  constexpr int kDigit = 11;
  int position_bits = 0;
  while ((std::uint64_t{1} << position_bits) < keys.size()) ++position_bits;
  if (!packer.fits || packer.bits + position_bits > 64) return {};
  std::vector<std::uint64_t> a(keys.size()), b(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) a[i] = packer.pack(keys[i]) << position_bits | i;
  for (int shift = position_bits; shift < position_bits + packer.bits; shift += kDigit) {
    std::vector<std::size_t> start((1 << kDigit) + 1, 0);
    for (const std::uint64_t item : a) ++start[((item >> shift) & ((1 << kDigit) - 1)) + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    for (const std::uint64_t item : a) b[start[(item >> shift) & ((1 << kDigit) - 1)]++] = item;
    a.swap(b);
  }
  std::vector<int> order(keys.size());
  const std::uint64_t position_mask = (std::uint64_t{1} << position_bits) - 1;
  for (std::size_t i = 0; i < keys.size(); ++i) order[i] = static_cast<int>(a[i] & position_mask);
  return order;
}

// floor(t) as an int when -kVoxelReach <= t < kVoxelReach + 1 (exactly when floor(t) is within
// the reach), without the library call; false otherwise (and for NaN).
bool floor_within(double t, int& out) {
  static_assert(kVoxelReach < 2147483647.0, "a voxel coordinate is an int");
  if (!(t >= -kVoxelReach && t < kVoxelReach + 1)) return false;
  const int truncated = static_cast<int>(t);
  out = truncated - (truncated > t);
  return true;
}

}  // namespace

std::vector<char> voxelisable(const Frame& frame, double voxel_size, std::size_t& valid_points,
                              std::size_t& voxelised_points) {
  if (!(voxel_size > 0)) throw InputError("voxel_size must be > 0");
  std::vector<char> out(frame.size(), 0);
  valid_points = voxelised_points = 0;
  const double inv = 1.0 / voxel_size;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    if (!frame.valid(i)) continue;
    ++valid_points;
    const Eigen::Vector3f& p = frame.xyz[i];
    int c;
    out[i] = floor_within(p.x() * inv, c) && floor_within(p.y() * inv, c) &&
             floor_within(p.z() * inv, c);
    voxelised_points += out[i];
  }
  return out;
}

namespace {

void voxel_neighbours(VoxelGrid& grid, const KeyPacker& packer) {
  // 26-neighbourhood in the sorted keys; symmetric by construction.
  grid.neighbours.resize(grid.keys.size());
  int found[26];
  if (packer.fits) {
    // Packed keys: cells (x - 1, y', z'), (x, y', z'), (x + 1, y', z') are consecutive in the
    // order, so one search per (y', z') row finds all three; rows are visited in key order, so
    // the neighbours come out ascending. The first cell of a row, taken for the voxels in
    // order, only moves forward: one cursor per row offset walks the keys once.
    std::vector<std::uint64_t> packed(grid.keys.size());
    for (std::size_t v = 0; v < grid.keys.size(); ++v) packed[v] = packer.pack(grid.keys[v]);
    std::size_t cursor[9] = {};
    for (std::size_t v = 0; v < grid.keys.size(); ++v) {
      const Eigen::Vector3i& k = grid.keys[v];
      int count = 0;
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy) {
          const Eigen::Vector3i first(std::max(k.x() - 1, packer.lo.x()), k.y() + dy, k.z() + dz);
          const Eigen::Vector3i last(std::min(k.x() + 1, packer.hi.x()), k.y() + dy, k.z() + dz);
          if (!packer.inside(first) || !packer.inside(last)) continue;
          std::size_t& it = cursor[(dz + 1) * 3 + dy + 1];
          const std::uint64_t begin = packer.pack(first), end = packer.pack(last);
          while (it < packed.size() && packed[it] < begin) ++it;
          for (std::size_t q = it; q < packed.size() && packed[q] <= end; ++q)
            if (q != v) found[count++] = static_cast<int>(q);
        }
      grid.neighbours[v].assign(found, found + count);
    }
    return;
  }
  for (std::size_t v = 0; v < grid.keys.size(); ++v) {
    int count = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const Eigen::Vector3i q = grid.keys[v] + Eigen::Vector3i(dx, dy, dz);
          auto it = std::lower_bound(grid.keys.begin(), grid.keys.end(), q, key_less);
          if (it != grid.keys.end() && *it == q)
            found[count++] = static_cast<int>(it - grid.keys.begin());
        }
    grid.neighbours[v].assign(found, found + count);  // (dz, dy, dx) order is key order
  }
}

}  // namespace

VoxelGrid build_voxels(const Frame& frame, double voxel_size) {
  if (!(voxel_size > 0)) throw InputError("voxel_size must be > 0");
  VoxelGrid grid;
  grid.voxel_size = voxel_size;
  grid.voxel_of_point.assign(frame.size(), -1);

  // The cell of every valid point, in point order. Coordinates beyond the int range cannot be
  // voxelised; those points are treated as invalid.
  std::vector<Eigen::Vector3i> cells;
  std::vector<int> point;
  cells.reserve(frame.size());
  point.reserve(frame.size());
  const double inv = 1.0 / voxel_size;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    if (!frame.valid(i)) continue;
    ++grid.valid_points;
    const Eigen::Vector3f& p = frame.xyz[i];
    Eigen::Vector3i c;
    if (!floor_within(p.x() * inv, c.x()) || !floor_within(p.y() * inv, c.y()) ||
        !floor_within(p.z() * inv, c.z()))
      continue;
    cells.push_back(c);
    point.push_back(static_cast<int>(i));
  }
  grid.voxelised_points = cells.size();
  // Sorted by cell, then by point index: voxels and their point lists come out in a canonical
  // order.
  const KeyPacker packer(cells);
  std::vector<int> order = radix_order(cells, packer);
  if (order.size() != cells.size()) {
    order.resize(cells.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return key_less(cells[a], cells[b]); });
  }
  for (std::size_t s = 0; s < order.size();) {
    const Eigen::Vector3i& key = cells[order[s]];
    std::size_t e = s + 1;
    while (e < order.size() && cells[order[e]] == key) ++e;
    const int v = static_cast<int>(grid.keys.size());
    grid.keys.push_back(key);
    std::vector<int>& pts = grid.points.emplace_back(e - s);
    for (std::size_t t = s; t < e; ++t) {
      pts[t - s] = point[order[t]];
      grid.voxel_of_point[pts[t - s]] = v;
    }
    s = e;
  }

  voxel_neighbours(grid, packer);
  return grid;
}

std::vector<int> dense_voxels(const VoxelGrid& grid, int min_points) {
  std::vector<int> out;
  for (std::size_t v = 0; v < grid.size(); ++v)
    if (static_cast<int>(grid.points[v].size()) >= min_points) out.push_back(static_cast<int>(v));
  return out;
}

std::vector<std::vector<int>> induced_neighbours(const VoxelGrid& grid,
                                                 const std::vector<int>& subset) {
  std::vector<int> local(grid.size(), -1);
  for (std::size_t i = 0; i < subset.size(); ++i) local[subset[i]] = static_cast<int>(i);
  std::vector<std::vector<int>> out(subset.size());
  for (std::size_t i = 0; i < subset.size(); ++i)
    for (int n : grid.neighbours[subset[i]])
      if (local[n] >= 0) out[i].push_back(local[n]);
  return out;
}

}  // namespace proxseg
