// The model database file (docs/database.md): a SQLite file in WAL mode, three tables of view
// records beside a table of settings. SQLite gives what a database shared by robots and built
// over weeks needs: one writer at a time across processes, readers that never wait for it, a
// commit that a crash or a full disk cannot tear. This file: its place in its directory, opening
// it, and its settings (database_file.hpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/recognition/database_io.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "database_file.hpp"
#include "folder_database.hpp"
#include "util/checksum.hpp"
#include "util/shown_names.hpp"

namespace fs = std::filesystem;

namespace proxseg::detail {
namespace {

const char* const kSchema = R"(
CREATE TABLE IF NOT EXISTS meta(key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS views(
  record INTEGER PRIMARY KEY AUTOINCREMENT,
  object TEXT NOT NULL, name TEXT NOT NULL UNIQUE, source TEXT NOT NULL,
  points INTEGER NOT NULL, coloured INTEGER NOT NULL, summary BLOB NOT NULL);
CREATE INDEX IF NOT EXISTS views_object ON views(object);
CREATE TABLE IF NOT EXISTS parts(record INTEGER PRIMARY KEY, data BLOB NOT NULL);
CREATE TABLE IF NOT EXISTS bodies(record INTEGER PRIMARY KEY, data BLOB NOT NULL);
)";

std::string descriptor_text(const DescriptorParams& d) {
  return to_json(d).dump();
}

// The settings row: the descriptor's JSON with its checksum, so that an edited voxel size is
// told rather than used (candidates would be described unlike the views).
std::string sealed_text(const std::string& text) {
  char sum[24];
  std::snprintf(sum, sizeof sum, "%016llx",
                static_cast<unsigned long long>(checksum64(text.data(), text.size())));
  return text + "\n" + sum;
}

std::string unsealed_text(const std::string& where, const std::string& value) {
  const auto cut = value.rfind('\n');
  if (cut == std::string::npos || sealed_text(value.substr(0, cut)) != value)
    throw InputError(where + ": the descriptor setting is damaged (its checksum does not match)");
  return value.substr(0, cut);
}

DescriptorParams parse_descriptor(const std::string& where, const std::string& text) {
  DescriptorParams d;
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    d.voxel_size = j.at("voxel_size").get<double>();
    d.normal_radius = j.at("normal_radius").get<double>();
    d.fpfh_radii = j.at("fpfh_radii").get<std::vector<double>>();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(where + ": the descriptor setting is not what proxseg writes (" + e.what() +
                     ")");
  }
  try {
    check_descriptor(d);
  } catch (const InputError& e) {
    throw InputError(where + ": descriptor " + e.what());
  }
  return d;
}

std::string setting(Sqlite& sql, const std::string& key) {
  Statement s(sql, "SELECT value FROM meta WHERE key = ?");
  s.bind(1, key);
  return s.step() ? s.text(0) : std::string();
}

bool has_table(Sqlite& sql, const char* table) {
  Statement s(sql, "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?");
  s.bind(1, std::string(table));
  return s.step();
}

}  // namespace

std::string file_path(const std::string& dir) {
  return (fs::path(dir) / kDatabaseFile).string();
}

// The database reads and writes only its own plain files: the database file and SQLite's WAL,
// shared-memory and journal files beside it must not be symbolic links (they could point
// anywhere) or special files (a FIFO would block, a device be read as data). DIR itself may be
// a link: that is where the user put the database. Whether the database file exists.
bool check_own_files(const std::string& dir) {
  std::error_code ec;
  const fs::file_status d = fs::status(dir, ec);
  if (d.type() == fs::file_type::not_found) return false;
  if (d.type() != fs::file_type::directory)
    throw FileError(dir + ": is not a directory (expected a model database)");
  bool found = false;
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) {
    const fs::path p = fs::path(dir) / (std::string(kDatabaseFile) + suffix);
    const fs::file_status st = fs::symlink_status(p, ec);
    if (st.type() == fs::file_type::not_found) continue;
    if (st.type() == fs::file_type::symlink)
      throw FileError(p.string() + ": is a symbolic link (a database reads only its own files)");
    if (st.type() != fs::file_type::regular)
      throw FileError(p.string() + ": is not a regular file (a database reads only its own files)");
    found = found || *suffix == '\0';
  }
  return found;
}

