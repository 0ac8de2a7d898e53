// The model database on disk (docs/database.md): one SQLite file, DIR/database.sqlite, that
// holds per view a small summary (what the shortlist compares), its parts' signatures and its
// body (points, normals, FPFH, colours), each record with its checksum. Opening reads the
// summaries only; a view's parts and body are read when recognition first needs them. Any
// number of processes and threads may read it while one at a time adds to it; a reader sees the
// database as it was when it opened it (plus its own adds), never half an add.
#pragma once
#include <proxseg/core/database.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace proxseg {

// The database file in its directory.
inline constexpr const char* kDatabaseFile = "database.sqlite";

// Opens the database in DIR: reads the descriptor and every view's summary. A view whose summary
// is damaged is left out and named in Database::damaged. Throws InputError naming the file and
// what is wrong (not a database, another format version, a version-1 folder database that
// `proxseg db upgrade` converts), FileError when the system refuses it (missing, a symbolic link
// or special file in place of the database's files, locked for longer than 30 s).
Database load_database(const std::string& dir);
// The database in DIR if it exists; otherwise a new empty one with these descriptor parameters
// (nothing is written until a view is added). The descriptor is checked (InputError naming
// voxel_size, normal_radius or fpfh_radii). descriptor_given: the caller chose it, so a database
// that exists with other descriptor parameters is an InputError (they apply to a new one only)
// rather than opened with its own.
Database open_database(const std::string& dir, const DescriptorParams& descriptor,
                       bool descriptor_given = false);

// Describes one view (points in the model frame, viewpoint = sensor position in that frame,
// NaN for a full model) and adds it in one transaction: another process's add waits for it,
// readers see the database with or without it, a crash or a full disk leaves the database as it
// was. The view is appended to db.views as a later load_database() reads it (float precision).
const ModelView& add_view(Database& db, const std::string& object, const Frame& points,
                          const Eigen::Vector3d& viewpoint, const std::string& source);
// Removes every view of `object` (one transaction); the number removed. InputError when the
// database has no such object.
int remove_object(Database& db, const std::string& object);
// Gives `from`'s views the name `to` (which may be an object already there: the views join it);
// the number renamed. InputError when there is no `from` or `to` is not a valid name.
int rename_object(Database& db, const std::string& from, const std::string& to);

// What `proxseg db check` finds: every record read and its checksum and contents verified.
struct DatabaseCheck {
  int views = 0;                     // views listed
  int whole = 0;                     // of them, with every record whole
  std::vector<std::string> damaged;  // one line per damaged record or structure: where and what
};
DatabaseCheck check_database(const std::string& dir);

// Writes every view of `db` (made in memory, or read from another database) into the database
// in DIR, one transaction, creating it with db.descriptor when missing (an existing one must have
// the same descriptor). A view whose name is taken there gets a free one. Returns the views
// written. What a benchmark or a program that renders thousands of views uses instead of one
// add_view() per view.
int write_database(const Database& db, const std::string& dir);

// Converts the version-1 folder database in DIR (index.json, views/*.pcd, views/*.fpfh) into
// DIR/database.sqlite with the same views, signatures and names, so that recognition gives the
// same answers; the old files are left as they were (no longer read). Returns the views
// converted. InputError when DIR has no version-1 index, or already has a database file.
int upgrade_database(const std::string& dir);

// Descriptor, objects (views, points, bytes), totals and the file's size.
nlohmann::json database_info(const Database& db);

}  // namespace proxseg
