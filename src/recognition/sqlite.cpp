// The one place SQLite's C API is used (sqlite.hpp).
#include "sqlite.hpp"

#include <sqlite3.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>

namespace fs = std::filesystem;

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

// A "file:" URI naming `path` (absolute), every byte but letters, digits, "/-_.~" percent-encoded:
// SQLite decodes them, and a "?", "#" or "%" in a name would otherwise start the query, the
// fragment or an escape.
std::string file_uri(const std::string& path) {
  std::string uri = "file://";
  for (const unsigned char c : fs::absolute(path).string()) {
    if (std::isalnum(c) || std::strchr("/-_.~", c)) {
      uri += static_cast<char>(c);
    } else {
      char hex[4];
      std::snprintf(hex, sizeof hex, "%%%02X", c);
      uri += hex;
    }
  }
  return uri;
}

// Why this process may not write `p` ("" when it may), said of `what` ("it", "its folder DIR"):
// the system refuses (another user's file, a read-only mount), or nobody may (a mode without a
// write bit: root may write anything, but a file or folder made read-only is meant to stay so).
std::string refusal(const std::string& p, const std::string& what) {
  struct stat st {};
  const std::string who = what == "it" ? "" : what + ": ";  // the file itself goes unnamed
  if (::stat(p.c_str(), &st) != 0) return who + std::strerror(errno);
  if ((st.st_mode & 0222) == 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    return what + " has mode " + mode;
  }
  if (::faccessat(AT_FDCWD, p.c_str(), W_OK, AT_EACCESS) != 0) return who + std::strerror(errno);
  return "";
}

// Why this process may not write the database file or make files beside it ("" when it may).
std::string write_refusal(const std::string& path) {
  if (std::string why = refusal(path, "it"); !why.empty()) return why;
  std::string dir = fs::path(path).parent_path().string();
  if (dir.empty()) dir = ".";
  return refusal(dir, "its folder " + dir);
}

// Whether the -wal beside `path` holds pages (changes that may not be in the file yet).
bool wal_holds_changes(const std::string& path) {
  std::error_code ec;
  const auto size = fs::file_size(path + "-wal", ec);
  return !ec && size > 0;
}

// The error of result code `rc` (a SQLite code) on connection `db` (may be null) of the file at
// `path`, about what was being done: FileError when the system refused, InputError when the file
// is damaged or not a database.
[[noreturn]] void fail_on(const std::string& path, void* handle, int rc, const std::string& doing) {
  sqlite3* db = db_of(handle);
  std::string why = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
  // What the system said, when it said something (a write refused: "File too large").
  if (const int e = db ? sqlite3_system_errno(db) : 0; e != 0 && (rc & 0xff) != SQLITE_BUSY)
    why += ": " + std::string(std::strerror(e));
  switch (rc & 0xff) {
    case SQLITE_FULL:
      throw FileError(path + ": the disk is full (" + why + "); the database is as it was");
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
      throw FileError(path + ": locked by another writer for more than " +
                      std::to_string(kBusyTimeoutMs / 1000) + " s (" + why + ")");
    case SQLITE_READONLY:
    case SQLITE_PERM:
    case SQLITE_CANTOPEN:
    case SQLITE_IOERR:
      throw FileError(path + ": " + why + " while " + doing);
    case SQLITE_NOTADB:  // the header is not SQLite's: another kind of file, or overwritten
      throw InputError(path + ": not a SQLite database file (" + why + " while " + doing +
                       "): not a proxseg model database, or its header is damaged");
    case SQLITE_CORRUPT:  // the structure is damaged (`db check` runs SQLite's quick_check)
      throw InputError(path + ": the database file is damaged (" + why + ") while " + doing);
    default:
      throw InputError(path + ": " + why + " while " + doing);
  }
}

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

Sqlite::Sqlite(const std::string& path, Mode mode) : path_(path), mode_(mode) {
  db_ = open(mode);
}

