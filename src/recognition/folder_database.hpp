// Version 1 of the model database: a folder with index.json, one PCD and one feature cache per
// view (docs/database.md, "Upgrading"). Only `proxseg db upgrade` reads it.
#pragma once
#include <proxseg/core/database.hpp>

#include <string>

namespace proxseg::detail {

// The database's "format" setting, the same in the version-1 folder and the database file.
inline constexpr const char* kDatabaseFormat = "proxseg-model-database";

// Whether DIR holds a version-1 index (DIR/index.json).
bool is_folder_database(const std::string& dir);
// Reads DIR/index.json, every view's PCD and feature cache into views held in memory (named
// after their files: "duck-000"). Throws InputError naming the file and what is wrong (missing
// view, stale or truncated cache, bad index field, a link or special file among them).
Database read_folder_database(const std::string& dir);

}  // namespace proxseg::detail
