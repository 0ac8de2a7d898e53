// The parameter checks: every row's range (the table, parameters.hpp) and the rules between
// parameters, for validate().
#include <proxseg/core/errors.hpp>
#include <proxseg/core/parameters.hpp>

#include <string>
#include <vector>

namespace proxseg {

namespace {

// Every row's range (parameters.hpp): InputError "field KEY: expected RANGE, got VALUE".
template <class P>
void check_ranges(const P& p, const std::vector<Parameter>& table) {
  for (const Parameter& row : table) {
    const ParamValue value = get_parameter(p, row.key());
    if (!in_range(row, value))
      throw InputError("field " + row.key() + ": expected " + row.range_text() + ", got " +
                       format_parameter(value));
  }
}

}  // namespace

void validate(const SegmentParams& p) {
  check_ranges(p, segment_parameters());
  const SelectionParams& sp = p.selection;
  if (sp.containers.max_radius < sp.containers.min_radius)
    throw InputError(
        "field selection.containers.max_radius: expected >= "
        "selection.containers.min_radius (" +
        format_parameter(sp.containers.min_radius) + "), got " +
        format_parameter(sp.containers.max_radius));
}

void validate(const RecognitionParams& p) {
  check_ranges(p, recognition_parameters());
}

}  // namespace proxseg
