// The model database on disk: index.json, a PCD per view and a feature cache per view
// (format in docs/database.md).
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/recognition/database_io.hpp>
#include <proxseg/recognition/registration.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

namespace fs = std::filesystem;

namespace proxseg {
namespace {

constexpr char kMagic[8] = {'P', 'X', 'S', 'G', 'F', 'P', 'F', '1'};
constexpr int kVersion = 1;
const char* const kFormat = "proxseg-model-database";
const Rgb kNoColour = {128, 128, 128};  // what a view from an XYZ-only cloud stores in its PCD

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

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

std::string cache_bytes(const Cloud& c) {
  std::string out(kMagic, 8);
  put(out, static_cast<std::uint32_t>(c.size()));
  put(out, static_cast<std::uint32_t>(c.features.rows()));
  for (int k = 0; k < 3; ++k) put(out, c.viewpoint[k]);
  put(out, checksum(c.points));
  for (const auto& n : c.normals)
    for (int k = 0; k < 3; ++k) put(out, static_cast<float>(n[k]));
  for (Eigen::Index j = 0; j < c.features.cols(); ++j)
    for (Eigen::Index i = 0; i < c.features.rows(); ++i)
      put(out, static_cast<float>(c.features(i, j)));
  return out;
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

// File-name-safe form of an object name.
std::string slug(const std::string& name) {
  std::string s;
  for (unsigned char c : name) s += std::isalnum(c) || c == '-' || c == '_' || c == '.' ? c : '_';
  return s;
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

void write_index(const Database& db) {
  nlohmann::json objects = nlohmann::json::array();
  for (const std::string& name : db.objects()) {
    nlohmann::json views = nlohmann::json::array();
    for (const ModelView& v : db.views) {
      if (v.object != name) continue;
      const auto& vp = v.cloud.viewpoint;
      views.push_back({{"file", v.file},
                       {"features", v.features},
                       {"points", v.cloud.size()},
                       {"viewpoint", vp.allFinite() ? nlohmann::json{vp.x(), vp.y(), vp.z()}
                                                    : nlohmann::json(nullptr)},
                       {"colour", !v.cloud.colours.empty()},
                       {"source", v.source}});
    }
    objects.push_back({{"name", name}, {"views", views}});
  }
  const nlohmann::json index = {{"format", kFormat},
                                {"version", kVersion},
                                {"units", "metres"},
                                {"descriptor", to_json(db.descriptor)},
                                {"objects", objects}};
  write_file_atomic((fs::path(db.dir) / "index.json").string(), index.dump(2) + "\n");
}

}  // namespace

Database load_database(const std::string& dir) {
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
  if (field<std::string>(path, j, "format") != kFormat)
    fail(path, std::string("field \"format\" is not \"") + kFormat + "\"");
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
      ModelView mv;
      mv.object = name;
      const std::string where = path + " object " + name;
      mv.file = field<std::string>(where, v, "file");
      mv.features = field<std::string>(where, v, "features");
      check_inside(where, mv.file);
      check_inside(where, mv.features);
      mv.source =
          v.contains("source") && v["source"].is_string() ? v["source"].get<std::string>() : "";
      const std::string pcd = (fs::path(dir) / mv.file).string();
      if (plain_file(dir, mv.file).empty())
        fail(pcd, "is missing (view of " + name + " listed in " + path + "; expected a PCD file)");
      plain_file(dir, mv.features);  // a missing cache: read_cache says so
      const Frame f = read_pcd(pcd);
      std::vector<Eigen::Vector3d> points;
      for (std::size_t i = 0; i < f.size(); ++i)
        if (f.valid(i)) points.push_back(f.xyz[i].cast<double>());
      if (points.size() != f.size()) fail(pcd, "has invalid points (expected a filtered view)");
      mv.cloud = read_cache((fs::path(dir) / mv.features).string(), std::move(points),
                            view_colours(where, v, f), 33 * db.descriptor.fpfh_radii.size());
      add_part_signatures(mv.cloud);
      db.views.push_back(std::move(mv));
    }
  }
  return db;
}

Database open_database(const std::string& dir, const DescriptorParams& descriptor,
                       bool descriptor_given) {
  if (!(descriptor.voxel_size > 0) || !std::isfinite(descriptor.voxel_size))
    throw InputError("voxel_size: expected a positive size in metres");
  if (!(descriptor.normal_radius > 0) || !std::isfinite(descriptor.normal_radius))
    throw InputError("normal_radius: expected a positive radius in metres");
  if (descriptor.fpfh_radii.empty()) throw InputError("fpfh_radii: expected at least one radius");
  for (double r : descriptor.fpfh_radii)
    if (!(r > 0) || !std::isfinite(r)) throw InputError("fpfh_radii: expected positive radii");
  if (fs::exists(fs::path(dir) / "index.json")) {
    Database db = load_database(dir);
    const DescriptorParams& d = db.descriptor;
    if (descriptor_given && !db.views.empty() &&
        (d.voxel_size != descriptor.voxel_size || d.normal_radius != descriptor.normal_radius ||
         d.fpfh_radii != descriptor.fpfh_radii))
      throw InputError(dir +
                       ": the database exists with other descriptor parameters (see its info); "
                       "voxel_size, normal_radius and fpfh_radii apply to a new one");
    return db;
  }
  Database db;
  db.dir = dir;
  db.descriptor = descriptor;
  return db;
}

const ModelView& add_view(Database& db, const std::string& object, const Frame& points,
                          const Eigen::Vector3d& viewpoint, const std::string& source) {
  if (object.empty() || object == "unknown")
    throw InputError("object name: expected a non-empty name other than \"unknown\"");
  for (unsigned char c : object)
    if (c < 32) throw InputError("object name: control characters are not allowed");
  std::vector<Eigen::Vector3d> xyz;
  std::vector<Rgb> rgb;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (points.valid(i)) {
      xyz.push_back(points.xyz[i].cast<double>());
      rgb.push_back(points.rgb.size() == points.size() ? points.rgb[i] : kNoColour);
    }
  std::vector<Rgb> colours;
  const auto filtered = voxel_filter(xyz, db.descriptor.voxel_size, &rgb, &colours);
  if (filtered.size() < 10)
    throw InputError(source + ": " + std::to_string(filtered.size()) +
                     " points after the voxel filter (expected at least 10 for a view)");
  ModelView v;
  v.object = object;
  v.source = source;
  const bool coloured = points.rgb.size() == points.size() && informative(colours);
  v.cloud = describe_filtered(filtered, viewpoint, db.descriptor,
                              coloured ? colours : std::vector<Rgb>{});
  add_part_signatures(v.cloud);
  int number = 0;
  for (const ModelView& w : db.views) number += w.object == object;
  std::string stem;
  do {  // a free file name, even if an earlier view of another name has the same slug
    char buf[16];
    std::snprintf(buf, sizeof buf, "-%03d", number++);
    stem = "views/" + slug(object) + buf;
  } while (fs::exists(fs::path(db.dir) / (stem + ".pcd")));
  v.file = stem + ".pcd";
  v.features = stem + ".fpfh";
  std::error_code ec;
  fs::create_directories(fs::path(db.dir) / "views", ec);
  if (ec) fail_file(db.dir, "cannot create the database directory (" + ec.message() + ")");
  Frame out;
  out.width = static_cast<int>(v.cloud.size());
  out.height = 1;
  for (std::size_t i = 0; i < v.cloud.size(); ++i)
    out.xyz.push_back(v.cloud.points[i].cast<float>());
  out.rgb = colours;
  write_pcd((fs::path(db.dir) / v.file).string(), out, {});
  write_file_atomic((fs::path(db.dir) / v.features).string(), cache_bytes(v.cloud));
  db.views.push_back(std::move(v));
  write_index(db);
  return db.views.back();
}

nlohmann::json database_info(const Database& db) {
  nlohmann::json objects = nlohmann::json::array();
  std::size_t total = 0;
  for (const std::string& name : db.objects()) {
    int views = 0;
    std::size_t points = 0;
    for (const ModelView& v : db.views)
      if (v.object == name) {
        ++views;
        points += v.cloud.size();
      }
    total += points;
    objects.push_back({{"name", name}, {"views", views}, {"points", points}});
  }
  return {{"dir", db.dir},      {"units", "metres"},        {"descriptor", to_json(db.descriptor)},
          {"objects", objects}, {"views", db.views.size()}, {"points", total}};
}

}  // namespace proxseg
