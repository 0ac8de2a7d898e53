// The page of a batch (batch_page.hpp): one compact row per frame, embedded in the page
// (src/io/page/assets/batch.html and batch.js, compiled in as view_assets.cpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/io/batch.hpp>
#include <proxseg/io/batch_page.hpp>

#include <filesystem>

#include "io/page/page_text.hpp"
#include "io/page/view_assets.hpp"
#include "util/shown_names.hpp"

namespace proxseg {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// The link to the frame's output with this extension when the row lists it, else null: the
// URL of its name's bytes (the log shows a name that is not UTF-8 as \xFF text), relative and
// percent-encoded (page_text.hpp), the only form in which a name goes into a link. The file is
// named by output_stem (a frame named "summary" writes summary-frame.*).
json output_link(const json& row, const std::string& extension) {
  const std::string shown = output_stem(row.value("frame", "")) + extension;
  if (!row.contains("outputs") || !row["outputs"].contains(shown)) return json();
  return detail::relative_url(name_from_shown(shown));
}

// [frame, ms, count, named, error, picture, page], as batch.js reads it: count is the
// candidates of a segmentation or the objects of a recognition, named those with a name;
// picture and page are links (output_link).
json page_row(const json& row) {
  json count, named;
  if (row.contains("objects")) {
    count = row["objects"].size();
    std::size_t n = 0;
    for (const json& name : row["objects"]) n += name != kUnknown;
    named = n;
  } else if (row.contains("candidates")) {
    count = row["candidates"];
  }
  return {row.value("frame", ""),
          row.value("ms", 0.0),
          count,
          named,
          row.contains("error") ? row["error"] : json(),
          output_link(row, ".png"),
          output_link(row, ".html")};
}

}  // namespace

std::string batch_page(const std::string& out_dir, const std::string& title) {
  const std::vector<std::string> logs = summary_logs(out_dir);
  if (logs.empty())
    throw InputError(out_dir + ": no summary.jsonl (expected the folder of a --batch run)");
  const json summary = summarize(logs, false);
  json rows = json::array();
  for (const json& row : frame_rows(out_dir)) rows.push_back(page_row(row));
  const std::string name = fs::path(out_dir).lexically_normal().filename().string();
  const json data = {{"title", title.empty() ? (name.empty() ? out_dir : name) : title},
                     {"command", summary.value("command", "")},
                     {"missing", summary.value("frames_missing", 0)},
                     {"rows", rows}};
  return detail::page_text(
      detail::kBatchHtml, detail::kBatchCss,
      {{"@ROWS@", detail::script_safe(dump_shown(data))}, {"@JS@", detail::kBatchJs}});
}

}  // namespace proxseg
