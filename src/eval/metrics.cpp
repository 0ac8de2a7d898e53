// Segmentation metrics [paper 4]. Definitions and conventions: docs/metrics.md.
#include <proxseg/eval/metrics.hpp>

#include "assignment.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

namespace proxseg {
namespace {

// Dense ids 0..n-1 for arbitrary uint32 labels. A hash map keeps the per-point lookup O(1); the ids
// are then renumbered in ascending label order, so nothing downstream (loops, tie-breaks,
// floating-point sums) depends on hash order or on the order in which the points come.
class DenseIds {
 public:
  int id(std::uint32_t label) {
    // Organized clouds come in runs of equal labels: a repeat needs no hash lookup.
    if (last_id_ >= 0 && label == last_label_) return last_id_;
    const auto [it, fresh] = index_.try_emplace(label, static_cast<int>(labels_.size()));
    if (fresh) labels_.push_back(label);
    last_label_ = label;
    last_id_ = it->second;
    return last_id_;
  }

  // Sorts the labels ascending; returns, per id handed out so far, its new id (the label's rank).
  std::vector<int> sort() {
    std::vector<int> order(labels_.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int a, int b) { return labels_[a] < labels_[b]; });
    std::vector<int> rank(labels_.size());
    std::vector<std::uint32_t> sorted(labels_.size());
    for (std::size_t r = 0; r < order.size(); ++r) {
      rank[order[r]] = static_cast<int>(r);
      sorted[r] = labels_[order[r]];
    }
    labels_ = std::move(sorted);
    index_.clear();
    last_id_ = -1;
    return rank;
  }

  const std::vector<std::uint32_t>& labels() const { return labels_; }

 private:
  std::unordered_map<std::uint32_t, int> index_;
  std::vector<std::uint32_t> labels_;
  std::uint32_t last_label_ = 0;
  int last_id_ = -1;
};

struct Cell {
  int t = 0, p = 0;   // dense truth and predicted ids
  std::size_t n = 0;  // evaluated points with that truth and that prediction
};

// Sparse contingency table of the evaluated points (truth != 0). Ids follow ascending label
// values, so predicted id 0 is label 0 when any evaluated point is predicted 0.
struct Contingency {
  std::vector<std::uint32_t> truth_labels, predicted_labels;
  std::vector<std::size_t> truth_size, predicted_size;  // evaluated points per label
  std::vector<Cell> cells;                              // non-empty cells, sorted by (t, p)
  std::size_t points = 0;
};

Contingency contingency(const std::vector<std::uint32_t>& truth,
                        const std::vector<std::uint32_t>& predicted, const char* caller) {
  if (truth.size() != predicted.size())
    throw std::invalid_argument(std::string(caller) + ": sizes differ");
  DenseIds truth_ids, predicted_ids;
  std::vector<int> t_of, p_of;  // per evaluated point
  t_of.reserve(truth.size());
  p_of.reserve(truth.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (!truth[i]) continue;
    t_of.push_back(truth_ids.id(truth[i]));
    p_of.push_back(predicted_ids.id(predicted[i]));
  }
  const std::vector<int> t_rank = truth_ids.sort(), p_rank = predicted_ids.sort();
  Contingency c;
  c.truth_labels = truth_ids.labels();
  c.predicted_labels = predicted_ids.labels();
  c.points = t_of.size();
  const std::size_t nt = c.truth_labels.size(), np = c.predicted_labels.size();
  c.truth_size.assign(nt, 0);
  c.predicted_size.assign(np, 0);
  for (std::size_t k = 0; k < c.points; ++k) {
    t_of[k] = t_rank[t_of[k]];
    p_of[k] = p_rank[p_of[k]];
    ++c.truth_size[t_of[k]];
    ++c.predicted_size[p_of[k]];
  }
  // Two stable counting sorts (by p, then by t) put the points in (t, p) order in linear time; a
  // comparison sort of 300k keys would cost more than all the metrics together.
  std::vector<std::size_t> by_p(c.points), by_tp(c.points), next(np);
  std::size_t sum = 0;
  for (std::size_t p = 0; p < np; ++p) {
    next[p] = sum;
    sum += c.predicted_size[p];
  }
  for (std::size_t k = 0; k < c.points; ++k) by_p[next[p_of[k]]++] = k;
  next.assign(nt, 0);
  sum = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    next[t] = sum;
    sum += c.truth_size[t];
  }
  for (const std::size_t k : by_p) by_tp[next[t_of[k]]++] = k;
  for (const std::size_t k : by_tp) {
    if (!c.cells.empty() && c.cells.back().t == t_of[k] && c.cells.back().p == p_of[k])
      ++c.cells.back().n;
    else
      c.cells.push_back({t_of[k], p_of[k], 1});
  }
  return c;
}

