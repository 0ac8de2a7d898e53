// Clouds and meshes by file name: read_point_cloud and read_mesh choose the reader by the
// extension; PLY clouds and meshes (parsed by ply_io.hpp, colours as Open3D's reader gave them)
// and plain XYZ point lists. The other formats have a file each: PCD (pcd_reader.cpp,
// pcd_writer.cpp), OBJ (obj_io.cpp), RGB-D frames (rgbd_io.cpp), label images
// (label_image_io.cpp), atomic writes (atomic_write.cpp).
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/obj_io.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <sstream>
#include <utility>

#include "io/formats/ply_io.hpp"
#include "io/input_file.hpp"
#include "io/reader_errors.hpp"

namespace fs = std::filesystem;

namespace proxseg {
namespace {

using detail::fail;
using detail::one_line;
using detail::quote;

// The extension of path in lower case (".pcd"), "" if none.
std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// The PLY file at path (a regular file), parsed; InputError naming it when it is malformed.
detail::PlyData read_ply_data(const std::string& path, const std::string& label_property = "") {
  try {
    return detail::parse_ply(detail::read_input_file(path), label_property);
  } catch (const std::runtime_error& e) {
    fail(path, one_line(e.what()));
  }
}

}  // namespace

Frame read_ply(const std::string& path, const std::string& label_field) {
  detail::require_regular_file(path);
  return detail::ply_cloud(path, read_ply_data(path, label_field));
}

Frame read_point_cloud(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".pcd") return read_pcd(path);
  if (ext == ".ply") return read_ply(path);
  if (ext.empty()) fail(path, "has no file extension (expected .pcd or .ply)");
  fail(path, "unknown extension " + quote(ext) + " (expected .pcd or .ply)");
}

Mesh read_mesh(const std::string& path, double scale) {
  if (!(scale > 0) || !std::isfinite(scale)) fail(path, "mesh scale must be a positive number");
  detail::require_regular_file(path);
  const std::string ext = lower_extension(path);
  if (ext == ".obj") return read_obj(path, scale);  // textured: obj_io.hpp
  if (ext != ".ply")
    fail(path, "unknown mesh extension " + quote(ext) + " (expected .ply or .obj)");
  const detail::PlyData ply = read_ply_data(path);
  if (ply.vertices.empty() || ply.triangles.empty())
    fail(path, "mesh has " + std::to_string(ply.vertices.size()) + " vertices and " +
                   std::to_string(ply.triangles.size()) + " faces (expected both)");
  Mesh m;
  const int n = static_cast<int>(ply.vertices.size());
  m.vertices.reserve(n);
  for (const auto& v : ply.vertices) {
    if (!v.allFinite()) fail(path, "mesh has a vertex with NaN or infinite coordinates");
    m.vertices.push_back((v * scale).cast<float>());
  }
  const bool coloured = ply.colours.size() == ply.vertices.size();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d c =
        coloured
            ? Eigen::Vector3d(
                  (Eigen::Vector3d(ply.colours[i][0], ply.colours[i][1], ply.colours[i][2]) / 255.0)
                      .cwiseMax(0.0)
                      .cwiseMin(1.0) *
                  255.0)
            : Eigen::Vector3d(128, 128, 128);
    m.colours.push_back({static_cast<std::uint8_t>(std::lround(c.x())),
                         static_cast<std::uint8_t>(std::lround(c.y())),
                         static_cast<std::uint8_t>(std::lround(c.z()))});
  }
  for (const auto& t : ply.triangles) {
    if ((t.array() < 0).any() || (t.array() >= n).any())
      fail(path, "mesh has a face with a vertex index outside 0.." + std::to_string(n - 1));
    m.triangles.push_back(t);
  }
  return m;
}

std::vector<Eigen::Vector3d> read_xyz(const std::string& path) {
  std::istringstream in(detail::read_input_file(path));
  std::vector<Eigen::Vector3d> points;
  std::string line;
  for (long number = 1; std::getline(in, line); ++number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    Eigen::Vector3d p;
    std::string extra;
    if (!(fields >> p.x() >> p.y() >> p.z()) || (fields >> extra) || !p.allFinite())
      fail(path, "line " + std::to_string(number) + ": " + quote(line) +
                     " is invalid (expected three finite numbers x y z)");
    points.push_back(p);
  }
  if (points.empty()) fail(path, "has no points (expected lines of x y z in metres)");
  return points;
}

}  // namespace proxseg
