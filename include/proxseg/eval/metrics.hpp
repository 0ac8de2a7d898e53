// Segmentation metrics [paper 4]. Definitions, conventions and references: docs/metrics.md.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace proxseg {

// V-measure (Rosenberg and Hirschberg 2007) of a predicted labelling against ground truth,
// over the points whose truth is non-zero. Entropies in nats; 1 = perfect.
struct VMeasure {
  double homogeneity = 0, completeness = 0, v = 0;
};
VMeasure v_measure(const std::vector<std::uint32_t>& truth,
                   const std::vector<std::uint32_t>& predicted);

// mOSD labels to objects: 0 stays 0 (invalid), 1-9 (table parts) -> 1, 20-29 -> 2, 30-39 -> 3, ...
std::vector<std::uint32_t> mosd_objects(const std::vector<std::uint32_t>& labels);

// mOSD: 0 stays 0; table parts 1-9 -> 1; other labels unchanged (object parts, 20-29, 30-39...).
std::vector<std::uint32_t> mosd_parts(const std::vector<std::uint32_t>& labels);

struct SegmentationScores {
  std::size_t points = 0;  // evaluated points (truth != 0)
  int truth_regions = 0;   // distinct non-zero truth labels (background included)
  int truth_objects = 0;   // truth regions that are not background
  int segments = 0;        // distinct non-zero predicted labels on evaluated points
  // Paper section 4 (Table 1): every predicted label is mapped to the truth region holding most of
  // its evaluated points (ties -> smaller truth label); per truth region r, precision = points of
  // the labels mapped to r that lie in r / points of the labels mapped to r, recall = the same
  // numerator / |r|; both 0 for a region no label maps to; macro-averaged over all truth regions
  // (background included, as the paper's regions include floor/wall). Predicted 0 is no label: it
  // maps nowhere.
  double paper_precision = 0, paper_recall = 0;
  VMeasure v;  // existing v_measure (predicted 0 = one "unassigned" cluster)
  // Weighted overlap over truth objects (background excluded): sum_G |G| * max_S IoU(G, S) /
  // sum_G |G|, S over non-zero predicted segments.
  double weighted_overlap = 0;
  // Object overlap P/R/F as in unseen-object instance segmentation on OSD (Xie et al., UOIS,
  // "multilabel_metrics"): predicted segments = non-zero predicted labels, excluding those with
  // more than half of their evaluated points on background truth; F-measure F(S,G) =
  // 2|S∩G|/(|S|+|G|) for every pair; Hungarian matching maximising the sum of F; precision = sum
  // over matched pairs |S∩G| / sum over kept segments |S|; recall = sum over matched pairs |S∩G| /
  // sum over truth objects |G|; F = 2PR/(P+R) (0 if P+R = 0); detected_075 = share of truth objects
  // whose matched pair has F(S,G) >= 0.75 (0 if no objects).
  double object_precision = 0, object_recall = 0, object_f = 0, detected_075 = 0;
  // Over-segmented truth objects: at least two predicted segments (non-zero labels, background
  // segments included) each hold >= 10% of the object's points. Under-segmented truth objects: the
  // predicted segment holding most of the object's points (non-zero labels, ties -> smaller label;
  // none if the object's points are all predicted 0) has >= 10% of its evaluated points on one
  // other truth region (another object or the background).
  int over_segmented = 0, under_segmented = 0;
  // Objects lost in the background: truth objects whose majority segment (the non-zero predicted
  // label holding most of the object's points, ties -> smaller label) is a background segment,
  // i.e. has more than half of its evaluated points on background truth (the rule that leaves a
  // segment out of the object P/R). Objects whose points are all predicted 0 have no majority
  // segment: they are counted as unassigned_objects instead. lost_in_background_share =
  // lost_in_background / truth_objects (0 if no objects).
  int lost_in_background = 0, unassigned_objects = 0;
  double lost_in_background_share = 0;
};

// truth: per point, 0 = not evaluated (invalid position or unlabelled), else a region id; the
// caller zeroes it where the position is not finite (mOSD has NaN points under non-zero labels).
// predicted: per point, 0 = unassigned, else a segment id. background: the truth ids that are
// background (table, floor, wall), e.g. {1} for mosd_objects / mosd_parts.
// Throws std::invalid_argument if the sizes differ.
SegmentationScores score_segmentation(const std::vector<std::uint32_t>& truth,
                                      const std::vector<std::uint32_t>& predicted,
                                      const std::vector<std::uint32_t>& background);

}  // namespace proxseg