// Same sums in the same order (ascending labels) as the original map-based v_measure, so the
// values are bit-identical to it.
VMeasure v_measure_of(const Contingency& c) {
  VMeasure m;
  const double n = static_cast<double>(c.points);
  if (n == 0) return m;
  auto entropy = [n](const std::vector<std::size_t>& counts) {
    double h = 0;
    for (const std::size_t k : counts) {
      const double c = static_cast<double>(k);
      h -= c / n * std::log(c / n);
    }
    return h;
  };
  const double h_c = entropy(c.truth_size), h_k = entropy(c.predicted_size);
  double h_c_given_k = 0, h_k_given_c = 0;
  for (const Cell& cell : c.cells) {
    const double k = static_cast<double>(cell.n);
    h_c_given_k -= k / n * std::log(k / static_cast<double>(c.predicted_size[cell.p]));
    h_k_given_c -= k / n * std::log(k / static_cast<double>(c.truth_size[cell.t]));
  }
  // Conventions of the paper that defines the measure: a single class is perfectly homogeneous,
  // a single cluster perfectly complete.
  m.homogeneity = h_c > 0 ? 1.0 - h_c_given_k / h_c : 1.0;
  m.completeness = h_k > 0 ? 1.0 - h_k_given_c / h_k : 1.0;
  const double s = m.homogeneity + m.completeness;
  m.v = s > 0 ? 2 * m.homogeneity * m.completeness / s : 0.0;
  return m;
}

double ratio(std::size_t a, std::size_t b) {
  return b ? static_cast<double>(a) / static_cast<double>(b) : 0.0;
}

}  // namespace

VMeasure v_measure(const std::vector<std::uint32_t>& truth,
                   const std::vector<std::uint32_t>& predicted) {
  return v_measure_of(contingency(truth, predicted, "v_measure"));
}

std::vector<std::uint32_t> mosd_objects(const std::vector<std::uint32_t>& labels) {
  std::vector<std::uint32_t> out(labels.size());
  for (std::size_t i = 0; i < labels.size(); ++i)
    out[i] = labels[i] == 0 ? 0 : labels[i] < 10 ? 1 : labels[i] / 10;
  return out;
}

std::vector<std::uint32_t> mosd_parts(const std::vector<std::uint32_t>& labels) {
  std::vector<std::uint32_t> out(labels.size());
  for (std::size_t i = 0; i < labels.size(); ++i)
    out[i] = labels[i] >= 1 && labels[i] <= 9 ? 1 : labels[i];
  return out;
}

