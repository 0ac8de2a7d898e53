// The database as the Python module holds it: recognitions read it from several threads at once
// (shared lock), adding views writes it (exclusive lock).
#pragma once
#include <proxseg/core/database.hpp>

#include <mutex>
#include <shared_mutex>

namespace proxseg::python {

struct SharedDatabase {
  Database db;
  mutable std::shared_mutex mutex;
};

}  // namespace proxseg::python
