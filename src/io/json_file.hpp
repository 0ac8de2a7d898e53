// JSON as the readers take it from files (configs, the reports `view` reads): parsed with its
// nesting bounded, so that no later step (dump(), a recursive walk) runs out of stack, and quoted
// in messages by a short excerpt. Private to the library (docs/robustness.md, "Bad inputs").
#pragma once
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace proxseg::detail {

// The deepest nesting of arrays and objects a reader accepts.
inline constexpr int kMaxJsonDepth = 64;

// Whether text nests arrays and objects deeper than max_depth (brackets in strings not counted).
bool json_too_deep(std::string_view text, int max_depth = kMaxJsonDepth);

// text parsed; InputError "WHERE: not valid JSON (...)" or "WHERE: nested deeper than 64 levels
// (expected at most 64)". where names the file.
nlohmann::json parse_json(const std::string& text, const std::string& where);

// The file at path (a regular file, read_input_file) parsed as parse_json does.
nlohmann::json read_json_file(const std::string& path);

// A value as a message quotes it: a scalar's JSON cut to max_len characters, an array or object
// by its size ("an array of 3 elements"), never walked.
std::string json_excerpt(const nlohmann::json& value, std::size_t max_len = 60);

}  // namespace proxseg::detail