namespace {

// Per predicted label: its majority region (cells come in ascending t, so a strict > leaves
// ties to the smaller truth label), the largest count on any other region than that one (for
// the under-segmentation test), and its points on the background.
struct Majorities {
  std::vector<int> majority;
  std::vector<std::size_t> majority_n, runner_up_n, on_background;
};

Majorities majorities(const Contingency& c, const std::vector<char>& is_object) {
  const std::size_t np = c.predicted_labels.size();
  Majorities m;
  m.majority.assign(np, -1);
  m.majority_n.assign(np, 0);
  m.runner_up_n.assign(np, 0);
  m.on_background.assign(np, 0);
  for (const Cell& cell : c.cells) {
    if (cell.n > m.majority_n[cell.p]) {
      m.runner_up_n[cell.p] = m.majority_n[cell.p];
      m.majority_n[cell.p] = cell.n;
      m.majority[cell.p] = cell.t;
    } else if (cell.n > m.runner_up_n[cell.p]) {
      m.runner_up_n[cell.p] = cell.n;
    }
    if (!is_object[cell.t]) m.on_background[cell.p] += cell.n;
  }
  return m;
}

// Paper section 4: each label is assigned to its majority region.
void paper_scores(const Contingency& c, const Majorities& m, int first_segment,
                  SegmentationScores& s) {
  const int nt = static_cast<int>(c.truth_labels.size());
  const int np = static_cast<int>(c.predicted_labels.size());
  std::vector<std::size_t> hit(nt, 0), claimed(nt, 0);
  for (int p = first_segment; p < np; ++p) {
    hit[m.majority[p]] += m.majority_n[p];
    claimed[m.majority[p]] += c.predicted_size[p];
  }
  double precision = 0, recall = 0;
  for (int t = 0; t < nt; ++t) {
    precision += ratio(hit[t], claimed[t]);
    recall += ratio(hit[t], c.truth_size[t]);
  }
  s.paper_precision = precision / nt;
  s.paper_recall = recall / nt;
}

// Per truth object: best IoU, over- and under-segmentation, lost in the background. The cells of
// one t are contiguous.
// Returns the points of the truth objects.
std::size_t object_scores(const Contingency& c, const std::vector<char>& is_object,
                          const Majorities& m, const std::vector<char>& background_segment,
                          int first_segment, SegmentationScores& s) {
  std::size_t object_points = 0;
  double overlap = 0;
  for (std::size_t begin = 0, end = 0; begin < c.cells.size(); begin = end) {
    const int t = c.cells[begin].t;
    end = begin;
    while (end < c.cells.size() && c.cells[end].t == t) ++end;
    if (!is_object[t]) continue;
    const std::size_t g = c.truth_size[t];
    object_points += g;
    double best_iou = 0;
    int holders = 0, largest = -1;
    std::size_t largest_n = 0;
    for (std::size_t k = begin; k < end; ++k) {
      const Cell& cell = c.cells[k];
      if (cell.p < first_segment) continue;
      const std::size_t sz = c.predicted_size[cell.p];
      best_iou = std::max(best_iou, ratio(cell.n, g + sz - cell.n));
      if (10 * cell.n >= g) ++holders;
      // Cells come in ascending p: a strict > leaves ties to the smaller predicted label.
      if (cell.n > largest_n) {
        largest_n = cell.n;
        largest = cell.p;
      }
    }
    overlap += static_cast<double>(g) * best_iou;
    if (holders >= 2) ++s.over_segmented;
    if (largest >= 0) {
      // The largest count of that segment on a region other than t.
      const std::size_t other =
          m.majority[largest] == t ? m.runner_up_n[largest] : m.majority_n[largest];
      if (10 * other >= c.predicted_size[largest]) ++s.under_segmented;
      if (background_segment[largest]) ++s.lost_in_background;
    } else {
      ++s.unassigned_objects;
    }
  }
  s.weighted_overlap = object_points ? overlap / static_cast<double>(object_points) : 0.0;
  s.lost_in_background_share =
      s.truth_objects ? static_cast<double>(s.lost_in_background) / s.truth_objects : 0.0;
  return object_points;
}

// Object overlap P/R/F (UOIS). Segments with more than half of their points on the background
// are left out: they are the table, not a (bad) object.
void overlap_scores(const Contingency& c, const std::vector<char>& is_object,
                    const std::vector<char>& background_segment, int first_segment,
                    std::size_t object_points, SegmentationScores& s) {
  const int nt = static_cast<int>(c.truth_labels.size());
  const int np = static_cast<int>(c.predicted_labels.size());
  std::vector<char> kept(np, 0);
  std::size_t kept_points = 0;
  for (int p = first_segment; p < np; ++p) {
    kept[p] = !background_segment[p];
    if (kept[p]) kept_points += c.predicted_size[p];
  }
  // Only objects and kept segments that meet enter the matching: any other pair has F = 0, so
  // matching it or not changes neither the optimum nor any score.
  // Rows and columns are numbered in ascending label order, which fixes the tie-breaks.
  std::vector<int> row_of(nt, -1), col_of(np, -1);
  std::vector<char> meets(np, 0);
  int rows = 0, cols = 0;
  for (const Cell& cell : c.cells)
    if (is_object[cell.t] && kept[cell.p]) {
      if (row_of[cell.t] < 0) row_of[cell.t] = rows++;
      meets[cell.p] = 1;
    }
  for (int p = 0; p < np; ++p)
    if (meets[p]) col_of[p] = cols++;
  std::size_t matched = 0;
  int detected = 0;
  if (rows > 0) {
    // F and intersections of the pairs that meet, row-major rows x cols.
    std::vector<double> f(static_cast<std::size_t>(rows) * cols, 0.0);
    std::vector<std::size_t> inter(f.size(), 0), denom(f.size(), 0);
    for (const Cell& cell : c.cells) {
      if (!is_object[cell.t] || !kept[cell.p]) continue;
      const std::size_t k = static_cast<std::size_t>(row_of[cell.t]) * cols + col_of[cell.p];
      inter[k] = cell.n;
      denom[k] = c.truth_size[cell.t] + c.predicted_size[cell.p];
      f[k] = 2.0 * static_cast<double>(cell.n) / static_cast<double>(denom[k]);
    }
    // Maximise the sum of F = minimise the sum of -F, on the orientation with rows <= cols.
    const bool transpose = rows > cols;
    const int a = transpose ? cols : rows, b = transpose ? rows : cols;
    std::vector<double> cost(f.size());
    for (int i = 0; i < rows; ++i)
      for (int j = 0; j < cols; ++j) {
        const std::size_t k = static_cast<std::size_t>(i) * cols + j;
        cost[transpose ? static_cast<std::size_t>(j) * rows + i : k] = -f[k];
      }
    const std::vector<int> match = detail::assign_min_cost(cost, a, b);
    for (int i = 0; i < a; ++i) {
      const std::size_t k = transpose ? static_cast<std::size_t>(match[i]) * cols + i
                                      : static_cast<std::size_t>(i) * cols + match[i];
      matched += inter[k];
      // F >= 0.75 in integers, so a value on the threshold is not lost to rounding.
      if (inter[k] > 0 && 8 * inter[k] >= 3 * denom[k]) ++detected;
    }
  }
  s.object_precision = ratio(matched, kept_points);
  s.object_recall = ratio(matched, object_points);
  const double pr = s.object_precision + s.object_recall;
  s.object_f = pr > 0 ? 2 * s.object_precision * s.object_recall / pr : 0.0;
  s.detected_075 = s.truth_objects ? static_cast<double>(detected) / s.truth_objects : 0.0;
}

}  // namespace

