// The pages' HTML made from their templates (src/io/page/assets/, view_assets.hpp): the shared head
// with the page's style, then the placeholders of the page's template filled in. Private to io.
#pragma once
#include <string>
#include <utility>
#include <vector>

namespace proxseg::detail {

// JSON text that can stand inside a <script> element: every "<" escaped (no "</script>").
std::string script_safe(const std::string& json_text);

// body_template (a page of src/io/page/assets/ that starts with @HEAD@) with the head (style css)
// and each (placeholder, text) put in where the template has the placeholder; the texts put in are
// not searched for placeholders.
std::string page_text(const char* body_template, const char* css,
                      const std::vector<std::pair<std::string, std::string>>& parts);

}  // namespace proxseg::detail
