// The 3D page's and the batch page's HTML templates, style and scripts (src/io/page/assets/),
// compiled in by CMake (cmake/embed_text.cmake writes view_assets.cpp from them). Private to io.
#pragma once

namespace proxseg::detail {

extern const char* const kPageHead;    // head.html, both pages' head: @VERSION@ @CSS@
extern const char* const kViewerHtml;  // viewer.html: @HEAD@ @META@ @POINTS@ @JS@
extern const char* const kViewerCss;   // viewer.css
extern const char* const kViewerJs;    // viewer.js
extern const char* const kBatchHtml;   // batch.html: @HEAD@ @ROWS@ @JS@
extern const char* const kBatchCss;    // batch.css
extern const char* const kBatchJs;     // batch.js

}  // namespace proxseg::detail
