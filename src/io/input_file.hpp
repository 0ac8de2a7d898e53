// Input files as the readers take them: regular files only (a FIFO would hang the read, a link to
// /dev/zero would never end it), read by one descriptor that was checked, at most as many bytes
// as the caller expects. Private to the library (docs/robustness.md, "Special files").
#pragma once
#include <cstddef>
#include <limits>
#include <string>

namespace proxseg::detail {

// What path names when it is not a readable regular file, as a message fragment ("is a FIFO
// (expected a regular file)", "file not found (expected an existing file)", "is a symbolic link
// loop", ...); "" for a regular file (a link to one included).
std::string not_a_regular_file(const std::string& path);

// Throws FileError "PATH: <not_a_regular_file(PATH)>" unless path names a regular file.
void require_regular_file(const std::string& path);

// The first max_bytes bytes of the regular file at path (all of it when shorter). The file is
// opened without blocking and checked through that descriptor, so that a FIFO or device put in
// its place after a check is refused too. FileError when it cannot be opened or read.
std::string read_input_file(const std::string& path,
                            std::size_t max_bytes = std::numeric_limits<std::size_t>::max());

}  // namespace proxseg::detail
