// Voxels [paper 3.1]. The paper indexes cells with an octree to reach neighbours quickly; a sorted
// array of integer keys with binary search gives the same neighbourhoods, deterministically.
#include <proxseg/voxels.hpp>

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
  explicit KeyPacker(const std::vector<std::pair<Eigen::Vector3i, int>>& keyed) {
    if (keyed.empty()) return;
    lo = hi = keyed.front().first;
    for (const auto& [key, index] : keyed) {
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

// Sorts the (key, point) pairs, in point order on entry, by packed key with a stable LSD radix
// sort, so points stay ascending within a key: the order std::sort by (key, point) gives. Each
// item is one integer, packed key above the pair's position. False if they do not fit in 64 bits.
bool radix_sort(std::vector<std::pair<Eigen::Vector3i, int>>& keyed, const KeyPacker& packer) {
  constexpr int kDigit = 11;
  int position_bits = 0;
  while ((std::uint64_t{1} << position_bits) < keyed.size()) ++position_bits;
  if (!packer.fits || packer.bits + position_bits > 64) return false;
  std::vector<std::uint64_t> a(keyed.size()), b(keyed.size());
  for (std::size_t i = 0; i < keyed.size(); ++i)
    a[i] = packer.pack(keyed[i].first) << position_bits | i;
  for (int shift = position_bits; shift < position_bits + packer.bits; shift += kDigit) {
    std::vector<std::size_t> start((1 << kDigit) + 1, 0);
    for (const std::uint64_t item : a) ++start[((item >> shift) & ((1 << kDigit) - 1)) + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    for (const std::uint64_t item : a) b[start[(item >> shift) & ((1 << kDigit) - 1)]++] = item;
    a.swap(b);
  }
  std::vector<std::pair<Eigen::Vector3i, int>> sorted(keyed.size());
  const std::uint64_t position_mask = (std::uint64_t{1} << position_bits) - 1;
  for (std::size_t i = 0; i < keyed.size(); ++i) sorted[i] = keyed[a[i] & position_mask];
  keyed.swap(sorted);
  return true;
}

}  // namespace

VoxelGrid build_voxels(const Frame& frame, double voxel_size) {
  if (!(voxel_size > 0)) throw std::invalid_argument("voxel_size must be > 0");
  VoxelGrid grid;
  grid.voxel_size = voxel_size;
  grid.voxel_of_point.assign(frame.size(), -1);

  // (key, point) pairs sorted by key, then by point index: voxels and their point lists come out
  // in a canonical order.
  std::vector<std::pair<Eigen::Vector3i, int>> keyed;
  keyed.reserve(frame.size());
  const double inv = 1.0 / voxel_size;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    if (!frame.valid(i)) continue;
    const Eigen::Vector3f& p = frame.xyz[i];
    const Eigen::Vector3d c = (p.cast<double>() * inv).array().floor();
    // Coordinates beyond the int range cannot be voxelised; treat them as invalid.
    if ((c.array().abs() > 1e9).any()) continue;
    keyed.emplace_back(c.cast<int>(), static_cast<int>(i));
  }
  const KeyPacker packer(keyed);
  if (!radix_sort(keyed, packer)) {
    std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) {
      if (a.first != b.first) return key_less(a.first, b.first);
      return a.second < b.second;
    });
  }
  for (const auto& [key, index] : keyed) {
    if (grid.keys.empty() || grid.keys.back() != key) {
      grid.keys.push_back(key);
      grid.points.emplace_back();
    }
    grid.points.back().push_back(index);
    grid.voxel_of_point[index] = static_cast<int>(grid.keys.size()) - 1;
  }

  // 26-neighbourhood by binary search in the sorted keys; symmetric by construction.
  grid.neighbours.resize(grid.keys.size());
  if (packer.fits) {
    // Packed keys: cells (x - 1, y', z'), (x, y', z'), (x + 1, y', z') are consecutive in the
    // order, so one search per (y', z') row finds all three; rows are visited in key order, so
    // the neighbours come out ascending.
    std::vector<std::uint64_t> packed(grid.keys.size());
    for (std::size_t v = 0; v < grid.keys.size(); ++v) packed[v] = packer.pack(grid.keys[v]);
    for (std::size_t v = 0; v < grid.keys.size(); ++v) {
      const Eigen::Vector3i& k = grid.keys[v];
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy) {
          const Eigen::Vector3i first(std::max(k.x() - 1, packer.lo.x()), k.y() + dy, k.z() + dz);
          const Eigen::Vector3i last(std::min(k.x() + 1, packer.hi.x()), k.y() + dy, k.z() + dz);
          if (!packer.inside(first) || !packer.inside(last)) continue;
          const std::uint64_t end = packer.pack(last);
          for (auto it = std::lower_bound(packed.begin(), packed.end(), packer.pack(first));
               it != packed.end() && *it <= end; ++it)
            if (static_cast<std::size_t>(it - packed.begin()) != v)
              grid.neighbours[v].push_back(static_cast<int>(it - packed.begin()));
        }
    }
    return grid;
  }
  for (std::size_t v = 0; v < grid.keys.size(); ++v) {
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const Eigen::Vector3i q = grid.keys[v] + Eigen::Vector3i(dx, dy, dz);
          auto it = std::lower_bound(grid.keys.begin(), grid.keys.end(), q, key_less);
          if (it != grid.keys.end() && *it == q)
            grid.neighbours[v].push_back(static_cast<int>(it - grid.keys.begin()));
        }
    std::sort(grid.neighbours[v].begin(), grid.neighbours[v].end());
  }
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
