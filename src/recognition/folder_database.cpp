// Version 1 of the model database (proxseg 0.x before the database file): DIR/index.json, one
// PCD per view and one feature cache per view. Read only, by `proxseg db upgrade`.
#include "folder_database.hpp"

#include <proxseg/core/errors.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/recognition/model_view.hpp>
#include <proxseg/recognition/registration.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

namespace fs = std::filesystem;

namespace proxseg::detail {
namespace {

constexpr char kMagic[8] = {'P', 'X', 'S', 'G', 'F', 'P', 'F', '1'};
constexpr int kVersion = 1;

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  throw InputError(where + ": " + what);
}
// The same for a file or directory the system refuses (missing, unreadable, unwritable).
[[noreturn]] void fail_file(const std::string& where, const std::string& what) {
  throw FileError(where + ": " + what);
}

// FNV-1a over the float coordinates: ties a feature cache to the exact points of its PCD.
std::uint64_t checksum(const std::vector<Eigen::Vector3d>& points) {
  std::uint64_t h = 1469598103934665603ull;
  for (const auto& p : points)
    for (int k = 0; k < 3; ++k) {
      const float f = static_cast<float>(p[k]);
      unsigned char b[4];
      std::memcpy(b, &f, 4);
      for (unsigned char c : b) h = (h ^ c) * 1099511628211ull;
    }
  return h;
}

Cloud read_cache(const std::string& path, std::vector<Eigen::Vector3d> points,
                 std::vector<Rgb> colours, std::size_t expected_dims) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail_file(path, "cannot open the feature cache (expected the file named in index.json)");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t header = 8 + 4 + 4 + 3 * 8 + 8;
  if (bytes.size() < header || std::memcmp(bytes.data(), kMagic, 8) != 0)
    fail(path, "is not a proxseg feature cache (bad magic or truncated header)");
  std::uint32_t n = 0, dims = 0;
  double vp[3];
  std::uint64_t sum = 0;
  std::memcpy(&n, bytes.data() + 8, 4);
  std::memcpy(&dims, bytes.data() + 12, 4);
  std::memcpy(vp, bytes.data() + 16, 24);
  std::memcpy(&sum, bytes.data() + 40, 8);
  if (n != points.size())
    fail(path, "has " + std::to_string(n) + " points but its PCD has " +
                   std::to_string(points.size()) + " (stale cache; re-add the view)");
  if (dims != expected_dims)
    fail(path, "has " + std::to_string(dims) + " feature dimensions (expected " +
                   std::to_string(expected_dims) + " from the index's fpfh_radii)");
  const std::size_t expected = header + std::size_t(n) * (3 + dims) * sizeof(float);
  if (bytes.size() != expected)
    fail(path, "has " + std::to_string(bytes.size()) + " bytes (expected " +
                   std::to_string(expected) + "; truncated or corrupt)");
  if (sum != checksum(points))
    fail(path, "does not match the points of its PCD (stale cache; re-add the view)");
  const float* f = reinterpret_cast<const float*>(bytes.data() + header);
  std::vector<Eigen::Vector3d> normals(n);
  for (std::uint32_t i = 0; i < n; ++i, f += 3) {
    normals[i] = Eigen::Vector3d(f[0], f[1], f[2]);
    if (!normals[i].allFinite()) fail(path, "has a non-finite normal (corrupt cache)");
  }
  Eigen::MatrixXd features(dims, n);
  for (std::uint32_t j = 0; j < n; ++j)
    for (std::uint32_t i = 0; i < dims; ++i, ++f) {
      if (!std::isfinite(*f)) fail(path, "has a non-finite feature value (corrupt cache)");
      features(i, j) = *f;
    }
  return restore(std::move(points), std::move(normals), std::move(features),
                 Eigen::Vector3d(vp[0], vp[1], vp[2]), std::move(colours));
}

// A view's files must lie inside the database directory: the index is data, and must not make
// the loader read files elsewhere (another database's, or a device such as /dev/zero).
void check_inside(const std::string& where, const std::string& rel) {
  const fs::path p(rel);
  const bool up = std::any_of(p.begin(), p.end(), [](const fs::path& c) { return c == ".."; });
  if (rel.empty() || p.is_absolute() || up)
    fail(where, "view file \"" + rel + "\" is not a relative path inside the database directory");
}

// A file the loader reads, DIR/REL, must be the database's own plain file: no component below
// DIR a symbolic link (it could point anywhere, /proc/self/environ included) and the file itself
// a regular one (a FIFO would block the open for ever, a device would be read as data). DIR
// itself may be a link: that is where the user put the database. Missing: "" (the caller says
// what it expected); otherwise the path.
std::string plain_file(const std::string& dir, const std::string& rel) {
  fs::path at(dir);
  const fs::path r(rel);
  for (auto it = r.begin(); it != r.end(); ++it) {
    at /= *it;
    std::error_code ec;
    const fs::file_status st = fs::symlink_status(at, ec);
    if (ec || st.type() == fs::file_type::not_found) return "";
    if (st.type() == fs::file_type::symlink)
      fail(at.string(), "is a symbolic link (a database reads only its own files)");
    if (std::next(it) == r.end() && st.type() != fs::file_type::regular)
      fail(at.string(), "is not a regular file (a database reads only its own files)");
  }
  return at.string();
}

