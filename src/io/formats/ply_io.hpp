// PLY reading (ascii, binary little and big endian): the vertices, their colours and the faces,
// as Open3D's reader gives them, and the point cloud they make, without loading Open3D (the
// segmentation path reads PLY clouds). Private to the library.
#pragma once
#include <proxseg/core/frame.hpp>

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace proxseg::detail {

struct PlyData {
  std::vector<Eigen::Vector3d> vertices;       // x y z of every vertex
  std::vector<std::array<double, 3>> colours;  // red green blue as stored; empty if none
  std::vector<Eigen::Vector3i> triangles;      // faces, a polygon fanned into triangles
  // The vertex property named label_property, one per vertex; empty when none was asked for or
  // the vertex element has no such property.
  std::vector<std::uint32_t> labels;
};

// Parses a whole PLY file. Properties of any PLY number type are read; elements other than
// "vertex" and "face" are skipped. label_property (when not empty) names an integer vertex
// property kept in PlyData::labels (whole numbers 0..2^32-1; a float property or another value
// is an error). Throws std::runtime_error with a one-line reason (header line
// or element and record, what was expected) for anything malformed or truncated; counts are
// checked against the bytes left before anything of that size is allocated.
PlyData parse_ply(const std::string& bytes, const std::string& label_property = "");

// The point cloud of a parsed PLY (read_ply): unorganized, its colours as Open3D's reader gave
// them (the stored value / 255, then back to 0..255), none when the file has none; the labels as
// Frame::label. InputError naming `name` when it has no vertex or no valid one.
Frame ply_cloud(const std::string& name, const PlyData& ply);

}  // namespace proxseg::detail
