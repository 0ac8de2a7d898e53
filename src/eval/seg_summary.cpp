// Summaries of segmentation scores over scenes: means per method and category, CSV, Markdown and
// JSON (seg_summary.hpp).
#include <proxseg/eval/seg_summary.hpp>

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace proxseg {
namespace {

std::string fmt(double v, int digits = 3) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// Adds b * w into a (field by field) for the averaged scores.
void accumulate(SegmentationScores& a, const SegmentationScores& b, double w) {
  a.paper_precision += w * b.paper_precision;
  a.paper_recall += w * b.paper_recall;
  a.v.homogeneity += w * b.v.homogeneity;
  a.v.completeness += w * b.v.completeness;
  a.v.v += w * b.v.v;
  a.weighted_overlap += w * b.weighted_overlap;
  a.object_precision += w * b.object_precision;
  a.object_recall += w * b.object_recall;
  a.object_f += w * b.object_f;
  a.detected_075 += w * b.detected_075;
}

}  // namespace

std::vector<SummaryRow> summary_rows(const std::vector<SceneScores>& scenes) {
  // Methods keep their first-seen order; categories their natural order, "all" last.
  std::vector<std::string> methods;
  for (const auto& s : scenes)
    if (std::find(methods.begin(), methods.end(), s.method) == methods.end())
      methods.push_back(s.method);
  const std::vector<std::string> categories = {
      "boxes", "stacked", "occluded", "cylindric", "clutter", "piles", "occlusion", "other", "all"};
  std::vector<SummaryRow> rows;
  for (const auto& method : methods)
    for (const auto& category : categories) {
      SummaryRow r;
      r.method = method;
      r.category = category;
      for (const auto& s : scenes)
        if (s.method == method && (category == "all" || s.category == category)) ++r.scenes;
      if (r.scenes == 0) continue;
      const double w = 1.0 / r.scenes;
      long lost = 0, objects = 0, lost_parts = 0, objects_parts = 0;
      for (const auto& s : scenes) {
        if (s.method != method || (category != "all" && s.category != category)) continue;
        r.seconds += w * s.seconds;
        accumulate(r.objects, s.objects, w);
        accumulate(r.parts, s.parts, w);
        r.over_segmented += w * s.objects.over_segmented;
        r.under_segmented += w * s.objects.under_segmented;
        r.truth_objects += w * s.objects.truth_objects;
        r.lost_in_background += w * s.objects.lost_in_background;
        r.unassigned_objects += w * s.objects.unassigned_objects;
        lost += s.objects.lost_in_background;
        objects += s.objects.truth_objects;
        lost_parts += s.parts.lost_in_background;
        objects_parts += s.parts.truth_objects;
      }
      // Pooled over the scenes, not a mean of ratios: a scene with one object does not weigh as
      // much as one with ten.
      r.objects.lost_in_background_share =
          objects ? static_cast<double>(lost) / static_cast<double>(objects) : 0.0;
      r.parts.lost_in_background_share =
          objects_parts ? static_cast<double>(lost_parts) / static_cast<double>(objects_parts)
                        : 0.0;
      rows.push_back(r);
    }
  return rows;
}

nlohmann::json scores_json(const SegmentationScores& s) {
  return {{"points", s.points},
          {"truth_regions", s.truth_regions},
          {"truth_objects", s.truth_objects},
          {"segments", s.segments},
          {"paper_precision", s.paper_precision},
          {"paper_recall", s.paper_recall},
          {"homogeneity", s.v.homogeneity},
          {"completeness", s.v.completeness},
          {"v_measure", s.v.v},
          {"weighted_overlap", s.weighted_overlap},
          {"object_precision", s.object_precision},
          {"object_recall", s.object_recall},
          {"object_f", s.object_f},
          {"detected_075", s.detected_075},
          {"over_segmented", s.over_segmented},
          {"under_segmented", s.under_segmented},
          {"lost_in_background", s.lost_in_background},
          {"unassigned_objects", s.unassigned_objects},
          {"lost_in_background_share", s.lost_in_background_share}};
}

std::string scenes_csv(const std::vector<SceneScores>& scenes) {
  std::ostringstream out;
  out << "scene,category,method,seconds";
  for (const char* scheme : {"objects", "parts"})
    for (const char* m :
         {"paper_precision", "paper_recall", "homogeneity", "completeness", "v_measure",
          "weighted_overlap", "object_precision", "object_recall", "object_f", "detected_075",
          "over_segmented", "under_segmented", "truth_objects", "segments", "lost_in_background",
          "unassigned_objects", "lost_in_background_share"})
      out << "," << scheme << "_" << m;
  out << "\n";
  for (const auto& s : scenes) {
    out << s.scene << "," << s.category << "," << s.method << "," << fmt(s.seconds, 4);
    for (const SegmentationScores* x : {&s.objects, &s.parts})
      out << "," << fmt(x->paper_precision, 4) << "," << fmt(x->paper_recall, 4) << ","
          << fmt(x->v.homogeneity, 4) << "," << fmt(x->v.completeness, 4) << "," << fmt(x->v.v, 4)
          << "," << fmt(x->weighted_overlap, 4) << "," << fmt(x->object_precision, 4) << ","
          << fmt(x->object_recall, 4) << "," << fmt(x->object_f, 4) << ","
          << fmt(x->detected_075, 4) << "," << x->over_segmented << "," << x->under_segmented << ","
          << x->truth_objects << "," << x->segments << "," << x->lost_in_background << ","
          << x->unassigned_objects << "," << fmt(x->lost_in_background_share, 4);
    out << "\n";
  }
  return out.str();
}

std::string summary_markdown(const std::vector<SummaryRow>& rows) {
  std::ostringstream out;
  out << "| method | category | scenes | object F | object P | object R | F>=0.75 | V | WOv | "
         "paper P | paper R | over | under | lost bg | parts F | parts V | s/frame |\n"
      << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : rows)
    out << "| " << r.method << " | " << r.category << " | " << r.scenes << " | "
        << fmt(r.objects.object_f) << " | " << fmt(r.objects.object_precision) << " | "
        << fmt(r.objects.object_recall) << " | " << fmt(r.objects.detected_075) << " | "
        << fmt(r.objects.v.v) << " | " << fmt(r.objects.weighted_overlap) << " | "
        << fmt(r.objects.paper_precision) << " | " << fmt(r.objects.paper_recall) << " | "
        << fmt(r.over_segmented, 2) << " | " << fmt(r.under_segmented, 2) << " | "
        << fmt(r.objects.lost_in_background_share) << " | " << fmt(r.parts.object_f) << " | "
        << fmt(r.parts.v.v) << " | " << fmt(r.seconds) << " |\n";
  return out.str();
}

nlohmann::json summary_json(const std::vector<SummaryRow>& rows) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& r : rows) {
    nlohmann::json objects = scores_json(r.objects), parts = scores_json(r.parts);
    // Counts are means over scenes here.
    objects["over_segmented"] = r.over_segmented;
    objects["under_segmented"] = r.under_segmented;
    objects["truth_objects"] = r.truth_objects;
    objects["lost_in_background"] = r.lost_in_background;
    objects["unassigned_objects"] = r.unassigned_objects;
    for (nlohmann::json* x : {&objects, &parts}) {
      x->erase("points");
      x->erase("truth_regions");
      x->erase("segments");
    }
    parts.erase("over_segmented");
    parts.erase("under_segmented");
    parts.erase("truth_objects");
    parts.erase("lost_in_background");
    parts.erase("unassigned_objects");
    j.push_back({{"method", r.method},
                 {"category", r.category},
                 {"scenes", r.scenes},
                 {"seconds_per_frame", r.seconds},
                 {"objects", objects},
                 {"parts", parts}});
  }
  return j;
}

}  // namespace proxseg
