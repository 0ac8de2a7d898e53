// The Hungarian method: the minimum-cost assignment of rows to columns, shared by the
// segmentation metrics (object F, metrics.cpp) and the recognition matching
// (max_weight_assignment, scene_eval.cpp). Private to the library.
#pragma once
#include <vector>

namespace proxseg::detail {

// Minimum-cost assignment of every row to a distinct column, rows <= cols, cost row-major. The
// Hungarian method with row/column potentials and shortest augmenting paths (Kuhn-Munkres in the
// O(rows^2 cols) form of Jonker and Volgenant). Working on the rectangle is the same as padding
// it to a square with zero-cost rows, which take the left-over columns, without paying for them.
// Returns the column of each row.
std::vector<int> assign_min_cost(const std::vector<double>& cost, int rows, int cols);

}  // namespace proxseg::detail
