// The model database's maintenance (docs/database.md): removing and renaming objects, checking
// every record, upgrading a version-1 folder database, and the summary `proxseg db info` shows.
#include <proxseg/core/errors.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/recognition/database_io.hpp>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <map>

#include "database_file.hpp"
#include "database_records.hpp"
#include "folder_database.hpp"
#include "util/shown_names.hpp"

namespace fs = std::filesystem;

namespace proxseg {

using detail::check_name;
using detail::check_own_files;
using detail::feature_dims;
using detail::file_path;
using detail::insert_views;
using detail::open_file;
using detail::read_body;
using detail::read_parts;
using detail::read_settings;
using detail::Sqlite;
using detail::Statement;
using detail::where_of;

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

// Changes the views of `object` in one write (change, given the connection), the settings checked
// first; the number of those views. InputError when the database has no such object.
int change_object(Database& db, const std::string& object,
                  const std::function<void(Sqlite&)>& change) {
  Sqlite& sql = writable(db);
  int count = 0;
  sql.run([&] {
    sql.write([&] {
      read_settings(sql);
      count = count_of(sql, object);
      if (count == 0) throw InputError(db.dir + ": no object named \"" + object + "\"");
      change(sql);
    });
  });
  return count;
}

}  // namespace

int remove_object(Database& db, const std::string& object) {
  const std::string stored = name_from_shown(object);  // the bytes of a name read shown
  const int removed = change_object(db, stored, [&](Sqlite& sql) {
    for (const char* table : {"parts", "bodies"}) {
      Statement s(sql, std::string("DELETE FROM ") + table +
                           " WHERE record IN (SELECT record FROM views WHERE object = ?)");
      s.bind(1, stored);
      s.step();
    }
    Statement s(sql, "DELETE FROM views WHERE object = ?");
    s.bind(1, stored);
    s.step();
  });
  db.views.erase(std::remove_if(db.views.begin(), db.views.end(),
                                [&](const ModelView& v) { return v.object == object; }),
                 db.views.end());
  return removed;
}

int rename_object(Database& db, const std::string& from, const std::string& to) {
  check_name(to);
  const std::string stored = name_from_shown(from);  // the bytes of a name read shown
  const int renamed = change_object(db, stored, [&](Sqlite& sql) {
    Statement s(sql, "UPDATE views SET object = ? WHERE object = ?");
    s.bind(1, to).bind(2, stored);
    s.step();
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
        stored[shown_name(s.text(0))] = {static_cast<std::size_t>(s.integer(1)),
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
          {"format_version", detail::kFormatVersion},
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
