// The split of a textured mesh's triangles (edge_split.hpp). Every decision depends only on the
// two positions of an edge, so that the triangles on both sides of it split alike: no
// T-junction, no crack.
#include "io/formats/edge_split.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <sstream>
#include <unordered_map>

#include "io/reader_errors.hpp"

namespace proxseg::detail {
namespace {

// The split makes no more triangles: 4 million (2 m^2 of surface at 2 mm edges, the banana at
// 0.25 mm) take about 1 s and 0.3 GB; the banana at 2 mm has 34 thousand.
constexpr std::size_t kMaxTriangles = 4'000'000;

// The midpoint of an edge: the same float whichever end comes first, so that the triangles on
// both sides of an edge (and of a UV seam) get the same point; halved first so as not to overflow.
Eigen::Vector3f midpoint(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  return 0.5f * a + 0.5f * b;
}

// Whether the split cuts edge a-b: it is longer than max_edge (limit2 = max_edge^2) and its
// midpoint is a new float point. The second test only fails far from the origin (beyond 16 km
// floats are more than 2 mm apart), where splitting would never end. Both depend only on the two
// positions, so the triangles on either side of an edge decide alike: no T-junction, no crack.
bool cuts(const Eigen::Vector3f& a, const Eigen::Vector3f& b, double limit2) {
  if ((a.cast<double>() - b.cast<double>()).squaredNorm() <= limit2) return false;
  const Eigen::Vector3f m = midpoint(a, b);
  return m != a && m != b;
}

// One step of the split of triangle t: its long edges are cut at their midpoints and its pieces
// pushed onto todo (true), or it has no long edge and is final (false). Corners are of type C:
// pos(c) is a corner's position, mid(a, b) the corner at the midpoint of edge a-b. Pieces keep the
// winding. Each step at least halves the long edges or shortens them to 0.87 of the longest (the
// diagonal of the two-edge case), so the split ends.
template <class C, class Pos, class Mid>
bool split_step(const std::array<C, 3>& t, double limit2, const Pos& pos, const Mid& mid,
                std::vector<std::array<C, 3>>& todo) {
  // cut[k]: the edge from corner k to corner k + 1.
  const std::array<bool, 3> cut{cuts(pos(t[0]), pos(t[1]), limit2),
                                cuts(pos(t[1]), pos(t[2]), limit2),
                                cuts(pos(t[2]), pos(t[0]), limit2)};
  const int n = cut[0] + cut[1] + cut[2];
  if (n == 0) return false;
  // The first corner: edge a-b is cut and, when two are, b-c is the other one.
  int r = 0;
  while (!(cut[r] && (n != 2 || cut[(r + 1) % 3]))) ++r;
  const C a = t[r], b = t[(r + 1) % 3], c = t[(r + 2) % 3];
  // Pushed last first, so that the pieces come off the stack in this order.
  if (n == 1) {
    const C m = mid(a, b);
    todo.push_back({m, b, c});
    todo.push_back({a, m, c});
  } else if (n == 2) {
    const C mab = mid(a, b), mbc = mid(b, c);
    // The quad a, mab, mbc, c is cut along its shorter diagonal.
    if ((pos(a) - pos(mbc)).squaredNorm() <= (pos(mab) - pos(c)).squaredNorm()) {
      todo.push_back({a, mbc, c});
      todo.push_back({a, mab, mbc});
    } else {
      todo.push_back({mab, mbc, c});
      todo.push_back({a, mab, c});
    }
    todo.push_back({mab, b, mbc});
  } else {
    const C mab = mid(a, b), mbc = mid(b, c), mca = mid(c, a);
    todo.push_back({mab, mbc, mca});
    todo.push_back({mca, mbc, c});
    todo.push_back({mab, b, mbc});
    todo.push_back({a, mab, mca});
  }
  return true;
}

// How many triangles the split makes, or cap + 1 as soon as it would make more: the same steps
// on positions alone, so that a mesh too large for max_edge (or given the wrong scale) is refused
// before anything is allocated. Depth first, so the stack stays short.
std::size_t split_count(const Vertices& v, const std::vector<Eigen::Vector3i>& triangles,
                        double limit2, std::size_t cap) {
  using P = Eigen::Vector3f;
  const auto pos = [](const P& p) -> const P& { return p; };
  std::vector<std::array<P, 3>> todo;
  std::size_t final = 0, steps = 0;
  for (const Eigen::Vector3i& t : triangles) {
    todo.push_back({v.p[t[0]], v.p[t[1]], v.p[t[2]]});
    while (!todo.empty()) {
      const std::array<P, 3> piece = todo.back();
      todo.pop_back();
      final += !split_step(piece, limit2, pos, midpoint, todo);
      // A step makes at least two pieces, so cap triangles take fewer than 2 cap steps.
      if (final > cap || ++steps > 2 * cap) return cap + 1;
    }
  }
  return final;
}

}  // namespace

std::vector<Eigen::Vector3i> subdivide(const std::string& path,
                                       const std::vector<Eigen::Vector3i>& triangles,
                                       double max_edge, Vertices& v) {
  const double limit2 = max_edge * max_edge;
  const std::size_t count = split_count(v, triangles, limit2, kMaxTriangles);
  if (count > kMaxTriangles) {
    std::ostringstream o;
    o << "splitting the textured mesh into edges of at most " << max_edge * 1000
      << " mm would make more than " << kMaxTriangles
      << " triangles (expected a smaller mesh: is it in metres with this scale?)";
    fail(path, o.str());
  }
  std::unordered_map<std::uint64_t, int> midpoints;
  midpoints.reserve(count);
  const auto pos = [&](int i) -> const Eigen::Vector3f& { return v.p[i]; };
  const auto mid = [&](int a, int b) {
    const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
                              static_cast<std::uint32_t>(std::max(a, b));
    const auto [it, added] = midpoints.emplace(key, 0);
    if (added)
      it->second = v.add(midpoint(v.p[a], v.p[b]), 0.5 * (v.uv[a] + v.uv[b]), v.texture[a],
                         0.5f * (v.colour[a] + v.colour[b]));
    return it->second;
  };
  std::vector<Eigen::Vector3i> done;
  done.reserve(count);
  std::vector<std::array<int, 3>> todo;
  for (const Eigen::Vector3i& t : triangles) {
    todo.push_back({t[0], t[1], t[2]});
    while (!todo.empty()) {
      const std::array<int, 3> piece = todo.back();
      todo.pop_back();
      if (!split_step(piece, limit2, pos, mid, todo))
        done.emplace_back(piece[0], piece[1], piece[2]);
    }
  }
  return done;
}

}  // namespace proxseg::detail
