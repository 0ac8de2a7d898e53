// The report the 3D page reads (PREFIX.json of segment or recognize), checked field by field
// before the page indexes it. Private to the library.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

namespace proxseg::detail {

// InputError "WHERE: FIELD: expected ..." (e.g. "R.json: candidates[2].pose: expected 4 rows of
// 4 numbers") unless every field the page reads has the type and shape the writers write:
// candidates and background lists of objects with unsigned ids, recognition poses 4x4, colours
// 3 bytes, boxes with a centre, 3 axes and an extent.
void check_view_report(const nlohmann::json& report, const std::string& where);

}  // namespace proxseg::detail
