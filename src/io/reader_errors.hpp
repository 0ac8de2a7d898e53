// How the readers and writers of files word what is wrong: "PATH: what (expected ...)", an
// InputError for the content of a file and a FileError for a file the system refuses, text
// quoted from the file made safe for a one-line message (docs/robustness.md). Private to the
// library.
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>

#include <cstddef>
#include <string>
#include <string_view>

namespace proxseg::detail {

[[noreturn]] inline void fail(const std::string& path, const std::string& what) {
  throw InputError(path + ": " + what);
}
// The same for a file the system refuses (missing, unreadable, unwritable).
[[noreturn]] inline void fail_file(const std::string& path, const std::string& what) {
  throw FileError(path + ": " + what);
}

// Makes text from a file safe to quote in a one-line message.
inline std::string quote(std::string_view s, std::size_t max_len = 60) {
  std::string out;
  for (char c : s.substr(0, max_len)) {
    const auto u = static_cast<unsigned char>(c);
    out += (u >= 32 && u < 127) ? c : '?';
  }
  if (s.size() > max_len) out += "...";
  return "'" + out + "'";
}

// A library's message (a parser's, a codec's) on one line.
inline std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

}  // namespace proxseg::detail
