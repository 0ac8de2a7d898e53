// The text of Wavefront OBJ and MTL files as both readers take it: lines without their '#'
// comments, fields split at any white space, names that may hold spaces, numbers, file names
// relative to the file that names them, and errors naming the file and line. Private to the
// library.
#pragma once
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "io/formats/text_numbers.hpp"

namespace proxseg::detail::wavefront {

// "path: line 12: what"
[[noreturn]] void fail_line(const std::string& path, std::size_t line, const std::string& what);

// Checks that path names a regular file; `named_by` says where the name came from.
void require_file(const std::string& path, const std::string& named_by);
// The whole file at path, checked as require_file does.
std::string read_text(const std::string& path, const std::string& named_by);

// The line of `all` that starts at pos (without its '\n' and anything from a '#' comment on);
// pos moves to the next line.
std::string_view next_line(std::string_view all, std::size_t& pos);
// The fields of a line separated by white space (views into line).
std::vector<std::string_view> split_ws(std::string_view line);
// The text of `line` from token `from` on, trimmed: a file or material name may hold spaces.
std::string rest_of_line(std::string_view line, std::string_view from);

// s as a finite number, a leading '+' allowed.
inline bool parse_double(std::string_view s, double& v) {
  return parse_number(s, v) && std::isfinite(v);
}

// The file a name in an OBJ or MTL refers to: relative names are relative to the directory of
// the file that holds them. Windows exporters write backslashes, taken as separators unless a
// file with the literal name exists.
std::string resolve(const std::filesystem::path& dir, const std::string& name);

// " named by PATH line N": where a file's name was read, for its messages.
std::string where(const std::string& path, std::size_t line);

}  // namespace proxseg::detail::wavefront