void check_name(const std::string& object) {
  if (object.empty() || object == kUnknown)
    throw InputError("object name: expected a non-empty name other than \"unknown\"");
  for (unsigned char c : object)
    if (c < 32) throw InputError("object name: control characters are not allowed");
  // shown_name leaves such a name as it is, so reports, `db info` and `--name` all see one text.
  if (shown_name(object) != object)
    throw InputError("object name " + shown_name(object) +
                     ": expected UTF-8 text without \\\\ or \\xHH (the name is shown in JSON "
                     "reports, where those read as escapes)");
}

void check_descriptor(const DescriptorParams& d) {
  if (!(d.voxel_size > 0) || !std::isfinite(d.voxel_size))
    throw InputError("voxel_size: expected a positive size in metres");
  if (!(d.normal_radius > 0) || !std::isfinite(d.normal_radius))
    throw InputError("normal_radius: expected a positive radius in metres");
  if (d.fpfh_radii.empty()) throw InputError("fpfh_radii: expected at least one radius");
  for (double r : d.fpfh_radii)
    if (!(r > 0) || !std::isfinite(r)) throw InputError("fpfh_radii: expected positive radii");
}

// The database's format, version and units, checked; its descriptor.
DescriptorParams read_settings(Sqlite& sql) {
  const std::string& path = sql.path();
  if (!has_table(sql, "meta") || !has_table(sql, "views") || !has_table(sql, "parts") ||
      !has_table(sql, "bodies"))
    throw InputError(path + ": not a proxseg model database (its tables are missing)");
  if (setting(sql, "format") != kDatabaseFormat)
    throw InputError(path + ": not a proxseg model database (format \"" + setting(sql, "format") +
                     "\")");
  const std::string version = setting(sql, "version");
  if (version != std::to_string(kFormatVersion))
    throw InputError(path + ": format version " + version + " (this proxseg reads version " +
                     std::to_string(kFormatVersion) + "; a newer proxseg wrote it?)");
  if (setting(sql, "units") != "metres")
    throw InputError(path + ": units \"" + setting(sql, "units") + "\" (expected metres)");
  return parse_descriptor(path, unsealed_text(path, setting(sql, "descriptor")));
}

std::size_t feature_dims(const DescriptorParams& d) {
  return 33 * d.fpfh_radii.size();
}

// SQLite opens the file refusing a link in its place (SQLITE_OPEN_NOFOLLOW, which refuses a
// link anywhere in the path): the directory is resolved first, as it may be one.
std::shared_ptr<DatabaseFile> open_file(const std::string& dir, Sqlite::Mode mode) {
  std::error_code ec;
  const fs::path resolved = fs::canonical(dir, ec);
  return std::make_shared<DatabaseFile>(file_path(ec ? dir : resolved.string()), mode);
}

// The version-1 folder database's hint, for a directory that has one.
void refuse_folder_database(const std::string& dir) {
  if (detail::is_folder_database(dir))
    throw InputError(dir +
                     ": a version-1 folder database (index.json, views/); convert it with "
                     "`proxseg db upgrade " +
                     dir + "`");
}

// Creates the tables and settings of a new file, or checks that an existing one holds the same
// descriptor (another process may have made it since this one looked). Inside a write.
void ensure_settings(Sqlite& sql, const DescriptorParams& descriptor) {
  if (has_table(sql, "meta") && !setting(sql, "format").empty()) {
    const DescriptorParams d = read_settings(sql);
    if (d.voxel_size != descriptor.voxel_size || d.normal_radius != descriptor.normal_radius ||
        d.fpfh_radii != descriptor.fpfh_radii)
      throw InputError(sql.path() +
                       ": the database was made with other descriptor parameters meanwhile");
    return;
  }
  sql.exec(kSchema);
  for (const auto& [key, value] : {std::pair<std::string, std::string>{"format", kDatabaseFormat},
                                   {"version", std::to_string(kFormatVersion)},
                                   {"units", "metres"},
                                   {"descriptor", sealed_text(descriptor_text(descriptor))}}) {
    Statement s(sql, "INSERT OR REPLACE INTO meta(key, value) VALUES (?, ?)");
    s.bind(1, key).bind(2, value);
    s.step();
  }
}

}  // namespace proxseg::detail
