// The errors proxseg throws for bad input: InputError (what was wrong and where) and FileError
// (a file the system refuses). Every public function that reads user input throws only these
// for it; anything else is a bug.
#pragma once
#include <proxseg/core/errors.hpp>

#include <stdexcept>
#include <string>

namespace proxseg {

// Thrown for any problem with user input (files, fields, parameters). The message names the
// file or field and what was expected; the CLI prints it on one line and exits with 1.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// An InputError about a file the system refuses: missing, unreadable, unwritable, a directory
// instead of a file. Python raises OSError for it (FileNotFoundError, PermissionError,
// IsADirectoryError by `error`), ValueError for other InputErrors.
struct FileError : InputError {
  explicit FileError(const std::string& what, int error = 0) : InputError(what), error(error) {}
  int error = 0;  // the errno that tells what the system refused; 0 when none applies
};

}  // namespace proxseg
