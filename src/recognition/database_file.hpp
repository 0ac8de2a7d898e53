// The model database file (docs/database.md): DIR/database.sqlite, a SQLite file in WAL mode;
// where it is, how it is opened, its settings (format, version, units, the sealed descriptor) and
// the checks of what goes into it. Private to src/recognition.
#pragma once
#include <proxseg/core/database.hpp>

#include <cstddef>
#include <memory>
#include <string>

#include "sqlite.hpp"

namespace proxseg {

struct DatabaseFile {
  DatabaseFile(const std::string& path, detail::Sqlite::Mode mode) : sql(path, mode) {}
  detail::Sqlite sql;
};

namespace detail {

// The version of the file's format this proxseg reads and writes.
constexpr int kFormatVersion = 2;

// DIR/database.sqlite.
std::string file_path(const std::string& dir);
// Whether the database file exists in DIR; FileError when DIR is not a directory or one of the
// database's files is a link or not a regular file.
bool check_own_files(const std::string& dir);
// The database file in DIR, opened (DIR resolved first: it may be a link).
std::shared_ptr<DatabaseFile> open_file(const std::string& dir, Sqlite::Mode mode);
// InputError with the hint to upgrade, for a directory that holds a version-1 folder database.
void refuse_folder_database(const std::string& dir);

// InputError for an empty name, "unknown" or a name with control characters.
void check_name(const std::string& object);
// InputError naming voxel_size, normal_radius or fpfh_radii when one is not positive and finite.
void check_descriptor(const DescriptorParams& d);
// The database's format, version and units, checked; its descriptor.
DescriptorParams read_settings(Sqlite& sql);
// Creates the tables and settings of a new file, or checks that an existing one holds the same
// descriptor. Inside a write.
void ensure_settings(Sqlite& sql, const DescriptorParams& descriptor);
// The rows of a view's FPFH features: 33 per radius.
std::size_t feature_dims(const DescriptorParams& d);

}  // namespace detail
}  // namespace proxseg
