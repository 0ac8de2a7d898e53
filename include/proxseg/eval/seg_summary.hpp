// Summaries of segmentation scores over scenes [paper 4]: means per method and category, and
// the tables that report them (per-scene CSV, Markdown, JSON).
#pragma once
#include <proxseg/eval/metrics.hpp>
#include <proxseg/eval/seg_scores.hpp>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace proxseg {

// Means over scenes of every score, per method and category, plus an "all" category.
struct SummaryRow {
  std::string method, category;
  int scenes = 0;
  double seconds = 0;
  // Means of the scores; the int counts stay 0 here. Except lost_in_background_share (objects
  // and parts): pooled, the sum of lost objects over the sum of truth objects of the scenes.
  SegmentationScores objects, parts;
  double over_segmented = 0, under_segmented = 0, truth_objects = 0;  // mean counts, objects
  double lost_in_background = 0, unassigned_objects = 0;              // mean counts, objects
};
std::vector<SummaryRow> summary_rows(const std::vector<SceneScores>& scenes);

// Per-scene rows: every score of both schemes (objects_*, parts_*), lost_in_background,
// unassigned_objects and lost_in_background_share included.
std::string scenes_csv(const std::vector<SceneScores>& scenes);
std::string summary_markdown(const std::vector<SummaryRow>& rows);
nlohmann::json summary_json(const std::vector<SummaryRow>& rows);
nlohmann::json scores_json(const SegmentationScores& s);

}  // namespace proxseg
