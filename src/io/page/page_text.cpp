// The pages' HTML from their templates (page_text.hpp).
#include "io/page/page_text.hpp"

#include <proxseg/core/version.hpp>

#include "io/page/view_assets.hpp"

namespace proxseg::detail {
namespace {

using Parts = std::vector<std::pair<std::string, std::string>>;

// text with every placeholder of parts replaced, in one pass: what is put in is never searched,
// so a report's text, a title or an object's name that reads like a placeholder stays as it is.
std::string substituted(const std::string& text, const Parts& parts) {
  std::string out;
  out.reserve(text.size() + 1024);
  std::size_t i = 0;
  while (i < text.size()) {
    const Parts::value_type* part = nullptr;
    if (text[i] == '@')
      for (const auto& p : parts)
        if (text.compare(i, p.first.size(), p.first) == 0) part = &p;
    if (part) {
      out += part->second;
      i += part->first.size();
    } else {
      out += text[i++];
    }
  }
  return out;
}

}  // namespace

std::string relative_url(const std::string& path) {
  static const char* hex = "0123456789ABCDEF";
  std::string out = "./";
  for (const char c : path) {
    const auto b = static_cast<unsigned char>(c);
    // By ranges, not std::isalnum: that follows the locale, which may take bytes above 127.
    const bool unreserved = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') ||
                            (c >= '0' && c <= '9') || c == '-' || c == '.' || c == '_' || c == '~';
    if (unreserved || c == '/')  // '/' only between folders: a name cannot hold one
      out += c;
    else
      out += {'%', hex[b >> 4], hex[b & 15]};
  }
  return out;
}

std::string script_safe(const std::string& json_text) {
  std::string out;
  out.reserve(json_text.size());
  for (char c : json_text) out += c == '<' ? std::string("\\u003c") : std::string(1, c);
  return out;
}

std::string page_text(const char* body_template, const char* css, const Parts& parts) {
  Parts all = {{"@HEAD@", substituted(kPageHead, {{"@VERSION@", version()}, {"@CSS@", css}})}};
  all.insert(all.end(), parts.begin(), parts.end());
  return substituted(body_template, all);
}

}  // namespace proxseg::detail
