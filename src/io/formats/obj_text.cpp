// The text of Wavefront OBJ and MTL files (obj_text.hpp).
#include "io/formats/obj_text.hpp"

#include <algorithm>

#include "io/input_file.hpp"
#include "io/reader_errors.hpp"

namespace fs = std::filesystem;

namespace proxseg::detail::wavefront {
namespace {

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

}  // namespace

// "path: line 12: what"
void fail_line(const std::string& path, std::size_t line, const std::string& what) {
  fail(path, "line " + std::to_string(line) + ": " + what);
}

// Checks that path names a regular file; `named_by` says where the name came from.
void require_file(const std::string& path, const std::string& named_by) {
  std::string why = not_a_regular_file(path);
  if (why.empty()) return;
  if (!named_by.empty() && why.back() == ')') why.insert(why.size() - 1, named_by);
  fail_file(path, why);
}

std::string read_text(const std::string& path, const std::string& named_by) {
  require_file(path, named_by);
  return read_input_file(path);
}

// The line of `all` that starts at pos (without its '\n' and anything from a '#' comment on);
// pos moves to the next line.
std::string_view next_line(std::string_view all, std::size_t& pos) {
  std::size_t end = all.find('\n', pos);
  if (end == std::string_view::npos) end = all.size();
  std::string_view line = all.substr(pos, end - pos);
  pos = end < all.size() ? end + 1 : end;
  const std::size_t hash = line.find('#');
  if (hash != std::string_view::npos) line = line.substr(0, hash);
  return line;
}

std::vector<std::string_view> split_ws(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const std::size_t b = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > b) out.push_back(line.substr(b, i - b));
  }
  return out;
}

// The text of `line` from token `from` on, trimmed: a file or material name may hold spaces.
std::string rest_of_line(std::string_view line, std::string_view from) {
  std::string_view rest = line.substr(static_cast<std::size_t>(from.data() - line.data()));
  while (!rest.empty() && is_space(rest.back())) rest.remove_suffix(1);
  return std::string(rest);
}

// The file a name in an OBJ or MTL refers to: relative names are relative to the directory of
// the file that holds them. Windows exporters write backslashes, taken as separators unless a
// file with the literal name exists.
std::string resolve(const fs::path& dir, const std::string& name) {
  const fs::path literal = dir / name;
  std::string slashed = name;
  std::replace(slashed.begin(), slashed.end(), '\\', '/');
  if (slashed == name || fs::exists(literal)) return literal.string();
  return (dir / slashed).string();
}

std::string where(const std::string& path, std::size_t line) {
  return " named by " + path + " line " + std::to_string(line);
}

}  // namespace proxseg::detail::wavefront
