// The pages' HTML from their templates (page_text.hpp).
#include "page_text.hpp"

#include <proxseg/core/version.hpp>

#include "view_assets.hpp"

namespace proxseg::detail {
namespace {

void replace_first(std::string& text, const std::string& key, const std::string& value) {
  const std::size_t at = text.find(key);
  if (at != std::string::npos) text.replace(at, key.size(), value);
}

}  // namespace

std::string script_safe(const std::string& json_text) {
  std::string out;
  out.reserve(json_text.size());
  for (char c : json_text) out += c == '<' ? std::string("\\u003c") : std::string(1, c);
  return out;
}

std::string page_text(const char* body_template, const char* css,
                      const std::vector<std::pair<std::string, std::string>>& parts) {
  std::string head = kPageHead;
  replace_first(head, "@VERSION@", version());
  replace_first(head, "@CSS@", css);
  std::string page = body_template;
  replace_first(page, "@HEAD@", head);
  for (const auto& [key, text] : parts) replace_first(page, key, text);
  return page;
}

}  // namespace proxseg::detail
