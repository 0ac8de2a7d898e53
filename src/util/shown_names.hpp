// Names (file, frame, object) as bytes until shown: a name that is not UTF-8 is shown in JSON
// with its bad bytes as \xFF-style text (and its backslashes doubled), so two bad names never
// collide and the bytes can be had back (name_from_shown). A UTF-8 name is shown as it is, unless
// it holds text that reads as such an escape (`a\xFFb`, `a\\b`): that one is escaped too, so that
// every name reads back to its own bytes.
#pragma once
#include <nlohmann/json.hpp>

#include <cstddef>
#include <string>
#include <utility>

namespace proxseg {

// The length of the UTF-8 sequence at s[i] (1 to 4), 0 when it is not one: strict as JSON wants
// it (no overlong forms, no surrogates, nothing above U+10FFFF).
inline std::size_t utf8_length(const std::string& s, std::size_t i) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[i + k]); };
  const auto cont = [&](std::size_t k) { return i + k < s.size() && (b(k) & 0xC0) == 0x80; };
  const unsigned char c = b(0);
  if (c < 0x80) return 1;
  if (c >= 0xC2 && c <= 0xDF) return cont(1) ? 2 : 0;
  if (c >= 0xE0 && c <= 0xEF) {
    if (!cont(1) || !cont(2)) return 0;
    if (c == 0xE0 && b(1) < 0xA0) return 0;   // overlong
    if (c == 0xED && b(1) >= 0xA0) return 0;  // a surrogate
    return 3;
  }
  if (c >= 0xF0 && c <= 0xF4) {
    if (!cont(1) || !cont(2) || !cont(3)) return 0;
    if (c == 0xF0 && b(1) < 0x90) return 0;   // overlong
    if (c == 0xF4 && b(1) >= 0x90) return 0;  // above U+10FFFF
    return 4;
  }
  return 0;
}

inline bool is_utf8(const std::string& s) {
  for (std::size_t i = 0; i < s.size();) {
    const std::size_t n = utf8_length(s, i);
    if (n == 0) return false;
    i += n;
  }
  return true;
}

// Whether s[i] starts what name_from_shown reads as an escape: \\ or \x and two hex digits.
inline bool escape_at(const std::string& s, std::size_t i) {
  const auto hex = [&](std::size_t k) {
    return k < s.size() && ((s[k] >= '0' && s[k] <= '9') || (s[k] >= 'A' && s[k] <= 'F'));
  };
  if (s[i] != '\\' || i + 1 >= s.size()) return false;
  return s[i + 1] == '\\' || (s[i + 1] == 'x' && hex(i + 2) && hex(i + 3));
}

// The name as JSON may hold it: itself when UTF-8 without escape-like text, else each bad byte
// as \xHH and each backslash as \\ (so the text reads back to the bytes, and two names never
// give one text).
inline std::string shown_name(const std::string& name) {
  bool plain = is_utf8(name);
  for (std::size_t i = 0; plain && i < name.size(); ++i) plain = !escape_at(name, i);
  if (plain) return name;
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (std::size_t i = 0; i < name.size();) {
    const std::size_t n = utf8_length(name, i);
    const auto c = static_cast<unsigned char>(name[i]);
    if (n == 0) {
      out += {'\\', 'x', hex[c >> 4], hex[c & 15]};
      ++i;
    } else {
      out += c == '\\' ? std::string("\\\\") : name.substr(i, n);
      i += n;
    }
  }
  return out;
}

// The bytes of a shown name: a text holding escapes was escaped (shown_name escapes every name
// that holds escape-like text), so they read back; any other text is the name itself.
inline std::string name_from_shown(const std::string& shown) {
  std::string out;
  for (std::size_t i = 0; i < shown.size(); ++i) {
    if (!escape_at(shown, i)) {
      out += shown[i];
    } else if (shown[i + 1] == '\\') {
      out += '\\';
      ++i;
    } else {
      const auto digit = [](char c) { return c <= '9' ? c - '0' : c - 'A' + 10; };
      out += static_cast<char>(digit(shown[i + 2]) * 16 + digit(shown[i + 3]));
      i += 3;
    }
  }
  return out;
}

// j with every string and key shown (shown_name): what can be dumped whatever bytes it holds.
inline nlohmann::json shown_json(const nlohmann::json& j) {
  if (j.is_string()) return shown_name(j.get_ref<const std::string&>());
  if (j.is_array()) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& v : j) out.push_back(shown_json(v));
    return out;
  }
  if (j.is_object()) {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& [key, v] : j.items()) out[shown_name(key)] = shown_json(v);
    return out;
  }
  return j;
}

// j's text (nlohmann::json::dump) with its names shown: never throws on bytes that are not UTF-8.
// Dumped as it is first: the copy is made only for a text that holds such bytes. A text already
// shown stays as it is (valid UTF-8), so where names must read back (batch logs) they are put in
// with shown_name, escape-like text and all.
inline std::string dump_shown(const nlohmann::json& j, int indent = -1) {
  try {
    return j.dump(indent);
  } catch (const nlohmann::json::type_error&) {
    return shown_json(j).dump(indent);
  }
}

}  // namespace proxseg
