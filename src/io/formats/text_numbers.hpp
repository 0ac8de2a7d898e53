// Numbers in the text of the readers' formats (PCD, OBJ, MTL): a whole field or nothing, through
// std::from_chars (no locale, exact round trip). Private to the library.
#pragma once
#include <charconv>
#include <cstdint>
#include <string_view>
#include <system_error>

namespace proxseg::detail {

// s as an unsigned integer, digits only.
inline bool parse_u64(std::string_view s, std::uint64_t& v) {
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

// s as a number of type T (float, double or a signed integer), a leading '+' allowed.
template <typename T>
bool parse_number(std::string_view s, T& v) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

}  // namespace proxseg::detail
