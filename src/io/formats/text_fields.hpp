// Splitting a text line of the readers' formats (PCD header, PLY header) into its fields.
// Private to the library.
#pragma once
#include <string_view>
#include <vector>

namespace proxseg::detail {

// The fields of a line separated by spaces, tabs or a carriage return (views into line).
inline std::vector<std::string_view> split_ws(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t b = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > b) out.push_back(line.substr(b, i - b));
  }
  return out;
}

}  // namespace proxseg::detail
