// The database as the Python module holds it: copy on write. A recognition takes the current
// snapshot and works on it without a lock; adding views (one writer at a time in a process, one
// across processes by the database file's own lock) makes a new snapshot and puts it in place.
// So a reader never waits for a writer, a writer never waits for readers (the pthread rwlock this
// replaces let a stream of recognitions keep an add waiting for 29 s), and every recognition sees
// the database with or without an add, never half of it.
#pragma once
#include <proxseg/core/database.hpp>

#include <memory>
#include <mutex>

namespace proxseg::python {

class SharedDatabase {
 public:
  explicit SharedDatabase(Database db) : db_(std::make_shared<const Database>(std::move(db))) {}
  std::shared_ptr<const Database> snapshot() const {
    std::lock_guard<std::mutex> lock(pointer_);
    return db_;
  }
  // Runs change(copy) on a copy of the current database (views share their loaded data) with
  // the other writers of this process waiting, then puts the copy in place.
  template <class F>
  auto change(F&& change) {
    std::lock_guard<std::mutex> writing(writer_);
    auto copy = std::make_shared<Database>(*snapshot());
    auto result = change(*copy);
    std::lock_guard<std::mutex> lock(pointer_);
    db_ = std::move(copy);
    return result;
  }

 private:
  mutable std::mutex pointer_, writer_;
  std::shared_ptr<const Database> db_;
};

}  // namespace proxseg::python
