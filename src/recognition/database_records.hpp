// A view's records in the model database file (docs/database.md, "Records"): the row with its
// summary, its parts and its body, read (lazily, for a stored view) and written. Private to
// src/recognition.
#pragma once
#include <proxseg/core/database.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "database_file.hpp"
#include "sqlite.hpp"

namespace proxseg::detail {

// "PATH view NAME (record N)": where a damaged record is, in messages.
std::string where_of(const std::string& path, const std::string& name, std::int64_t record);
// The parts and the body of a stored view, read and checked against its row (InputError naming
// `where` when damaged or missing).
std::vector<Signature> read_parts(DatabaseFile& file, std::int64_t record,
                                  const std::string& where);
Cloud read_body(DatabaseFile& file, std::int64_t record, const std::string& where,
                std::size_t points, std::size_t dims, const Eigen::Vector3d& viewpoint,
                bool coloured);
// The descriptor and the views of db.file in one read transaction; damaged summaries go to
// db.damaged.
void read_views(Database& db);

// The next free name for a view of `object`: slug-NNN.
std::string free_name(Sqlite& sql, const std::string& object);
// Writes one view's records; its record number. Inside a write.
std::int64_t insert_view(Sqlite& sql, const ModelView& v, const std::string& body);
// Writes every view of db in one transaction (see database_records.cpp).
void insert_views(Sqlite& sql, const Database& db, bool rename);

}  // namespace proxseg::detail
