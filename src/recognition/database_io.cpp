// The model database (docs/database.md): opening one (load_database(), open_database()) and
// adding views to it (add_view(), write_database()); any number of processes read it while one
// at a time adds to it. The file is database_file.cpp, a view's records database_records.cpp,
// and the maintenance commands database_maintenance.cpp.
#include <proxseg/core/errors.hpp>
#include <proxseg/recognition/database_io.hpp>
#include <proxseg/recognition/model_view.hpp>
#include <proxseg/recognition/registration.hpp>

#include <algorithm>
#include <cerrno>
#include <filesystem>

#include "database_file.hpp"
#include "database_records.hpp"
#include "view_record.hpp"

namespace fs = std::filesystem;

namespace proxseg {

using detail::check_descriptor;
using detail::check_name;
using detail::check_own_files;
using detail::ensure_settings;
using detail::feature_dims;
using detail::file_path;
using detail::free_name;
using detail::insert_view;
using detail::insert_views;
using detail::open_file;
using detail::read_views;
using detail::refuse_folder_database;
using detail::Sqlite;

namespace {

const Rgb kNoColour = {128, 128, 128};  // what a point of an XYZ-only cloud is filtered with

// Whether a view's colours say anything: a captured or rendered surface never has one colour at
// every point, while a model painted with a placeholder (PCL's milk.pcd is (0, 0, 255)
// throughout) or filtered from an XYZ-only cloud (kNoColour) does.
bool informative(const std::vector<Rgb>& colours) {
  return std::any_of(colours.begin(), colours.end(),
                     [&](const Rgb& c) { return c != colours.front(); });
}

}  // namespace

Database load_database(const std::string& dir) {
  if (!check_own_files(dir)) {
    refuse_folder_database(dir);
    if (!fs::is_directory(dir))
      throw FileError(dir + (fs::exists(dir) ? ": is not a directory" : ": does not exist") +
                          " (expected a model database)",
                      fs::exists(dir) ? ENOTDIR : ENOENT);
    throw FileError(file_path(dir) + ": does not exist (expected a model database in " + dir + ")",
                    ENOENT);
  }
  Database db;
  db.dir = dir;
  db.file = open_file(dir, Sqlite::Mode::kRead);
  read_views(db);
  return db;
}

Database open_database(const std::string& dir, const DescriptorParams& descriptor,
                       bool descriptor_given) {
  check_descriptor(descriptor);
  if (check_own_files(dir)) {
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
  refuse_folder_database(dir);
  Database db;
  db.dir = dir;
  db.descriptor = descriptor;
  return db;
}

const ModelView& add_view(Database& db, const std::string& object, const Frame& points,
                          const Eigen::Vector3d& viewpoint, const std::string& source) {
  check_name(object);
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
  const bool coloured = points.rgb.size() == points.size() && informative(colours);
  // The view as a later load reads it: described, stored as floats, restored.
  const std::string body = detail::encode_body(describe_filtered(
      filtered, viewpoint, db.descriptor, coloured ? colours : std::vector<Rgb>{}));
  ModelView v = make_model_view(
      object,
      detail::decode_body(source, body, filtered.size(), feature_dims(db.descriptor), viewpoint),
      source);
  if (!db.file) {
    std::error_code ec;
    fs::create_directories(db.dir, ec);
    if (ec)
      throw FileError(db.dir + ": cannot create the database directory (" + ec.message() + ")");
    check_own_files(db.dir);
    db.file = open_file(db.dir, Sqlite::Mode::kCreate);
  }
  Sqlite& sql = db.file->sql;
  sql.run([&] {
    sql.write([&] {
      ensure_settings(sql, db.descriptor);
      v.name = free_name(sql, object);
      v.record = insert_view(sql, v, body);
    });
  });
  db.views.push_back(std::move(v));
  return db.views.back();
}

int write_database(const Database& db, const std::string& dir) {
  check_descriptor(db.descriptor);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw FileError(dir + ": cannot create the database directory (" + ec.message() + ")");
  check_own_files(dir);
  refuse_folder_database(dir);
  const auto file = open_file(dir, Sqlite::Mode::kCreate);
  file->sql.run([&] { insert_views(file->sql, db, true); });
  return static_cast<int>(db.views.size());
}

}  // namespace proxseg
