// The checks of the report the 3D page reads (view_report.hpp), against what output.cpp writes.
#include "io/page/view_report.hpp"

#include <cstdint>

#include "io/json_file.hpp"
#include "io/reader_errors.hpp"

namespace proxseg::detail {
namespace {

using nlohmann::json;

[[noreturn]] void wrong(const std::string& where, const std::string& field,
                        const std::string& expected, const json& got) {
  fail(where, field + ": expected " + expected + ", got " + json_excerpt(got));
}

bool numbers(const json& v, std::size_t n) {
  if (!v.is_array() || v.size() != n) return false;
  for (const json& x : v)
    if (!x.is_number()) return false;
  return true;
}

bool matrix(const json& v, std::size_t rows, std::size_t cols) {
  if (!v.is_array() || v.size() != rows) return false;
  for (const json& row : v)
    if (!numbers(row, cols)) return false;
  return true;
}

void check_number(const json& c, const char* key, const std::string& where, const std::string& at) {
  if (c.contains(key) && !c[key].is_number()) wrong(where, at + key, "a number", c[key]);
}

void check_box(const json& box, const std::string& where, const std::string& at) {
  if (!box.is_object()) wrong(where, at, "an object", box);
  if (!box.contains("centre") || !numbers(box["centre"], 3))
    fail(where, at + ".centre: expected 3 numbers");
  if (!box.contains("axes") || !matrix(box["axes"], 3, 3))
    fail(where, at + ".axes: expected 3 rows of 3 numbers");
  if (!box.contains("extent") || !numbers(box["extent"], 3))
    fail(where, at + ".extent: expected 3 numbers");
}

// A whole number in [0, most]: a report read from a file holds unsigned numbers, one made in
// memory (a batch's pages) signed ones.
bool whole_in(const json& v, std::uint64_t most) {
  if (v.is_number_unsigned()) return v.get<std::uint64_t>() <= most;
  return v.is_number_integer() && v.get<std::int64_t>() >= 0 &&
         static_cast<std::uint64_t>(v.get<std::int64_t>()) <= most;
}

void check_colour(const json& c, const std::string& where, const std::string& at) {
  bool ok = c.is_array() && c.size() == 3;
  for (std::size_t i = 0; ok && i < 3; ++i) ok = whole_in(c[i], 255);
  if (!ok) wrong(where, at, "3 integers 0-255", c);
}

// One entry of candidates or background.
void check_entry(const json& c, bool recognition, const std::string& where, const std::string& at) {
  if (!c.is_object()) wrong(where, at, "an object", c);
  if (!c.contains("id")) fail(where, at + ".id: missing (expected an id)");
  if (!whole_in(c["id"], 0xffffffffu)) wrong(where, at + ".id", "an unsigned integer", c["id"]);
  check_number(c, "points", where, at + ".");
  if (c.contains("name") && !c["name"].is_string())
    wrong(where, at + ".name", "a string", c["name"]);
  if (c.contains("box")) check_box(c["box"], where, at + ".box");
  if (!recognition) return;
  for (const char* k : {"score", "fitness", "coverage"}) check_number(c, k, where, at + ".");
  if (c.contains("colour")) check_colour(c["colour"], where, at + ".colour");
  if (c.contains("pose") && !matrix(c["pose"], 4, 4))
    fail(where, at + ".pose: expected 4 rows of 4 numbers");
  if (c.contains("best")) {
    const json& best = c["best"];
    if (!best.is_null() && !best.is_object()) wrong(where, at + ".best", "an object or null", best);
    if (best.is_object()) check_number(best, "score", where, at + ".best.");
  }
}

}  // namespace

void check_view_report(const json& report, const std::string& where) {
  if (!report.is_object() || !report.contains("proxseg"))
    fail(where, "not a report of proxseg segment or recognize");
  const bool recognition = report.contains("database");
  if (report.contains("paper_labels") && !report["paper_labels"].is_boolean())
    wrong(where, "paper_labels", "true or false", report["paper_labels"]);
  if (report.contains("mrf")) {
    const json& mrf = report["mrf"];
    if (!mrf.is_object()) wrong(where, "mrf", "an object", mrf);
    if (mrf.contains("enabled") && !mrf["enabled"].is_boolean())
      wrong(where, "mrf.enabled", "true or false", mrf["enabled"]);
  }
  for (const char* kind : {"candidates", "background"}) {
    if (!report.contains(kind)) continue;
    const json& list = report[kind];
    if (!list.is_array()) wrong(where, kind, "a list", list);
    for (std::size_t i = 0; i < list.size(); ++i)
      check_entry(list[i], recognition, where, std::string(kind) + "[" + std::to_string(i) + "]");
  }
}

}  // namespace proxseg::detail
