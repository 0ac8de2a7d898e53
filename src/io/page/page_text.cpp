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
