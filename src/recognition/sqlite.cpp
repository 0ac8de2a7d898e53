// The one place SQLite's C API is used (sqlite.hpp).
#include "sqlite.hpp"

#include <sqlite3.h>

#include <cstring>
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>

namespace proxseg::detail {
namespace {

sqlite3* db_of(void* p) {
  return static_cast<sqlite3*>(p);
}
sqlite3_stmt* statement(void* p) {
  return static_cast<sqlite3_stmt*>(p);
}

// A writer waits this long for another writer (an add takes tens of milliseconds; a reader never
// holds it up: readers and the writer work on their own snapshots in WAL mode).
constexpr int kBusyTimeoutMs = 30000;

}  // namespace

Statement::Statement(Sqlite& db, const std::string& sql) : db_(db) {
  sqlite3_stmt* s = nullptr;
  const int rc = sqlite3_prepare_v2(db_of(db.handle()), sql.c_str(), -1, &s, nullptr);
  if (rc != SQLITE_OK) db.fail(rc, "preparing \"" + sql + "\"");
  stmt_ = s;
}

Statement::~Statement() {
  sqlite3_finalize(statement(stmt_));
}

Statement& Statement::bind(int i, std::int64_t v) {
  sqlite3_bind_int64(statement(stmt_), i, v);
  return *this;
}

Statement& Statement::bind(int i, const std::string& text) {
  sqlite3_bind_text(statement(stmt_), i, text.data(), static_cast<int>(text.size()),
                    SQLITE_TRANSIENT);
  return *this;
}

Statement& Statement::bind_blob(int i, const std::string& bytes) {
  sqlite3_bind_blob64(statement(stmt_), i, bytes.data(), bytes.size(), SQLITE_TRANSIENT);
  return *this;
}

bool Statement::step() {
  const int rc = sqlite3_step(statement(stmt_));
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  db_.fail(rc, "reading its records");
}

std::int64_t Statement::integer(int col) const {
  return sqlite3_column_int64(statement(stmt_), col);
}

std::string Statement::text(int col) const {
  const auto* p = sqlite3_column_text(statement(stmt_), col);
  return p ? std::string(reinterpret_cast<const char*>(p),
                         static_cast<std::size_t>(sqlite3_column_bytes(statement(stmt_), col)))
           : std::string();
}

std::string Statement::blob(int col) const {
  const void* p = sqlite3_column_blob(statement(stmt_), col);
  const int n = sqlite3_column_bytes(statement(stmt_), col);
  return p ? std::string(static_cast<const char*>(p), static_cast<std::size_t>(n)) : std::string();
}

bool Statement::null(int col) const {
  return sqlite3_column_type(statement(stmt_), col) == SQLITE_NULL;
}

Sqlite::Sqlite(const std::string& path, Mode mode) : path_(path) {
  const int flags = SQLITE_OPEN_READWRITE | (mode == Mode::kCreate ? SQLITE_OPEN_CREATE : 0) |
                    SQLITE_OPEN_FULLMUTEX | SQLITE_OPEN_NOFOLLOW;
  sqlite3* db = nullptr;
  const int rc = sqlite3_open_v2(path.c_str(), &db, flags, nullptr);
  db_ = db;
  if (rc != SQLITE_OK) {
    const std::string why = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
    const int error = db ? sqlite3_system_errno(db) : 0;
    sqlite3_close(db);
    db_ = nullptr;
    throw FileError(path + ": cannot open the model database (" + why + ")", error);
  }
  // The destructor does not run when the constructor throws: close the connection here.
  try {
    configure(mode);
  } catch (...) {
    sqlite3_close_v2(db);
    db_ = nullptr;
    throw;
  }
}

void Sqlite::configure(Mode mode) {
  sqlite3_busy_timeout(db_of(db_), kBusyTimeoutMs);
  sqlite3_extended_result_codes(db_of(db_), 1);
  // Checks that the file is a SQLite database at all (the first read of the header), and makes
  // it WAL: readers and a writer never wait for each other, a crash leaves the last commit.
  if (mode == Mode::kCreate)  // a new file only; no effect on one that has pages
    // 64 KB pages: the views table (600 bytes a view) in few pages, so opening reads 4,096 views
    // in ~40 reads instead of ~700, and a view's body (~250 KB) in 4 pages instead of 62.
    exec("PRAGMA page_size=65536", "creating it");
  if (mode != Mode::kRead) {
    exec("PRAGMA journal_mode=WAL", "opening it");
    exec("PRAGMA synchronous=FULL", "opening it");
  } else {
    exec("PRAGMA schema_version", "opening it");
  }
}

Sqlite::~Sqlite() {
  sqlite3_close_v2(db_of(db_));
}

void Sqlite::exec(const std::string& sql, const std::string& doing) {
  char* message = nullptr;
  const int rc = sqlite3_exec(db_of(db_), sql.c_str(), nullptr, nullptr, &message);
  sqlite3_free(message);
  if (rc != SQLITE_OK) fail(rc, doing.empty() ? "running \"" + sql + "\"" : doing);
}

void Sqlite::write(const std::function<void()>& f) {
  exec("BEGIN IMMEDIATE", "waiting to write");
  try {
    f();
    exec("COMMIT", "committing (the change is not in the database; what was there is kept)");
  } catch (...) {
    sqlite3_exec(db_of(db_), "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
}

void Sqlite::read(const std::function<void()>& f) {
  exec("BEGIN");
  try {
    f();
    exec("COMMIT");
  } catch (...) {
    sqlite3_exec(db_of(db_), "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
}

std::int64_t Sqlite::last_insert_rowid() const {
  return sqlite3_last_insert_rowid(db_of(db_));
}

void Sqlite::fail(int rc, const std::string& doing) const {
  std::string why = db_ ? sqlite3_errmsg(db_of(db_)) : sqlite3_errstr(rc);
  // What the system said, when it said something (a write refused: "File too large").
  if (const int e = db_ ? sqlite3_system_errno(db_of(db_)) : 0;
      e != 0 && (rc & 0xff) != SQLITE_BUSY)
    why += ": " + std::string(std::strerror(e));
  switch (rc & 0xff) {
    case SQLITE_FULL:
      throw FileError(path_ + ": the disk is full (" + why + "); the database is as it was");
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
      throw FileError(path_ + ": locked by another writer for more than " +
                      std::to_string(kBusyTimeoutMs / 1000) + " s (" + why + ")");
    case SQLITE_READONLY:
    case SQLITE_PERM:
    case SQLITE_CANTOPEN:
    case SQLITE_IOERR:
      throw FileError(path_ + ": " + why + " while " + doing);
    case SQLITE_CORRUPT:
    case SQLITE_NOTADB:
      throw InputError(path_ + ": damaged or not a proxseg model database (" + why + ") while " +
                       doing + "; see proxseg db check");
    default:
      throw InputError(path_ + ": " + why + " while " + doing);
  }
}

}  // namespace proxseg::detail
