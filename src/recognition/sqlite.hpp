// A SQLite connection as the model database uses it (docs/database.md, "Why SQLite"): one
// connection per opened database, shared by the threads that read views from it, statements made
// per call, every failure an InputError (damaged file) or FileError (the system refused: missing,
// locked too long, read-only, disk full) that names the file. SQLite's types stay in sqlite.cpp.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace proxseg::detail {

class Sqlite;

// A prepared statement; bind() numbers from 1, column() from 0. Used by one thread at a time,
// while it holds the connection (Sqlite::run()).
class Statement {
 public:
  Statement(Sqlite& db, const std::string& sql);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  Statement& bind(int i, std::int64_t v);
  Statement& bind(int i, const std::string& text);
  Statement& bind_blob(int i, const std::string& bytes);
  bool step();  // true: a row is ready
  std::int64_t integer(int col) const;
  std::string text(int col) const;
  std::string blob(int col) const;
  bool null(int col) const;

 private:
  Sqlite& db_;
  void* stmt_ = nullptr;
};

class Sqlite {
 public:
  enum class Mode {
    // An existing file, as it is: its journal mode is not changed. Opened read-write when this
    // process may write the file and its folder (so that the last to close it folds the -wal and
    // -shm back in, which a read-only connection cannot); else read-only, and immutable (no
    // -wal, -shm or lock made) unless a -wal holds changes not yet folded in (docs/database.md,
    // "Readers without write access").
    kRead,
    kWrite,   // an existing file, made WAL
    kCreate,  // the same, created when missing
  };
  // Opens the file at `path` with a busy timeout; the caller has checked that the path is a
  // plain file (no link, no special file).
  Sqlite(const std::string& path, Mode mode);
  ~Sqlite();
  Sqlite(const Sqlite&) = delete;
  Sqlite& operator=(const Sqlite&) = delete;

  const std::string& path() const { return path_; }
  // Runs f with the connection to itself (threads take turns).
  template <class F>
  auto run(F&& f) -> decltype(f()) {
    std::lock_guard<std::mutex> lock(mutex_);
    return f();
  }
  // Runs sql; a failure says what was being done (`doing`, or the statement).
  void exec(const std::string& sql, const std::string& doing = {});
  // f inside BEGIN IMMEDIATE ... COMMIT (the write lock taken first, so that two writers queue
  // instead of failing at commit); rolled back when f throws or the commit fails. A connection
  // opened to read is reopened to write first (FileError when this process may not write).
  void write(const std::function<void()>& f);
  // f inside one read transaction: everything it reads comes from one state of the file.
  void read(const std::function<void()>& f);
  std::int64_t last_insert_rowid() const;
  // Throws the error of result code `rc` (a SQLite code) about what was being done.
  [[noreturn]] void fail(int rc, const std::string& doing) const;
  void* handle() const { return db_; }

 private:
  // The connection `mode` wants, configured: its handle (the caller keeps or closes it).
  void* open(Mode mode) const;
  // Busy timeout, extended codes, page size and journal (WAL) as `mode` wants them.
  void configure(void* db, Mode mode) const;
  std::string path_;
  Mode mode_;
  void* db_ = nullptr;
  std::mutex mutex_;
};

}  // namespace proxseg::detail
