// A view's records in the model database file (docs/database.md, "Records"): its row (object,
// name, source, sizes, summary) and its parts and body records, each checked when read; a stored
// view reads its parts and body on first use (database_records.hpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/recognition/model_view.hpp>

#include <cstdio>

#include "database_records.hpp"
#include "util/shown_names.hpp"
#include "view_record.hpp"

namespace proxseg::detail {
namespace {

// File-name-safe form of an object name, the stem of its views' names.
std::string slug(const std::string& name) {
  std::string s;
  for (unsigned char c : name) s += std::isalnum(c) || c == '-' || c == '_' || c == '.' ? c : '_';
  return s;
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

}  // namespace

std::string where_of(const std::string& path, const std::string& name, std::int64_t record) {
  return path + " view " + name + " (record " + std::to_string(record) + ")";
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

namespace {

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

}  // namespace

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
        // Names as shown (util/shown_names.hpp): one written before names had to be UTF-8 is
        // read with its bad bytes as \xFF text, not a database every JSON of fails on.
        const std::string name = shown_name(s.text(2));
        const std::string where = where_of(sql.path(), name, record);
        try {
          const std::int64_t points = s.integer(4);
          if (points < 10 || points > (std::int64_t(1) << 31))
            throw InputError(where + ": its row says " + std::to_string(points) + " points");
          const auto summary = detail::decode_summary(where, s.blob(6));
          db.views.push_back(stored_view(db.file, record, shown_name(s.text(1)), name,
                                         shown_name(s.text(3)), static_cast<std::size_t>(points),
                                         s.integer(5) != 0, summary, feature_dims(db.descriptor)));
        } catch (const InputError& e) {
          db.damaged.push_back(e.what());
        }
      }
    });
  });
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

}  // namespace proxseg::detail