SegmentationScores score_segmentation(const std::vector<std::uint32_t>& truth,
                                      const std::vector<std::uint32_t>& predicted,
                                      const std::vector<std::uint32_t>& background) {
  const Contingency c = contingency(truth, predicted, "score_segmentation");
  const int nt = static_cast<int>(c.truth_labels.size());
  const int np = static_cast<int>(c.predicted_labels.size());
  SegmentationScores s;
  s.points = c.points;
  s.v = v_measure_of(c);
  if (c.points == 0) return s;

  std::vector<char> is_object(nt);
  for (int t = 0; t < nt; ++t)
    is_object[t] =
        std::find(background.begin(), background.end(), c.truth_labels[t]) == background.end();
  // Predicted 0 is "unassigned", not a segment; being the smallest label it can only be id 0.
  const int first_segment = c.predicted_labels[0] == 0 ? 1 : 0;
  s.truth_regions = nt;
  s.truth_objects = static_cast<int>(std::count(is_object.begin(), is_object.end(), 1));
  s.segments = np - first_segment;

  const Majorities m = majorities(c, is_object);
  paper_scores(c, m, first_segment, s);
  // Background segments: more than half of their points on the background (exactly half is not).
  std::vector<char> background_segment(np, 0);
  for (int p = first_segment; p < np; ++p)
    background_segment[p] = 2 * m.on_background[p] > c.predicted_size[p];

  const std::size_t object_points =
      object_scores(c, is_object, m, background_segment, first_segment, s);
  overlap_scores(c, is_object, background_segment, first_segment, object_points, s);
  return s;
}

}  // namespace proxseg
