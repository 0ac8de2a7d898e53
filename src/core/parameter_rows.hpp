// The rows of the parameter table as parameter_rows.txt states them: key, unit, range, flags,
// the paper's value, the old key and the help. The rest of a row (type, choices, default, the
// paper preset's value) comes from the member its key names (parameter_members.hpp). Internal
// to core.
#pragma once
#include <proxseg/core/parameters.hpp>

#include <string>
#include <vector>

namespace proxseg::detail {

// The rows of one table, "segmentation" or "recognition", in the file's order; `paper` is the
// file's column ("preset", the paper's value as text, or ""). std::logic_error for a line the
// file should not hold: it is part of the program, not input.
std::vector<Parameter> table_rows(const std::string& table);

}  // namespace proxseg::detail
