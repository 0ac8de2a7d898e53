// The cell index of the selection's neighbourhood queries [paper 3.3]: points grouped by
// (cluster, cell) of a cubic grid, a sorted index with an open-addressing hash from cell to its
// range.
#pragma once
#include <proxseg/core/frame.hpp>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace proxseg::detail {

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

}  // namespace proxseg::detail
