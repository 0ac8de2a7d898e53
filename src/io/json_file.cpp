// JSON read from files with its nesting bounded (json_file.hpp).
#include "io/json_file.hpp"

#include "io/input_file.hpp"
#include "io/reader_errors.hpp"

namespace proxseg::detail {

bool json_too_deep(std::string_view text, int max_depth) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (char c : text) {
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) return true;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return false;
}

nlohmann::json parse_json(const std::string& text, const std::string& where) {
  if (json_too_deep(text))
    fail(where, "nested deeper than " + std::to_string(kMaxJsonDepth) +
                    " levels (expected at most " + std::to_string(kMaxJsonDepth) + ")");
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {  // parse errors, numbers out of range (406)
    fail(where, "not valid JSON (" + quote(e.what(), 200) + ")");
  }
}

nlohmann::json read_json_file(const std::string& path) {
  return parse_json(read_input_file(path), path);
}

std::string json_excerpt(const nlohmann::json& value, std::size_t max_len) {
  if (value.is_array()) return "an array of " + std::to_string(value.size()) + " elements";
  if (value.is_object()) return "an object of " + std::to_string(value.size()) + " fields";
  return quote(value.dump(), max_len);
}

}  // namespace proxseg::detail