void* Sqlite::open(Mode mode) const {
  int flags = SQLITE_OPEN_URI | SQLITE_OPEN_FULLMUTEX | SQLITE_OPEN_NOFOLLOW;
  std::string uri = file_uri(path_);
  std::string wal_note;  // why a read-only open that fails may have failed
  if (mode == Mode::kRead && !write_refusal(path_).empty()) {
    flags |= SQLITE_OPEN_READONLY;
    if (!wal_holds_changes(path_)) {
      uri += "?immutable=1";
    } else {
      // Read through the -wal and the -shm that indexes it; SQLite would make a missing -shm.
      wal_note = path_ + "-wal holds changes not yet folded into the file, which this process " +
                 "cannot read without writing beside it (" + write_refusal(path_) +
                 "): open the database once as a user who may write it, e.g. `proxseg db info " +
                 fs::path(path_).parent_path().string() + "`";
      std::error_code ec;
      if (!fs::exists(path_ + "-shm", ec))
        throw FileError(wal_note + " (there is no " + path_ + "-shm to read it by)", EACCES);
      wal_note = "; " + wal_note;
    }
  } else {
    flags |= SQLITE_OPEN_READWRITE | (mode == Mode::kCreate ? SQLITE_OPEN_CREATE : 0);
    // A file this process may not write would be opened read-only by SQLite, which then makes
    // a -wal and -shm with the file's mode that no later writer could use.
    if (mode != Mode::kCreate || fs::exists(path_))
      if (const std::string why = write_refusal(path_); !why.empty())
        throw FileError(path_ + ": cannot be written (" + why + ")", EACCES);
  }
  sqlite3* db = nullptr;
  const int rc = sqlite3_open_v2(uri.c_str(), &db, flags, nullptr);
  if (rc != SQLITE_OK) {
    std::string why = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
    const int error = db ? sqlite3_system_errno(db) : 0;
    if (error != 0) why += ": " + std::string(std::strerror(error));
    sqlite3_close(db);
    throw FileError(path_ + ": cannot open the model database (" + why + ")" + wal_note, error);
  }
  // The caller keeps the connection only when it is configured: close it here otherwise.
  try {
    configure(db, mode);
  } catch (const std::exception& e) {
    sqlite3_close_v2(db);
    if (wal_note.empty()) throw;
    throw FileError(e.what() + wal_note, EACCES);
  }
  return db;
}

void Sqlite::configure(void* handle, Mode mode) const {
  sqlite3* db = db_of(handle);
  sqlite3_busy_timeout(db, kBusyTimeoutMs);
  sqlite3_extended_result_codes(db, 1);
  auto exec = [&](const char* sql, const std::string& doing) {
    const int rc = sqlite3_exec(db, sql, nullptr, nullptr, nullptr);
    if (rc != SQLITE_OK) fail_on(path_, db, rc, doing);
  };
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
  // A writer folds what it wrote into the file (as far as no reader still reads an older
  // state), so that a reader that may not write beside the file finds it there; the last
  // connection to close removes the -wal and -shm (docs/database.md, "Readers").
  if (mode_ != Mode::kRead)
    sqlite3_wal_checkpoint_v2(db_of(db_), nullptr, SQLITE_CHECKPOINT_PASSIVE, nullptr, nullptr);
  sqlite3_close_v2(db_of(db_));
}

void Sqlite::exec(const std::string& sql, const std::string& doing) {
  char* message = nullptr;
  const int rc = sqlite3_exec(db_of(db_), sql.c_str(), nullptr, nullptr, &message);
  sqlite3_free(message);
  if (rc != SQLITE_OK) fail(rc, doing.empty() ? "running \"" + sql + "\"" : doing);
}

void Sqlite::write(const std::function<void()>& f) {
  if (mode_ == Mode::kRead) {  // opened to read: reopened to write (WAL), the old one closed
    void* db = open(Mode::kWrite);
    sqlite3_close_v2(db_of(db_));
    db_ = db;
    mode_ = Mode::kWrite;
  }
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
  fail_on(path_, db_, rc, doing);
}

}  // namespace proxseg::detail
