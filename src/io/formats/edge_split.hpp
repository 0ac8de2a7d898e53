// The split of a textured mesh's triangles at the midpoints of their long edges: Mesh holds one
// colour per vertex and render() interpolates them, so a texture shows only through vertices
// close enough together (read_obj's max_edge). Private to the library.
#pragma once
#include <Eigen/Core>
#include <string>
#include <vector>

namespace proxseg::detail {

// The mesh being built: per vertex its position, and either a texture and UV or a colour.
struct Vertices {
  std::vector<Eigen::Vector3f> p;
  std::vector<Eigen::Vector2d> uv;
  std::vector<int> texture;             // -1 = colour holds the vertex colour
  std::vector<Eigen::Vector3f> colour;  // 0..255

  int add(const Eigen::Vector3f& pos, const Eigen::Vector2d& t, int tex, const Eigen::Vector3f& c) {
    p.push_back(pos);
    uv.push_back(t);
    texture.push_back(tex);
    colour.push_back(c);
    return static_cast<int>(p.size() - 1);
  }
};

// Splits triangles at the midpoints of their edges longer than max_edge until none is; a
// midpoint is made once per edge, with the UV and colour halfway, and added to v. Each triangle
// is split completely before the next, so the result keeps the file's order. InputError naming
// path when the split would make more than 4 million triangles.
std::vector<Eigen::Vector3i> subdivide(const std::string& path,
                                       const std::vector<Eigen::Vector3i>& triangles,
                                       double max_edge, Vertices& v);

}  // namespace proxseg::detail