// Whether a view's colours say anything: a captured or rendered surface never has one colour at
// every point, while a model painted with a placeholder (PCL's milk.pcd is (0, 0, 255)
// throughout) or stored from an XYZ-only cloud (kNoColour) does.
bool informative(const std::vector<Rgb>& colours) {
  return std::any_of(colours.begin(), colours.end(),
                     [&](const Rgb& c) { return c != colours.front(); });
}

// A view's colours, or none: "colour": false in the index, or colours that say nothing.
std::vector<Rgb> view_colours(const std::string& where, const nlohmann::json& view,
                              const Frame& f) {
  if (view.contains("colour")) {
    if (!view["colour"].is_boolean()) fail(where, "field \"colour\": expected true or false");
    if (!view["colour"].get<bool>()) return {};
  }
  return informative(f.rgb) ? f.rgb : std::vector<Rgb>{};
}

template <class T>
T field(const std::string& where, const nlohmann::json& j, const char* name) {
  if (!j.is_object() || !j.contains(name))
    fail(where, std::string("missing field \"") + name + "\"");
  try {
    return j.at(name).get<T>();
  } catch (const nlohmann::json::exception&) {
    fail(where,
         std::string("field \"") + name + "\" has the wrong type (" + j.at(name).type_name() + ")");
  }
}

}  // namespace

bool is_folder_database(const std::string& dir) {
  std::error_code ec;
  return fs::symlink_status(fs::path(dir) / "index.json", ec).type() != fs::file_type::not_found;
}

Database read_folder_database(const std::string& dir) {
  const std::string path = (fs::path(dir) / "index.json").string();
  if (!fs::is_directory(dir)) fail_file(dir, "is not a directory (expected a model database)");
  if (plain_file(dir, "index.json").empty())
    fail_file(path, "does not exist (expected a model database index)");
  nlohmann::json j;
  {
    std::ifstream in(path);
    try {
      j = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
      fail(path, std::string("is not valid JSON (") + e.what() + ")");
    }
  }
  if (field<std::string>(path, j, "format") != kDatabaseFormat)
    fail(path, std::string("field \"format\" is not \"") + kDatabaseFormat + "\"");
  if (field<int>(path, j, "version") != kVersion)
    fail(path, "field \"version\" is not " + std::to_string(kVersion));
  if (field<std::string>(path, j, "units") != "metres")
    fail(path, "field \"units\" is not \"metres\"");
  Database db;
  db.dir = dir;
  const auto d = field<nlohmann::json>(path, j, "descriptor");
  db.descriptor.voxel_size = field<double>(path + " descriptor", d, "voxel_size");
  db.descriptor.normal_radius = field<double>(path + " descriptor", d, "normal_radius");
  db.descriptor.fpfh_radii = field<std::vector<double>>(path + " descriptor", d, "fpfh_radii");
  if (!(db.descriptor.voxel_size > 0) || !(db.descriptor.normal_radius > 0) ||
      db.descriptor.fpfh_radii.empty())
    fail(path, "descriptor: expected voxel_size > 0, normal_radius > 0 and fpfh_radii");
  const auto objects = field<nlohmann::json>(path, j, "objects");
  if (!objects.is_array()) fail(path, "field \"objects\" is not an array");
  for (const auto& o : objects) {
    const auto name = field<std::string>(path + " objects[]", o, "name");
    const auto views = field<nlohmann::json>(path + " object " + name, o, "views");
    if (!views.is_array()) fail(path, "object " + name + ": \"views\" is not an array");
    for (const auto& v : views) {
      const std::string where = path + " object " + name;
      const auto file = field<std::string>(where, v, "file");
      const auto features = field<std::string>(where, v, "features");
      check_inside(where, file);
      check_inside(where, features);
      const std::string source =
          v.contains("source") && v["source"].is_string() ? v["source"].get<std::string>() : "";
      const std::string pcd = (fs::path(dir) / file).string();
      if (plain_file(dir, file).empty())
        fail(pcd, "is missing (view of " + name + " listed in " + path + "; expected a PCD file)");
      plain_file(dir, features);  // a missing cache: read_cache says so
      const Frame f = read_pcd(pcd);
      std::vector<Eigen::Vector3d> points;
      for (std::size_t i = 0; i < f.size(); ++i)
        if (f.valid(i)) points.push_back(f.xyz[i].cast<double>());
      if (points.size() != f.size()) fail(pcd, "has invalid points (expected a filtered view)");
      Cloud cloud = read_cache((fs::path(dir) / features).string(), std::move(points),
                               view_colours(where, v, f), 33 * db.descriptor.fpfh_radii.size());
      db.views.push_back(
          make_model_view(name, std::move(cloud), source, fs::path(file).stem().string()));
    }
  }
  return db;
}

}  // namespace proxseg::detail
