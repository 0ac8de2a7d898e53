// The model database file (docs/database.md): a SQLite file in WAL mode, three tables of view
// records beside a table of settings. SQLite gives what a database shared by robots and built
// over weeks needs: one writer at a time across processes, readers that never wait for it, a
// commit that a crash or a full disk cannot tear.
#include <proxseg/io/params.hpp>
#include <proxseg/recognition/database_io.hpp>
#include <proxseg/recognition/model_view.hpp>
#include <proxseg/recognition/registration.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include "folder_database.hpp"
#include "sqlite.hpp"
#include "util/checksum.hpp"
#include "view_record.hpp"

namespace fs = std::filesystem;

namespace proxseg {

struct DatabaseFile {
  DatabaseFile(const std::string& path, detail::Sqlite::Mode mode) : sql(path, mode) {}
  detail::Sqlite sql;
};

namespace {

using detail::Sqlite;
using detail::Statement;

const char* const kFormat = "proxseg-model-database";
constexpr int kVersion = 2;
const Rgb kNoColour = {128, 128, 128};  // what a point of an XYZ-only cloud is filtered with

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
  if (object.empty() || object == "unknown")
    throw InputError("object name: expected a non-empty name other than \"unknown\"");
  for (unsigned char c : object)
    if (c < 32) throw InputError("object name: control characters are not allowed");
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

// File-name-safe form of an object name, the stem of its views' names.
std::string slug(const std::string& name) {
  std::string s;
  for (unsigned char c : name) s += std::isalnum(c) || c == '-' || c == '_' || c == '.' ? c : '_';
  return s;
}

// Whether a view's colours say anything: a captured or rendered surface never has one colour at
// every point, while a model painted with a placeholder (PCL's milk.pcd is (0, 0, 255)
// throughout) or filtered from an XYZ-only cloud (kNoColour) does.
bool informative(const std::vector<Rgb>& colours) {
  return std::any_of(colours.begin(), colours.end(),
                     [&](const Rgb& c) { return c != colours.front(); });
}

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

// The database's format, version and units, checked; its descriptor.
DescriptorParams read_settings(Sqlite& sql) {
  const std::string& path = sql.path();
  if (!has_table(sql, "meta") || !has_table(sql, "views") || !has_table(sql, "parts") ||
      !has_table(sql, "bodies"))
    throw InputError(path + ": not a proxseg model database (its tables are missing)");
  if (setting(sql, "format") != kFormat)
    throw InputError(path + ": not a proxseg model database (format \"" + setting(sql, "format") +
                     "\")");
  const std::string version = setting(sql, "version");
  if (version != std::to_string(kVersion))
    throw InputError(path + ": format version " + version + " (this proxseg reads version " +
                     std::to_string(kVersion) + "; a newer proxseg wrote it?)");
  if (setting(sql, "units") != "metres")
    throw InputError(path + ": units \"" + setting(sql, "units") + "\" (expected metres)");
  return parse_descriptor(path, unsealed_text(path, setting(sql, "descriptor")));
}

std::string where_of(const std::string& path, const std::string& name, std::int64_t record) {
  return path + " view " + name + " (record " + std::to_string(record) + ")";
}

std::string record_bytes(DatabaseFile& f, const char* table, std::int64_t record,
                         const std::string& where) {
  return f.sql.run([&] {
    Statement s(f.sql, std::string("SELECT data FROM ") + table + " WHERE record = ?");
    s.bind(1, record);
    if (!s.step())
      throw InputError(where + ": its " + (std::string(table) == "parts" ? "parts" : "body") +
                       " record is missing (removed since the database was opened, or damaged)");
    return s.blob(0);
  });
}

// The parts and the body of a stored view, read and checked against its row.
std::vector<Signature> read_parts(DatabaseFile& file, std::int64_t record,
                                  const std::string& where) {
  return detail::decode_parts(where, record_bytes(file, "parts", record, where));
}

Cloud read_body(DatabaseFile& file, std::int64_t record, const std::string& where,
                std::size_t points, std::size_t dims, const Eigen::Vector3d& viewpoint,
                bool coloured) {
  Cloud c = detail::decode_body(where, record_bytes(file, "bodies", record, where), points, dims,
                                viewpoint);
  if (c.colours.empty() == coloured)
    throw InputError(where + ": body record damaged: its colours disagree with its row");
  return c;
}

// A stored view: its summary decoded, its parts and body read on first use.
ModelView stored_view(const std::shared_ptr<DatabaseFile>& file, std::int64_t record,
                      std::string object, std::string name, std::string source, std::size_t points,
                      bool coloured, const detail::ViewSummary& summary, std::size_t dims) {
  ModelView v;
  v.object = std::move(object);
  v.name = std::move(name);
  v.source = std::move(source);
  v.record = record;
  v.points = points;
  v.coloured = coloured;
  v.viewpoint = summary.viewpoint;
  v.signature = summary.signature;
  v.part_sketches = summary.part_sketches;
  const std::string where = where_of(file->sql.path(), v.name, record);
  v.parts =
      std::make_shared<const Lazy<std::vector<Signature>>>(std::function<std::vector<Signature>()>(
          [file, record, where] { return read_parts(*file, record, where); }));
  const Eigen::Vector3d viewpoint = summary.viewpoint;
  v.described = std::make_shared<const Lazy<Cloud>>(
      std::function<Cloud()>([file, record, where, points, dims, viewpoint, coloured] {
        return read_body(*file, record, where, points, dims, viewpoint, coloured);
      }));
  return v;
}

std::size_t feature_dims(const DescriptorParams& d) {
  return 33 * d.fpfh_radii.size();
}

// The views of a file in one read transaction: the database as one writer left it.
void read_views(Database& db) {
  Sqlite& sql = db.file->sql;
  sql.run([&] {
    sql.read([&] {
      db.descriptor = read_settings(sql);
      Statement s(sql,
                  "SELECT record, object, name, source, points, coloured, summary FROM views "
                  "ORDER BY record");
      while (s.step()) {
        const std::int64_t record = s.integer(0);
        const std::string name = s.text(2);
        const std::string where = where_of(sql.path(), name, record);
        try {
          const std::int64_t points = s.integer(4);
          if (points < 10 || points > (std::int64_t(1) << 31))
            throw InputError(where + ": its row says " + std::to_string(points) + " points");
          const auto summary = detail::decode_summary(where, s.blob(6));
          db.views.push_back(stored_view(db.file, record, s.text(1), name, s.text(3),
                                         static_cast<std::size_t>(points), s.integer(5) != 0,
                                         summary, feature_dims(db.descriptor)));
        } catch (const InputError& e) {
          db.damaged.push_back(e.what());
        }
      }
    });
  });
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

// The next free name for a view of `object`: slug-NNN.
std::string free_name(Sqlite& sql, const std::string& object) {
  Statement count(sql, "SELECT count(*) FROM views WHERE object = ?");
  count.bind(1, object);
  count.step();
  for (std::int64_t n = count.integer(0);; ++n) {
    char buf[24];
    std::snprintf(buf, sizeof buf, "-%03lld", static_cast<long long>(n));
    const std::string name = slug(object) + buf;
    Statement taken(sql, "SELECT 1 FROM views WHERE name = ?");
    taken.bind(1, name);
    if (!taken.step()) return name;
  }
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
  for (const auto& [key, value] : {std::pair<std::string, std::string>{"format", kFormat},
                                   {"version", std::to_string(kVersion)},
                                   {"units", "metres"},
                                   {"descriptor", sealed_text(descriptor_text(descriptor))}}) {
    Statement s(sql, "INSERT OR REPLACE INTO meta(key, value) VALUES (?, ?)");
    s.bind(1, key).bind(2, value);
    s.step();
  }
}

// Writes one view's records; its record number. Inside a write.
std::int64_t insert_view(Sqlite& sql, const ModelView& v, const std::string& body) {
  const detail::ViewSummary summary{v.viewpoint, v.signature, v.part_sketches};
  Statement row(sql,
                "INSERT INTO views(object, name, source, points, coloured, summary) "
                "VALUES (?, ?, ?, ?, ?, ?)");
  row.bind(1, v.object)
      .bind(2, v.name)
      .bind(3, v.source)
      .bind(4, static_cast<std::int64_t>(v.points))
      .bind(5, std::int64_t(v.coloured))
      .bind_blob(6, detail::encode_summary(summary));
  row.step();
  const std::int64_t record = sql.last_insert_rowid();
  for (const auto& [table, bytes] :
       {std::pair<const char*, std::string>{"parts", detail::encode_parts(v.part_signatures())},
        {"bodies", body}}) {
    Statement s(sql, std::string("INSERT INTO ") + table + "(record, data) VALUES (?, ?)");
    s.bind(1, record).bind_blob(2, bytes);
    s.step();
  }
  return record;
}

// Writes every view of db in one transaction; rename: give a view a free name when its own is
// taken (otherwise a clash fails the whole write).
void insert_views(Sqlite& sql, const Database& db, bool rename) {
  sql.write([&] {
    ensure_settings(sql, db.descriptor);
    for (const ModelView& v : db.views) {
      ModelView named = v;
      if (rename) {
        Statement taken(sql, "SELECT 1 FROM views WHERE name = ?");
        taken.bind(1, v.name);
        if (v.name.empty() || taken.step()) named.name = free_name(sql, v.object);
      }
      insert_view(sql, named, detail::encode_body(v.cloud()));
    }
  });
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

namespace {

// An existing database's file, opened to write (a database not yet written has nothing to change).
Sqlite& writable(Database& db) {
  if (!db.file) {
    if (!check_own_files(db.dir))
      throw InputError(db.dir + ": the database has no views yet (nothing to change)");
    db.file = open_file(db.dir, Sqlite::Mode::kWrite);
  }
  return db.file->sql;
}

int count_of(Sqlite& sql, const std::string& object) {
  Statement s(sql, "SELECT count(*) FROM views WHERE object = ?");
  s.bind(1, object);
  s.step();
  return static_cast<int>(s.integer(0));
}

}  // namespace

int remove_object(Database& db, const std::string& object) {
  Sqlite& sql = writable(db);
  int removed = 0;
  sql.run([&] {
    sql.write([&] {
      read_settings(sql);
      removed = count_of(sql, object);
      if (removed == 0) throw InputError(db.dir + ": no object named \"" + object + "\"");
      for (const char* table : {"parts", "bodies"}) {
        Statement s(sql, std::string("DELETE FROM ") + table +
                             " WHERE record IN (SELECT record FROM views WHERE object = ?)");
        s.bind(1, object);
        s.step();
      }
      Statement s(sql, "DELETE FROM views WHERE object = ?");
      s.bind(1, object);
      s.step();
    });
  });
  db.views.erase(std::remove_if(db.views.begin(), db.views.end(),
                                [&](const ModelView& v) { return v.object == object; }),
                 db.views.end());
  return removed;
}

int rename_object(Database& db, const std::string& from, const std::string& to) {
  check_name(to);
  Sqlite& sql = writable(db);
  int renamed = 0;
  sql.run([&] {
    sql.write([&] {
      read_settings(sql);
      renamed = count_of(sql, from);
      if (renamed == 0) throw InputError(db.dir + ": no object named \"" + from + "\"");
      Statement s(sql, "UPDATE views SET object = ? WHERE object = ?");
      s.bind(1, to).bind(2, from);
      s.step();
    });
  });
  for (ModelView& v : db.views)
    if (v.object == from) v.object = to;
  return renamed;
}

DatabaseCheck check_database(const std::string& dir) {
  DatabaseCheck out;
  Database db = load_database(dir);
  Sqlite& sql = db.file->sql;
  sql.run([&] {
    Statement s(sql, "PRAGMA quick_check");
    while (s.step())
      if (s.text(0) != "ok") out.damaged.push_back(sql.path() + ": structure: " + s.text(0));
    Statement orphans(sql,
                      "SELECT count(*) FROM (SELECT record FROM parts UNION SELECT record FROM "
                      "bodies) WHERE record NOT IN (SELECT record FROM views)");
    orphans.step();
    if (orphans.integer(0) > 0)
      out.damaged.push_back(sql.path() + ": " + std::to_string(orphans.integer(0)) +
                            " records belong to no view");
  });
  out.views = static_cast<int>(db.views.size() + db.damaged.size());
  for (const std::string& d : db.damaged) out.damaged.push_back(d);
  // Each view's records decoded and dropped (not kept as a recognition keeps them: a database
  // of 16,384 views holds 4 GB of bodies).
  const std::size_t dims = feature_dims(db.descriptor);
  for (const ModelView& v : db.views) {
    const std::string where = where_of(sql.path(), v.name, v.record);
    bool whole = true;
    for (const auto& read : {std::function<void()>([&] { read_parts(*db.file, v.record, where); }),
                             std::function<void()>([&] {
                               read_body(*db.file, v.record, where, v.points, dims, v.viewpoint,
                                         v.coloured);
                             })})
      try {
        read();
      } catch (const InputError& e) {
        out.damaged.push_back(e.what());
        whole = false;
      }
    out.whole += whole;
  }
  return out;
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

int upgrade_database(const std::string& dir) {
  if (check_own_files(dir))
    throw InputError(file_path(dir) + ": already exists (the database is upgraded)");
  if (!detail::is_folder_database(dir))
    throw InputError(dir + ": has no version-1 index.json to upgrade");
  const Database old = detail::read_folder_database(dir);
  // Written under another name and renamed when complete: an interrupted upgrade leaves no
  // database file that looks like one.
  const std::string partial = file_path(dir) + ".upgrading";
  std::error_code ec;
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) fs::remove(partial + suffix, ec);
  {
    Sqlite sql(partial, Sqlite::Mode::kCreate);
    insert_views(sql, old, false);
    sql.exec("PRAGMA wal_checkpoint(TRUNCATE)");
  }
  fs::rename(partial, file_path(dir), ec);
  if (ec) throw FileError(file_path(dir) + ": cannot be written (" + ec.message() + ")");
  for (const char* suffix : {"-wal", "-shm"}) fs::remove(partial + suffix, ec);
  return static_cast<int>(old.views.size());
}

nlohmann::json database_info(const Database& db) {
  nlohmann::json objects = nlohmann::json::array();
  std::size_t total_points = 0;
  std::map<std::string, std::pair<std::size_t, std::size_t>> stored;  // records, bytes
  if (db.file) {
    Sqlite& sql = db.file->sql;
    sql.run([&] {
      Statement s(sql,
                  "SELECT v.object, count(*), sum(length(v.summary) + length(p.data) + "
                  "length(b.data)) FROM views v JOIN parts p USING(record) JOIN bodies b "
                  "USING(record) GROUP BY v.object");
      while (s.step())
        stored[s.text(0)] = {static_cast<std::size_t>(s.integer(1)),
                             static_cast<std::size_t>(s.integer(2))};
    });
  }
  std::size_t total_bytes = 0;
  for (const std::string& name : db.objects()) {
    int views = 0;
    std::size_t points = 0;
    for (const ModelView& v : db.views)
      if (v.object == name) {
        ++views;
        points += v.points;
      }
    total_points += points;
    const std::size_t bytes = stored.count(name) ? stored[name].second : 0;
    total_bytes += bytes;
    objects.push_back({{"name", name}, {"views", views}, {"points", points}, {"bytes", bytes}});
  }
  std::size_t file_bytes = 0;
  if (db.file)
    for (const char* suffix : {"", "-wal"}) {
      std::error_code ec;
      const auto n = fs::file_size(file_path(db.dir) + suffix, ec);
      if (!ec) file_bytes += n;
    }
  return {{"dir", db.dir},
          {"file", db.file ? file_path(db.dir) : ""},
          {"format_version", kVersion},
          {"units", "metres"},
          {"descriptor", to_json(db.descriptor)},
          {"objects", objects},
          {"views", db.views.size()},
          {"points", total_points},
          {"record_bytes", total_bytes},
          {"file_bytes", file_bytes},
          {"damaged", db.damaged}};
}

}  // namespace proxseg
