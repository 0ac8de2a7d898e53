// The pages' HTML made from their templates (src/io/page/assets/, view_assets.hpp): the shared head
// with the page's style, then the placeholders of the page's template filled in; and the texts
// put in: JSON safe in a <script>, names made URLs. Private to io.
#pragma once
#include <string>
#include <utility>
#include <vector>

namespace proxseg::detail {

// The URL of a file beside the page, from its path there (bytes, whatever they hold; '/' between
// folders): "./" and each part percent-encoded, every byte but RFC 3986's unreserved ones
// (A-Z a-z 0-9 - . _ ~) as %XX. So no name becomes a scheme ("javascript:"), a query or a
// fragment, and the browser, decoding it, asks for the file's very bytes (not UTF-8 ones too).
std::string relative_url(const std::string& path);

// JSON text that can stand inside a <script> element: every "<" escaped (no "</script>").
std::string script_safe(const std::string& json_text);

// body_template (a page of src/io/page/assets/ that starts with @HEAD@) with the head (style css)
// and each (placeholder, text) put in where the template has the placeholder; the texts put in are
// not searched for placeholders.
std::string page_text(const char* body_template, const char* css,
                      const std::vector<std::pair<std::string, std::string>>& parts);

}  // namespace proxseg::detail
