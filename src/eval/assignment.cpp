// The Hungarian method: minimum-cost assignment of rows to columns (assignment.hpp).
#include "assignment.hpp"

#include <algorithm>
#include <limits>

namespace proxseg::detail {

std::vector<int> assign_min_cost(const std::vector<double>& cost, int rows, int cols) {
  const double inf = std::numeric_limits<double>::infinity();
  // 1-based rows and columns; column 0 is the virtual start of each augmenting path.
  std::vector<double> u(rows + 1, 0.0), v(cols + 1, 0.0), min_slack(cols + 1);
  std::vector<int> row_of_col(cols + 1, 0), prev_col(cols + 1, 0);
  std::vector<char> used(cols + 1);
  for (int i = 1; i <= rows; ++i) {
    row_of_col[0] = i;
    int j0 = 0;
    std::fill(min_slack.begin(), min_slack.end(), inf);
    std::fill(used.begin(), used.end(), 0);
    do {
      used[j0] = 1;
      const int i0 = row_of_col[j0];
      const double* cost_row = cost.data() + static_cast<std::size_t>(i0 - 1) * cols;
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= cols; ++j) {
        if (used[j]) continue;
        const double slack = cost_row[j - 1] - u[i0] - v[j];
        if (slack < min_slack[j]) {
          min_slack[j] = slack;
          prev_col[j] = j0;
        }
        // Strict: among equal slacks the lowest column wins, a fixed tie-break.
        if (min_slack[j] < delta) {
          delta = min_slack[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= cols; ++j) {
        if (used[j]) {
          u[row_of_col[j]] += delta;
          v[j] -= delta;
        } else {
          min_slack[j] -= delta;
        }
      }
      j0 = j1;
    } while (row_of_col[j0] != 0);
    do {
      const int j1 = prev_col[j0];
      row_of_col[j0] = row_of_col[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> col_of_row(rows, -1);
  for (int j = 1; j <= cols; ++j)
    if (row_of_col[j]) col_of_row[row_of_col[j] - 1] = j - 1;
  return col_of_row;
}

}  // namespace proxseg::detail
